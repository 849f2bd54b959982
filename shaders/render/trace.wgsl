// Ray queries against the scene's CWBVH (bvh.inc.wgsl does the work): the batch entry points
// behind facet_render::trace::RayTracer, used by tests and benchmarks and as the extend stage's
// reference. Two schedules, chosen at pipeline creation (facet_render::trace::TraceVariant):
// one thread per ray (`trace_*_rays`), or persistent threads (`trace_*_persistent`); WG, the
// workgroup size, is an override of both.

#include "render/bvh.inc.wgsl"

override WG: u32 = 64u;

// tmin is unused (keep 0): triangles count from t = 0 and nodes from t = 1e-4, as in obvhs.
struct Ray {
    origin: vec3<f32>,
    tmin: f32,
    dir: vec3<f32>,
    tmax: f32,
}

@group(0) @binding(0) var<storage, read> bvh_nodes: array<CwNode>;
@group(0) @binding(1) var<storage, read> bvh_primitives: array<u32>;
@group(0) @binding(2) var<storage, read> bvh_triangles: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> rays: array<Ray>;
// Each entry point writes one of these (the pipelines' layouts come from the shader).
@group(0) @binding(4) var<storage, read_write> hits: array<Hit>;
@group(0) @binding(5) var<storage, read_write> occluded: array<u32>;
// The persistent schedule's next ray to fetch (0 before each dispatch).
@group(0) @binding(6) var<storage, read_write> next_ray: atomic<u32>;

@compute @workgroup_size(WG)
fn trace_closest_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    bvh_lane = lid;
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[i];
    hits[i] = trace_closest(ray.origin, ray.dir, ray.tmax);
}

@compute @workgroup_size(WG)
fn trace_any_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
        @builtin(local_invocation_index) lid: u32) {
    bvh_lane = lid;
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[i];
    occluded[i] = select(0u, 1u, trace_any(ray.origin, ray.dir, ray.tmax));
}

// Persistent threads (Aila & Laine, "Understanding the Efficiency of Ray Traversal on GPUs",
// HPG 2009): a fixed set of workgroups loops, each taking the next WG rays with one atomic add,
// so that a workgroup whose rays end early fetches more instead of waiting for the dispatch's
// slowest. With WG the SIMD width (32 on NVIDIA), a workgroup is one warp, as in the paper.
var<workgroup> batch_start: u32;

// The first ray of the workgroup's next batch (the same in every invocation).
fn next_batch(lid: u32) -> u32 {
    if (lid == 0u) {
        batch_start = atomicAdd(&next_ray, WG);
    }
    return workgroupUniformLoad(&batch_start);
}

@compute @workgroup_size(WG)
fn trace_closest_persistent(@builtin(local_invocation_index) lid: u32) {
    bvh_lane = lid;
    let n = arrayLength(&rays);
    for (var start = next_batch(lid); start < n; start = next_batch(lid)) {
        let i = start + lid;
        if (i < n) {
            let ray = rays[i];
            hits[i] = trace_closest(ray.origin, ray.dir, ray.tmax);
        }
    }
}

@compute @workgroup_size(WG)
fn trace_any_persistent(@builtin(local_invocation_index) lid: u32) {
    bvh_lane = lid;
    let n = arrayLength(&rays);
    for (var start = next_batch(lid); start < n; start = next_batch(lid)) {
        let i = start + lid;
        if (i < n) {
            let ray = rays[i];
            occluded[i] = select(0u, 1u, trace_any(ray.origin, ray.dir, ray.tmax));
        }
    }
}
