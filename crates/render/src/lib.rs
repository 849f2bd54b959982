//! # facet-render: a wavefront path tracer on wgpu
pub mod bvh;
pub mod error;
pub mod procedural;
pub mod scene;
pub mod trace;

pub use bvh::{Bvh, BvhConfig, BvhPreset, GpuBvh, Hit};
pub use error::RenderError;
/// The BVH library, whose types [`Bvh`] exposes.
pub use obvhs;
pub use trace::{GpuHit, GpuRay, RayTracer};
