// Extend stage: closest hit of every flying path (CWBVH traversal, render/bvh.inc.wgsl). A miss
// adds the environment (weighted against light sampling, `emission_weight`) and ends the path; a hit adds the
// surface's emission (likewise), widens the ray cone to the hit and queues the path for its
// material's shading stage.

#include "render/frame.inc.wgsl"
#include "render/bvh.inc.wgsl"
#include "render/scene.inc.wgsl"

@compute @workgroup_size(WG)
fn extend(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_EXTEND, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    let o = path_get(R_ORIGIN, slot);
    let d = path_get(R_DIR, slot);
    let beta = path_get(R_BETA, slot);
    var l = path_get(R_L, slot);
    let hit = trace_closest(o.xyz, d.xyz, 3.0e38);
    if (hit.prim == 0xffffffffu) {
        if (frame.scene.env_kind != ENV_NONE) {
            let w = emission_weight(beta.w, env_light_pmf() * env_pdf(d.xyz));
            l = vec4<f32>(l.xyz + beta.xyz * env_radiance(d.xyz) * w, l.w);
            path_set(R_L, slot, l);
        }
        info[slot].x = SLOT_ENDED;
        return;
    }
    let s = surface_at(hit.prim, hit.u, hit.v, -d.xyz);
    let le = emitted(s);
    if (any(le > vec3<f32>(0.0))) {
        // The light BVH is asked as next-event estimation asked it at the ray's origin.
        let n = path_get(R_PREV_N, slot).xyz;
        let w = emission_weight(beta.w, triangle_light_pdf(hit.prim, o.xyz, o.xyz, n, s.p, s.ng, s.area));
        path_set(R_L, slot, vec4<f32>(l.xyz + beta.xyz * le * w, l.w));
    }
    path_set(R_HIT, slot, vec4<f32>(hit.t, bitcast<f32>(hit.prim), hit.u, hit.v));
    // Cone width at the hit: w + spread · t.
    path_set(R_ORIGIN, slot, vec4<f32>(o.xyz, abs(o.w + d.w * hit.t)));
    push(materials[s.material].queue, slot);
}

