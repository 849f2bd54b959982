"""Type stubs of facet_brdf (the extension module facet_brdf._native, re-exported)."""

import os
from typing import Any, Dict, Literal, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
"""The Facet workspace's version (Cargo's), the same as ``facet --version``."""

PathLike = Union[str, os.PathLike]
ArrayLike = npt.ArrayLike
Model = Literal["tabulated", "ggx", "beckmann"]

class FacetError(ValueError):
    """An error of Facet with the message the ``facet`` command prints, naming the file or
    input. A missing or unreadable file is a FacetError too (not an OSError)."""

class Brdf:
    """A BRDF: measured (MERL, RGL ``.bsdf``, a neural proxy), analytic, or a fit's model."""

    @property
    def name(self) -> str:
        """The source's name (a file's stem, a proxy's name, ``<fit>-ggx``, ...)."""
    @property
    def source(self) -> str:
        """Where it came from, as named: ``load``'s ``source``, ``"from_merl"``, ``fit:NAME:MODEL``."""
    @property
    def is_isotropic(self) -> bool:
        """Whether f_r is invariant under rotation about the normal."""
    def eval(self, wi: ArrayLike, wo: ArrayLike) -> npt.NDArray[np.float64]:
        """f_r(wi, wo) per RGB channel without the cosine, shape (N, 3), for directions of shape
        (N, 3) in the local frame (z the normal, pointing away from the surface; not
        normalised here). NaN where the source has no value (at or below the horizon, a
        missing MERL sample). All cores (``RAYON_NUM_THREADS``), the GIL released."""
    def to_merl(self) -> npt.NDArray[np.float64]:
        """The MERL-grid table, shape (3, 90, 90, 180) (channel, θh, θd, φd), f_r values (the
        file's values times its scales), −1 where missing; what ``from_merl`` takes."""
    def save(self, path: PathLike) -> None:
        """Writes ``.binary`` (MERL) or ``.bsdf`` (RGL) by extension, as ``facet convert``;
        replaces an existing file."""

class Fit:
    """A fit: the record ``facet fit`` writes, and its models."""

    @property
    def name(self) -> str:
        """The fitted material's name."""
    @property
    def record(self) -> Dict[str, Any]:
        """The fit JSON ``facet fit`` writes, as a dict (the same serialisation)."""
    def to_json(self) -> str:
        """The record as the pretty-printed JSON text of the file."""
    def model(self, model: Model = "tabulated", *, coated: bool = False) -> Brdf:
        """One fitted model as a Brdf; ``coated=True``: under the coat the fit kept."""
    def save(self, path: PathLike) -> None:
        """Writes the fit JSON as ``facet fit`` does; ``load(path)`` reads it back."""
    def ndf(self, theta: ArrayLike, phi: float = 0.0) -> npt.NDArray[np.float64]:
        """The tabulated NDF D(θ, φ) at polar angles ``theta`` (radians), in theta's shape."""
    def export(
        self,
        target: Literal["mitsuba", "pbrt", "gltf"] = "mitsuba",
        model: Literal["ggx", "beckmann", "best"] = "ggx",
        *,
        kind: Literal["auto", "conductor", "plastic"] = "auto",
        coat: bool = False,
        table_dir: Optional[PathLike] = None,
    ) -> Tuple[str, Dict[str, Any]]:
        """``facet export``'s file text and its statement of what it approximates, as a dict."""
    def to_mitsuba(
        self,
        model: Literal["ggx", "beckmann", "best"] = "ggx",
        *,
        kind: Literal["auto", "conductor", "plastic"] = "auto",
        coat: bool = False,
        table_dir: Optional[PathLike] = None,
    ) -> Dict[str, Any]:
        """The Mitsuba export as a dict for ``mitsuba.load_dict``."""

def load(source: PathLike, nbrdf: Optional[PathLike] = None) -> Brdf:
    """Every input ``facet fit`` takes: a MERL ``.binary``, an RGL ``.bsdf``, ``nbrdf:NAME``,
    ``analytic:SPEC``, a fit ``.json``."""

def from_merl(array: ArrayLike, name: str = "from_merl") -> Brdf:
    """A MERL measurement from an array of shape (3, 90, 90, 180) of f_r values, negative
    where missing (``Brdf.to_merl``'s layout)."""

def fit(
    source: Union[PathLike, Brdf],
    *,
    aniso: bool = False,
    coat: Literal["auto", "always", "off"] = "auto",
    backend: Literal["cpu", "auto", "gpu"] = "cpu",
    model: Literal["all", "tabulated", "ggx", "beckmann"] = "all",
    resolution: Optional[int] = None,
    phi_resolution: int = 64,
    iterations: Optional[int] = None,
    tolerance: float = 1e-9,
    quadrature: Literal["uniform-theta", "sqrt-midpoint", "gauss-legendre-sqrt"] = "gauss-legendre-sqrt",
    no_diffuse: bool = False,
    no_refine: bool = False,
    fresnel: Literal["table", "conductor", "dielectric", "schlick"] = "table",
    metric: Optional[Literal["perceptual", "log"]] = None,
    nbrdf: Optional[PathLike] = None,
) -> Fit:
    """``facet fit``'s fit with its options, the GIL released; ``backend="gpu"`` raises
    FacetError (CPU-only build)."""
