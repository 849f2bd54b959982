//! Errors of the renderer, each naming the file or resource at fault.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A scene, texture, environment or material file that cannot be used.
    #[error("{}: {message}", path.display())]
    Input { path: PathBuf, message: String },
    /// An output file that cannot be written.
    #[error("writing {}: {message}", path.display())]
    Output { path: PathBuf, message: String },
    /// A scene that loaded but cannot be rendered (no triangles, a bad camera).
    #[error("{0}")]
    Scene(String),
    #[error(transparent)]
    Gpu(#[from] facet_gpu::GpuError),
}

impl RenderError {
    pub fn input(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        RenderError::Input {
            path: path.into(),
            message: message.to_string(),
        }
    }
}

impl From<facet_fit::input::InputError> for RenderError {
    fn from(e: facet_fit::input::InputError) -> Self {
        RenderError::Input {
            path: e.path,
            message: e.problem,
        }
    }
}
