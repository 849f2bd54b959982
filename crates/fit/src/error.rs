//! Errors of the fitting library: facet-brdf's error type, under the name the fitter's callers
//! know. The readers below the fit and the fit itself fail with the same variants.

pub use facet_brdf::error::BrdfError as FitError;
