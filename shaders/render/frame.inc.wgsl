// Include-only. Group 0 of every integrator stage: the frame, the path state in
// structure-of-arrays form, the queues and the film (Rust twin: facet_render::layout::gpu_types).
//
// Path state: `paths` holds one vec4 region per field, W = frame.wavefront slots each:
// region r of slot s is paths[r * W + s]. `info` is per slot (flags, next sample, depth, -).

// The stage's workgroup size, from Rust: facet_render::stages::STAGE_WORKGROUP.
override WG: u32;

// Queues, numbered from Rust (facet_render::queues::Queue).
override Q_GEN: u32;
override Q_EXTEND: u32;
override Q_SHADOW: u32;

// Path-state regions R_*, slot states SLOT_* (info.x), strategies STRATEGY_*.
#include "render/tags.inc.wgsl"

// Rust: facet_render::layout::gpu_types::GpuSceneInfo. The scene's part of the frame, the same in
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

// Rust: facet_render::layout::gpu_types::GpuFrame.
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
    // SEQUENCE_*
    sequence: u32,
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
    if (frame.sequence == SEQUENCE_SOBOL) {
        return sobol_rand(p, s, d);
    }
    let h = pcg(pcg(pcg(p ^ pcg(frame.seed)) + s) + d);
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// Owen-scrambled Sobol points (Burley 2020, "Practical hash-based Owen scrambling"). The
// dimensions a bounce uses together are paired — the pixel position (0, 1), the light sample's
// point (k = 1, 2 of a bounce) and the BSDF sample's direction (k = 3, 4) — and each pair takes
// the first two dimensions of the Sobol sequence, a (0, 2)-sequence: the first 2^m samples of a
// pixel are then stratified in every elementary interval of area 2^-m of that pair. The other
// dimensions take the first (van der Corput). Each pair's sample index is shuffled and its
// values scrambled by hashes keyed by (pixel, seed, pair), so pairs are independent of one
// another (padding) and every pixel and seed is an independent randomisation: unbiased, as
// the PCG numbers are.

// The Laine-Karras permutation, Burley's constants: bit i of the result depends on bits ≤ i.
fn lk_permutation(x_in: u32, seed: u32) -> u32 {
    var x = x_in + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

// Nested uniform (Owen) scrambling in base 2: each bit flipped by a hash of the bits above it.
fn owen_scramble(x: u32, seed: u32) -> u32 {
    return reverseBits(lk_permutation(reverseBits(x), seed));
}

// The second Sobol dimension of index i, its generator matrix (the Pascal matrix mod 2) a
// column at a time: v_k+1 = v_k ^ (v_k >> 1) from v_1 = 2^31.
fn sobol_second(i: u32) -> u32 {
    var v = 0x80000000u;
    var r = 0u;
    var n = i;
    loop {
        if (n == 0u) {
            break;
        }
        if ((n & 1u) != 0u) {
            r ^= v;
        }
        n = n >> 1u;
        v ^= v >> 1u;
    }
    return r;
}

// Dimension d of sample s of pixel p from the scrambled Sobol points: (the first dimension of
// its pair, which of the pair's two it is).
fn sobol_pair(d: u32) -> vec2<u32> {
    if (d < 2u) {
        return vec2<u32>(0u, d);
    }
    let k = (d - 2u) % DIMS_PER_BOUNCE;
    if (k == 2u || k == 4u) {
        return vec2<u32>(d - 1u, 1u);
    }
    return vec2<u32>(d, 0u);
}

fn sobol_rand(p: u32, s: u32, d: u32) -> f32 {
    let pair = sobol_pair(d);
    let key = pcg(pcg(p ^ pcg(frame.seed)) ^ pcg(pair.x + 0x2545f491u));
    let index = owen_scramble(s, key);
    var x = reverseBits(index);
    if (pair.y == 1u) {
        x = sobol_second(index);
    }
    x = owen_scramble(x, pcg(key ^ (0x68bc21ebu * (pair.y + 1u))));
    return f32(x >> 8u) * (1.0 / 16777216.0);
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
