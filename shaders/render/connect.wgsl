// Connect stage: the shadow rays of next-event estimation. An unoccluded one adds its
// contribution (already MIS-weighted by the shading stage) to the path's radiance.

#include "render/frame.inc.wgsl"
#include "render/bvh.inc.wgsl"
#include "render/scene.inc.wgsl"

@compute @workgroup_size(WG)
fn connect(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_SHADOW, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    let o = path_get(R_SHADOW_O, slot);
    let d = path_get(R_SHADOW_D, slot);
    if (!trace_any(o.xyz, d.xyz, o.w)) {
        let c = path_get(R_SHADOW_C, slot);
        let l = path_get(R_L, slot);
        path_set(R_L, slot, vec4<f32>(l.xyz + c.xyz, l.w));
    }
}
