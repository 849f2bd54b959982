// A batch of ray queries against the scene's CWBVH, one thread per ray (bvh.inc.wgsl does the
// work): the rays and the BVH bound, for trace_closest.wgsl and trace_any.wgsl, the pipelines
// behind facet_render::trace::RayTracer (used by tests and benchmarks and as the extend
// stage's reference).

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
