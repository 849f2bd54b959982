//! Structs shared with WGSL, `#[repr(C)]` + Pod; `tests/shaders.rs` checks each size and offsets
//! against what naga computes for its WGSL twin.

use bytemuck::{Pod, Zeroable};

pub use crate::layout::tags::{LightKind, MaterialKind};

/// Texture index meaning "none" (WGSL `NONE`).
pub const NONE: u32 = u32::MAX;

/// Regions of the path-state buffer ([`Region`](crate::layout::tags::Region)), one vec4 per slot each.
pub const PATH_REGIONS: u64 = crate::layout::tags::Region::ALL.len() as u64;

/// WGSL `SceneInfo` (`shaders/render/frame.inc.wgsl`): what the frame uniform carries of the
/// scene — its sizes, the light-selection CDF and the environment — made once by
/// [`SceneResources::new`](crate::SceneResources::new) and copied whole into every frame.
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuSceneInfo {
    /// Vertices uploaded.
    pub n_vertices: u32,
    /// Lights uploaded.
    pub n_lights: u32,
    /// Word offset of the light-selection CDF in the scene tables.
    pub light_cdf: u32,
    /// [`EnvKind`](crate::layout::tags::EnvKind) as `u32`.
    pub env_kind: u32,
    /// The environment map's size (1 × 1 without a map).
    pub env_width: u32,
    pub env_height: u32,
    /// Word offsets of the map's texels, marginal and conditional CDFs in the scene tables.
    pub env_texels: u32,
    pub env_marginal: u32,
    pub env_conditional: u32,
    /// Radius of the scene's bounding sphere.
    pub scene_radius: f32,
    /// The probability that next-event estimation asks the light BVH (0 without one).
    pub light_tree_share: f32,
    /// Nodes of the light BVH (0: lights picked by the CDF alone).
    pub light_tree_nodes: u32,
    /// A constant environment's radiance (rgb).
    pub env_color: [f32; 4],
}

/// WGSL `Frame` (`shaders/render/frame.inc.wgsl`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuFrame {
    pub width: u32,
    pub height: u32,
    pub tile_base: u32,
    pub tile_pixels: u32,
    pub wavefront: u32,
    pub sample_end: u32,
    pub max_depth: u32,
    pub seed: u32,
    pub rr_depth: u32,
    pub ray_epsilon: f32,
    /// [`Strategy`](crate::layout::tags::Strategy) as `u32`.
    pub strategy: u32,
    /// [`NdfSampling`](crate::layout::tags::NdfSampling) as `u32`.
    pub ndf_sampling: u32,
    /// 1: the film's squares are accumulated too (`Integrator::wavefront_with_variance`).
    pub moments: u32,
    /// [`Sequence`](crate::layout::tags::Sequence) as `u32`.
    pub sequence: u32,
    pub pad1: u32,
    pub pad2: u32,
    /// The scene's part, the same in every frame.
    pub scene: GpuSceneInfo,
    pub cam_pos: [f32; 4],
    pub cam_forward: [f32; 4],
    pub cam_up: [f32; 4],
    pub cam_right: [f32; 4],
}

/// WGSL `Light`.
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    pub kind: u32,
    pub prim: u32,
    pub cos_inner: f32,
    pub cos_outer: f32,
    pub position: [f32; 4],
    pub direction: [f32; 4],
    pub intensity: [f32; 4],
    /// Its leaf in the light BVH (NONE: not in the tree, or no tree).
    pub leaf: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}
