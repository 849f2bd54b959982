"""Facet from Python: measured BRDFs as NumPy arrays, microfacet fits, Mitsuba 3 exports.

>>> import numpy as np, facet_brdf
>>> gold = facet_brdf.load("analytic:ggx?alpha=0.3&conductor=gold")
>>> wi = wo = np.array([[0.0, 0.0, 1.0]])
>>> gold.eval(wi, wo).shape
(1, 3)

``load`` takes every input ``facet fit`` takes; ``fit`` runs the same fit and returns the same
record. Errors raise ``FacetError`` (a ``ValueError``) with the message ``facet`` prints.
See docs/python.md in the repository.
"""

from ._native import Brdf, FacetError, Fit, __version__, fit, from_merl, load

__all__ = ["Brdf", "FacetError", "Fit", "__version__", "fit", "from_merl", "load"]
