//! The one error type of the benchmarks: the step of a measurement that failed, with its cause.

use thiserror::Error;

/// Why a section stopped.
#[derive(Debug, Error)]
pub enum BenchError {
    /// A scene, its resources or the integrator.
    #[error(transparent)]
    Render(#[from] facet_render::RenderError),
    /// A pipeline, a buffer, a timer or the glint tables on the GPU.
    #[error(transparent)]
    Gpu(#[from] facet_gpu::GpuError),
    /// A material's source or its fit.
    #[error(transparent)]
    Fit(#[from] facet_fit::FitError),
    /// Waiting for the GPU.
    #[error("waiting for the GPU: {0}")]
    Poll(#[from] wgpu::PollError),
    /// A file or a process of the shard section, named by `what`.
    #[error("{what}: {source}")]
    Io {
        /// What was read, written or run.
        what: String,
        /// Why it failed.
        source: std::io::Error,
    },
    /// A shard's fit record that is not JSON.
    #[error("a shard's fit record: {0}")]
    Json(#[from] serde_json::Error),
    /// Anything else, in words: a material a loader refuses, an output not as expected.
    #[error("{0}")]
    Other(String),
}

/// A benchmark's result.
pub type Result<T, E = BenchError> = std::result::Result<T, E>;

impl BenchError {
    /// An I/O error on `what`.
    pub fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> BenchError {
        let what = what.into();
        move |source| BenchError::Io { what, source }
    }
}
