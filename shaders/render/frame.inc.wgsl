// Include-only. Group 0 of every integrator stage: the frame, the path state in
// structure-of-arrays form, the queues and the film (Rust twin: facet_render::gpu_types).
//
// Path state: `paths` holds one vec4 region per field, W = frame.wavefront slots each:
// region r of slot s is paths[r * W + s]. `info` is per slot (flags, next sample, depth, -).

// The stage's workgroup size, from Rust: facet_render::stages::STAGE_WORKGROUP, the extend
// stage's its facet_render::trace::TraceVariant's.
override WG: u32;

// Queues, numbered from Rust (facet_render::queues::Queue), and the counter a persistent extend
// stage takes its batches from (facet_render::queues::FETCH_COUNTER).
override Q_GEN: u32;
override Q_EXTEND: u32;
override Q_SHADOW: u32;
override Q_FETCH: u32;

// Path-state regions R_*, slot states SLOT_* (info.x), strategies STRATEGY_*.
#include "render/tags.inc.wgsl"

// Rust: facet_render::gpu_types::GpuSceneInfo. The scene's part of the frame, the same in
// every frame of a scene.
struct SceneInfo {
    n_vertices: u32,
    n_lights: u32,
    light_cdf: u32,
    // ENV_*
    env_kind: u32,
    env_width: u32,
    env_height: u32,
    env_texels: u32,
    env_marginal: u32,
    env_conditional: u32,
    scene_radius: f32,
    // the probability of asking the light BVH (0 without one) and its node count
    light_tree_share: f32,
    light_tree_nodes: u32,
    // Constant environment radiance (env_kind ENV_CONSTANT).
    env_color: vec4<f32>,
}

// Rust: facet_render::gpu_types::GpuFrame.
struct Frame {
    width: u32,
    height: u32,
    tile_base: u32,
    tile_pixels: u32,
    wavefront: u32,
    sample_end: u32,
    max_depth: u32,
    seed: u32,
    rr_depth: u32,
    ray_epsilon: f32,
    // STRATEGY_*
    strategy: u32,
    // NDF_SAMPLING_*
    ndf_sampling: u32,
    // 1: also accumulate squared radiance into film_sq (per-pixel variance)
    moments: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    scene: SceneInfo,
    // xyz position, w tan(yfov / 2)
    cam_pos: vec4<f32>,
    // xyz forward, w aspect
    cam_forward: vec4<f32>,
    // xyz up, w pixel spread angle
    cam_up: vec4<f32>,
    // xyz right
    cam_right: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read_write> paths: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> info: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read> sizes: array<u32>;
@group(0) @binding(5) var<storage, read_write> queues: array<u32>;
@group(0) @binding(6) var<storage, read_write> film: array<vec4<f32>>;
// Σ L² per pixel (rgb) when frame.moments is 1; a single texel otherwise.
@group(0) @binding(7) var<storage, read_write> film_sq: array<vec4<f32>>;

fn path_get(region: u32, slot: u32) -> vec4<f32> {
    return paths[region * frame.wavefront + slot];
}

fn path_set(region: u32, slot: u32, v: vec4<f32>) {
    paths[region * frame.wavefront + slot] = v;
}

fn push(q: u32, slot: u32) {
    let k = atomicAdd(&counters[q], 1u);
    queues[q * frame.wavefront + k] = slot;
}

// Thread index of a 2D dispatch.
fn thread_index(gid: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return gid.x + gid.y * nwg.x * WG;
}

// The slot of thread i of a dispatch over queue q, or 0xffffffff past its end.
fn queue_slot(q: u32, i: u32) -> u32 {
    if (i >= sizes[q]) {
        return 0xffffffffu;
    }
    return queues[q * frame.wavefront + i];
}

// Stateless random numbers: PCG hash (Jarzynski & Olano 2020) of (pixel, sample, dimension),
// so an image depends only on the seed, never on scheduling.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Dimension d of sample s of pixel p: a uniform number in [0, 1).
fn rand(p: u32, s: u32, d: u32) -> f32 {
    let h = pcg(pcg(pcg(p ^ pcg(frame.seed)) + s) + d);
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// Random dimensions used per bounce.
const DIMS_PER_BOUNCE: u32 = 8u;

fn slot_pixel(slot: u32) -> u32 {
    return frame.tile_base + slot;
}

// The random number k of the current bounce of a slot's path.
fn path_rand(slot: u32, k: u32) -> f32 {
    let i = info[slot];
    return rand(slot_pixel(slot), i.y - 1u, 2u + i.z * DIMS_PER_BOUNCE + k);
}
