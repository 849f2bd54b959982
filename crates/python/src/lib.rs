//! # facet-python: Facet from Python
//!
//! The extension module of the Python package `facet-brdf` (import `facet_brdf`), built by
//! maturin from `pyproject.toml` (`pip install ./crates/python`). The module is
//! `facet_brdf._native`; `python/facet_brdf/__init__.py` re-exports it, and
//! `python/facet_brdf/__init__.pyi` types it.
//!
//! | Python | Rust |
//! |---|---|
//! | `load(source, nbrdf=None)` | [`facet_fit::sources::InputSpec::parse`] and `open` |
//! | `from_merl(array)` | [`facet_fit::model::merl_grid::MerlTable`] parsed as a file, [`facet_fit::sources::merl::MerlBrdf::from_table`] |
//! | `Brdf.eval`, `to_merl`, `save` | [`facet_fit::Brdf::eval`] over rayon with the GIL released, `merl_table`, [`facet_fit::export::rgl::write_rgl`] |
//! | `fit(...)`, `Fit.record`, `Fit.model`, `Fit.to_mitsuba` | [`facet_fit::fitting::fit_material`], the fit JSON's serde path, [`facet_fit::export::export`] |
//! | `FacetError` (a `ValueError`) | [`facet_fit::FitError`]'s `Display`, the message `facet` prints |
//!
//! The functions are documented in Python (docstrings and stubs); `docs/python.md` is the
//! guide.
#![warn(missing_docs)]

pub mod arrays;
pub mod brdf;
pub mod error;
pub mod fit;
pub mod merl;

use pyo3::prelude::*;

/// The module `facet_brdf._native`.
#[pymodule]
#[pyo3(name = "_native")]
fn native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("FacetError", m.py().get_type::<error::FacetError>())?;
    m.add_class::<brdf::PyBrdf>()?;
    m.add_class::<fit::PyFit>()?;
    m.add_function(wrap_pyfunction!(brdf::load, m)?)?;
    m.add_function(wrap_pyfunction!(brdf::from_merl, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    Ok(())
}
