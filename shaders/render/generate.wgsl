// Generate stage: a camera ray for the next sample of the slot's pixel, with its ray cone
// (Akenine-Möller et al. 2019: width 0 at the pinhole, spread = the pixel's angle).

#include "render/frame.inc.wgsl"

@compute @workgroup_size(WG)
fn generate(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_GEN, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    let px = slot_pixel(slot);
    let s = info[slot].y;
    let x = f32(px % frame.width) + rand(px, s, 0u);
    let y = f32(px / frame.width) + rand(px, s, 1u);
    // NDC in [-1, 1], y up.
    let ndc = vec2<f32>(2.0 * x / f32(frame.width) - 1.0, 1.0 - 2.0 * y / f32(frame.height));
    let tan_half = frame.cam_pos.w;
    let aspect = frame.cam_forward.w;
    let dir = normalize(frame.cam_forward.xyz + ndc.x * tan_half * aspect * frame.cam_right.xyz + ndc.y * tan_half * frame.cam_up.xyz);
    path_set(R_ORIGIN, slot, vec4<f32>(frame.cam_pos.xyz, 0.0));
    path_set(R_DIR, slot, vec4<f32>(dir, frame.cam_up.w));
    path_set(R_BETA, slot, vec4<f32>(1.0, 1.0, 1.0, 0.0));
    path_set(R_L, slot, vec4<f32>(0.0));
    // No MIS for a camera ray (β.w = 0); the light BVH's normal is set by each bounce.
    path_set(R_PREV_N, slot, vec4<f32>(0.0));
    info[slot] = vec4<u32>(SLOT_FLYING, s + 1u, 0u, 0u);
    push(Q_EXTEND, slot);
}
