//! # facet-gpu: the wgpu layer of Facet
//!
//! Adapter and device selection ([`Gpu`]), WGSL loading from `shaders/` with includes and naga
//! validation ([`shader`]), closed sets written once for Rust and WGSL ([`tags!`],
//! [`tags`](mod@tags)), buffer upload and read-back ([`buffer`]), GPU timestamps
//! ([`timer::GpuTimer`]) and errors a caller can act on ([`GpuError`]), and for tests the GPU or a visible skip
//! ([`gpu_for_tests`], [`skip`]). Nothing domain-specific.
//!
//! ```no_run
//! let gpu = facet_gpu::Gpu::new()?; // honours FACET_BACKEND and FACET_ADAPTER
//! println!("{}", gpu.describe());
//! let pipeline = facet_gpu::shader::compute_pipeline(&gpu.device, "fit/kernel.wgsl", "kernel", &[("ISOTROPIC", 1.0)])?;
//! # Ok::<(), facet_gpu::GpuError>(())
//! ```

#![warn(missing_docs)]

pub mod buffer;
mod context;
pub mod dispatch;
mod error;
mod runtime_dir;
pub mod shader;
pub mod skip;
pub mod tags;
pub mod timer;

pub use context::{Gpu, GpuOptions, gpu_for_tests, gpu_for_tests_with};
pub use error::GpuError;
pub use runtime_dir::ensure_runtime_dir;
pub use skip::report_skip;
