// Whether each ray of a batch hits anything (RayTracer's `Query::Any`; the output binding is
// trace_closest.wgsl's next one).

#include "render/ray_batch.inc.wgsl"

@group(0) @binding(5) var<storage, read_write> occluded: array<u32>;

@compute @workgroup_size(WG)
fn trace_any_rays(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= arrayLength(&rays)) {
        return;
    }
    let ray = rays[i];
    occluded[i] = select(0u, 1u, trace_any(ray.origin, ray.dir, ray.tmax));
}
