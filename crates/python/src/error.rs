//! `facet_brdf.FacetError`: every error of the Rust side, with the message `facet` prints.

use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

create_exception!(
    facet_brdf,
    FacetError,
    PyValueError,
    "An error of Facet: a file that cannot be read (a missing one included: FacetError, not \
     OSError), a source or array of the wrong shape, a fit that fails, an option out of range. \
     The message is the one the `facet` command prints, naming the file or input."
);

/// `e` as a [`FacetError`] with `e`'s `Display` (the text `facet` prints after `error: `).
pub fn facet_err(e: impl std::fmt::Display) -> PyErr {
    FacetError::new_err(e.to_string())
}
