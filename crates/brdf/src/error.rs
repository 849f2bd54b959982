//! Errors of reading, modelling and fitting a BRDF. Every variant names the file or input it
//! concerns. One type for the readers here and the fitter above them (facet-fit re-exports it as
//! `FitError`), so that a caller matches one set of variants whichever layer failed.

use std::path::PathBuf;

/// Why a source could not be read or fitted.
#[derive(Debug, thiserror::Error)]
pub enum BrdfError {
    /// A file that is not a regular file, too large for its kind, or unreadable.
    #[error(transparent)]
    Input(#[from] crate::io::input::InputError),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// A file that is not a MERL `.binary` BRDF (wrong size, bad dimensions, bad values).
    #[error("{path}: not a MERL BRDF file: {problem}")]
    Merl {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A file that is not a usable RGL `.bsdf` (tensor file damaged, fields missing or of the
    /// wrong shape, densities that are not densities), or a source that cannot be written as one.
    #[error("{path}: RGL .bsdf: {problem}")]
    Bsdf {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A neural-proxy file (or an entry of it) of the wrong shape, or a name it does not hold.
    #[error("{path}: neural BRDF file: {problem}")]
    Nbrdf {
        /// The file (the embedded one has a label in its place).
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// A fit JSON that does not parse or does not describe a usable material.
    #[error("{path}: fit file: {problem}")]
    Material {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// An input specification (`nbrdf:NAME`, `analytic:...`) that cannot be used.
    #[error("input `{spec}`: {problem}")]
    Spec {
        /// The specification as given.
        spec: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A GPU failure during a fit (facet-fit's `fit_material_on` falls back to the CPU on it;
    /// only its `gpu` feature returns it).
    #[error("{name}: on the GPU: {source}")]
    Gpu {
        /// The source being fitted.
        name: String,
        /// The GPU layer's error (a `facet_gpu::GpuError`).
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The extraction or the fit failed for this source (no valid sample on the MERL grid,
    /// values out of range, a diverging power iteration, tables that make no material).
    #[error("{name}: cannot extract an NDF: {problem}")]
    Extraction {
        /// The source being fitted.
        name: String,
        /// What is wrong.
        problem: String,
    },
}

impl BrdfError {
    /// [`BrdfError::Io`] for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        BrdfError::Io {
            path: path.into(),
            source,
        }
    }
}
