//! Errors of the fitting library. Every variant names the file or input it concerns.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// A file that is not a regular file, too large for its kind, or unreadable.
    #[error(transparent)]
    Input(#[from] crate::input::InputError),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: not a MERL BRDF file: {problem}")]
    Merl { path: PathBuf, problem: String },
    #[error("{path}: neural BRDF file: {problem}")]
    Nbrdf { path: PathBuf, problem: String },
    #[error("{path}: fit file: {problem}")]
    Material { path: PathBuf, problem: String },
    #[error("input `{spec}`: {problem}")]
    Spec { spec: String, problem: String },
    #[cfg(feature = "gpu")]
    #[error("{name}: on the GPU: {source}")]
    Gpu {
        name: String,
        source: facet_gpu::GpuError,
    },
    #[error("{name}: cannot extract an NDF: {problem}")]
    Extraction { name: String, problem: String },
}

impl FitError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        FitError::Io {
            path: path.into(),
            source,
        }
    }
}
