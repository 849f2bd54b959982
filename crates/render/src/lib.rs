//! # facet-render: a wavefront path tracer on wgpu

// `!(x > 0.0)` is how the validators reject NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod scene;

pub use error::RenderError;
