// The closest hit of each ray of a batch (RayTracer's `Query::Closest`).

#include "render/ray_batch.inc.wgsl"

@group(0) @binding(4) var<storage, read_write> hits: array<Hit>;

@compute @workgroup_size(WG)
fn trace_closest_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[i];
    hits[i] = trace_closest(ray.origin, ray.dir, ray.tmax);
}
