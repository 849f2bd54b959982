//! # facet-render: a wavefront path tracer on wgpu
pub mod error;
pub mod scene;

pub use error::RenderError;
