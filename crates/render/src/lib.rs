//! # facet-render: a wavefront path tracer on wgpu
//!
//! glTF scenes ([`scene::load_gltf`]), an obvhs CWBVH traversed in WGSL ([`bvh`]), and a
//! wavefront integrator ([`Integrator`]) whose stages — logic, generate, extend, shade per
//! material class (glTF metallic-roughness, fitted analytic or tabulated microfacet, glints),
//! connect — are separate compute passes over queues. The integrator holds the pipelines and the
//! loop; a [`Wavefront`] holds the GPU state of one image (path state, queues, film) for reuse,
//! and reads it back. [`Integrator::render_more`] accumulates samples in a wavefront's film on the
//! GPU, [`Wavefront::tone_mapped`] reads back the PNG tone map and
//! [`Integrator::profile_iteration`] times each stage. A render's settings come in two parts
//! ([`config`]): the image, fixed for a wavefront, and the sampling. The closed sets shared with
//! WGSL are in [`tags`].
//!
//! ```no_run
//! use facet_render::{Integrator, RenderConfig, ResourceConfig, SceneResources, camera::CameraFrame};
//! let gpu = facet_gpu::Gpu::new()?;
//! let scene = facet_render::scene::load_gltf("scene.gltf".as_ref(), &Default::default())?;
//! let env = facet_render::scene::Environment::Constant(glam::Vec3::splat(1.0));
//! let res = SceneResources::new(&gpu, &scene, Some(&env), ResourceConfig::standard())?;
//! let integrator = Integrator::new(&gpu.device, &res)?;
//! let camera = CameraFrame::new(&scene.camera)?;
//! let (image, stats) = integrator.render(&gpu, &res, &camera, &RenderConfig::preview(), &mut |_| {})?;
//! image.write_png("out.png".as_ref(), 0.0)?;
//! # Ok::<(), facet_render::RenderError>(())
//! ```

#![warn(missing_docs)]
// `!(x > 0.0)` is how the validators reject NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bindings;
pub mod bvh;
pub mod camera;
pub mod config;
mod error;
pub mod gpu_types;
mod integrator;
pub(crate) mod limits;
pub mod output;
pub mod pacing;
pub mod procedural;
pub(crate) mod queues;
pub mod resources;
pub mod scene;
pub(crate) mod stages;
pub mod tags;
pub mod trace;
pub mod wavefront;

pub use bvh::{Bvh, BvhConfig, BvhPreset, GpuBvh, Hit};
pub use config::{ImageConfig, NdfSampling, RenderConfig, SampleConfig, Sequence, Strategy};
pub use error::RenderError;
pub use facet_gpu::{Gpu, GpuError};
/// The vector library of the scene types ([`scene::Camera`], [`scene::Environment`], ...).
pub use glam;
pub use integrator::{Integrator, RenderStats, StageClock, StageTime};
/// The BVH library, whose types [`Bvh`] exposes.
pub use obvhs;
pub use output::film::Image;
pub use resources::{Built, LightSelection, ResourceConfig, SceneResources};
pub use trace::{GpuHit, GpuRay, RayTracer};
pub use wavefront::Wavefront;
