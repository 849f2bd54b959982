//! # facet-render: a wavefront path tracer on wgpu
//!
//! The crate's folders, in the order a render flows through them:
//!
//! | room | what it holds |
//! |---|---|
//! | [`scene`] | glTF scenes ([`scene::load_gltf`]): meshes, materials (measured ones included), lights, the camera and its frame |
//! | [`bvh`] | the obvhs CWBVH, its GPU form, a batch ray query ([`RayTracer`]) |
//! | [`layout`] | what the resources and the integrator agree on with the WGSL: the GPU records, the closed-set tags, the bind groups, the queues, the device limits |
//! | [`materials`] | the material classes, one file each: a class's block of the GPU record, its plan, its queue and shading stage |
//! | [`resources`] | a scene on the GPU: BVH, material plan, tables, glint pyramids, textures, lights and their BVH |
//! | [`integrator`] | the wavefront loop ([`Integrator`]) and its stages — logic, generate, extend, shade per material class, connect — as compute passes over queues; a [`Wavefront`] (the GPU state of one image); the render's settings ([`integrator::config`]) |
//! | [`output`] | the film read back as PNG and EXR, the tone map, a shard's record, the merge of shards |
//!
//! [`Integrator::render_more`] accumulates samples in a wavefront's film on the GPU,
//! [`Wavefront::tone_mapped`] reads back the PNG tone map and [`Integrator::profile_iteration`]
//! times each stage.
//!
//! ```no_run
//! use facet_render::{Integrator, RenderConfig, ResourceConfig, SceneResources, scene::CameraFrame};
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

// The rooms (the map above is their order in a render).
pub mod bvh;
mod error;
pub mod integrator;
pub mod layout;
pub mod materials;
pub mod output;
pub mod resources;
pub mod scene;

pub use bvh::query::{GpuHit, GpuRay, RayTracer};
pub use bvh::{Bvh, BvhConfig, BvhPreset, GpuBvh, Hit};
pub use error::RenderError;
pub use facet_gpu::{Gpu, GpuError};
/// The vector library of the scene types ([`scene::Camera`], [`scene::Environment`], ...).
pub use glam;
pub use integrator::config::{
    ImageConfig, NdfSampling, RenderConfig, SampleConfig, Sequence, Strategy,
};
pub use integrator::wavefront::Wavefront;
pub use integrator::{Integrator, RenderStats, StageClock, StageTime};
/// The BVH library, whose types [`Bvh`] exposes.
pub use obvhs;
pub use output::film::Image;
pub use resources::{Built, LightSelection, ResourceConfig, SceneResources};
