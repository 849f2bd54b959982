//! The one error type of the report: the step that failed, the input or file it concerns, and
//! its cause. A step's message names the step; its cause is its [`std::error::Error::source`],
//! which the binary prints after it (anyhow's `{:#}`).

use std::path::PathBuf;
use thiserror::Error;

/// Why a material, the sweep or the page could not be made.
#[derive(Debug, Error)]
pub enum ReportError {
    /// A material's source, its fit, or a fit JSON.
    #[error(transparent)]
    Fit(#[from] facet_fit::FitError),
    /// Fitting an input (at the polar resolution `n` in the sweep).
    #[error("fitting {input}{}", n.map_or(String::new(), |n| format!(" at N = {n}")))]
    Fitting {
        /// The input as given.
        input: String,
        /// The sweep's N; `None` for the report's own fit.
        n: Option<usize>,
        /// Why the fit failed.
        source: facet_fit::FitError,
    },
    /// A scene, its resources, the integrator or the environment map.
    #[error(transparent)]
    Render(#[from] facet_render::RenderError),
    /// Rendering one sphere of a material: `what` names the input and the variant.
    #[error("{what}")]
    Rendering {
        /// The input and the variant rendered.
        what: String,
        /// Why the render failed (boxed: the error stays small on every `Result`'s path).
        source: Box<facet_render::RenderError>,
    },
    /// Writing a file of the page.
    #[error("writing {}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why it could not be written.
        source: std::io::Error,
    },
    /// Encoding or writing a PNG (a render's, or a ΔE image's).
    #[error("writing {}", path.display())]
    Png {
        /// The file.
        path: PathBuf,
        /// Why it could not be written: the image crate's or the renderer's error.
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// Drawing a plot (plotters' error, in words).
    #[error("drawing a plot: {0}")]
    Plot(String),
    /// No input could be reported: there is no page to write.
    #[error("no input could be reported ({failed} failed)")]
    NothingReported {
        /// How many inputs failed.
        failed: usize,
    },
    /// Anything else, in words: a material a loader refuses, a variant with nothing to render.
    #[error("{0}")]
    Other(String),
}

/// A step of the report's result.
pub type Result<T, E = ReportError> = std::result::Result<T, E>;

impl ReportError {
    /// A write error on `path`.
    pub fn write(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> ReportError {
        let path = path.to_owned();
        move |source| ReportError::Write { path, source }
    }
}
