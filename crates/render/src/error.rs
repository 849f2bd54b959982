//! Errors of the renderer, each naming the file or resource at fault.

use std::path::PathBuf;

/// Why a scene could not be loaded, prepared or rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A scene, texture, environment or material file that cannot be used.
    #[error("{}: {message}", path.display())]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// An output file that cannot be written.
    #[error("writing {}: {message}", path.display())]
    Output {
        /// The file.
        path: PathBuf,
        /// Why it could not be written.
        message: String,
    },
    /// A scene that loaded but cannot be rendered (no triangles, a bad camera).
    #[error("{0}")]
    Scene(String),
    /// A GPU resource sized by input (the scene, a fit, the environment map, the render size)
    /// over a limit of the device, refused before it is created.
    #[error(
        "{what}: {} is more than this adapter's {limit_name} ({limit}); the size comes from {set_by}",
        amount(*needed, unit)
    )]
    TooLarge {
        /// The resource.
        what: String,
        /// How much of `unit` it needs (`u64::MAX`: more than a u64 counts).
        needed: u64,
        /// The unit of `needed` and `limit` (bytes, texels, ...).
        unit: &'static str,
        /// The wgpu limit that it exceeds.
        limit_name: &'static str,
        /// That limit's value on this device.
        limit: u64,
        /// The input that sets the size (a scene file, the render size, ...).
        set_by: String,
    },
    /// An error of the GPU layer.
    #[error(transparent)]
    Gpu(#[from] facet_gpu::GpuError),
}

impl RenderError {
    /// [`RenderError::Input`] for `path` with `message`.
    pub fn input(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        RenderError::Input {
            path: path.into(),
            message: message.to_string(),
        }
    }
}

impl From<facet_brdf::io::input::InputError> for RenderError {
    fn from(e: facet_brdf::io::input::InputError) -> Self {
        RenderError::Input {
            path: e.path,
            message: e.problem,
        }
    }
}

/// `needed unit`, or "over u64::MAX unit" for a size that saturated.
fn amount(needed: u64, unit: &str) -> String {
    if needed == u64::MAX {
        format!("over {needed} {unit}")
    } else {
        format!("{needed} {unit}")
    }
}
