// Ray queries against the scene's CWBVH, one thread per ray (bvh.inc.wgsl does the work): the
// batch entry points behind facet_render::trace::RayTracer, used by tests and benchmarks and as
// the extend stage's reference.

#include "render/bvh.inc.wgsl"

const WG: u32 = 64u;

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

@compute @workgroup_size(WG)
fn trace_closest_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[i];
    hits[i] = trace_closest(ray.origin, ray.dir, ray.tmax);
}

@compute @workgroup_size(WG)
fn trace_any_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[i];
    occluded[i] = select(0u, 1u, trace_any(ray.origin, ray.dir, ray.tmax));
}
