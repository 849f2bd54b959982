// Include-only. The body every shading stage shares: next-event estimation toward one light
// (MIS with BSDF sampling, power heuristic, unless frame.strategy picks one technique), a BSDF
// sample for the continuation, the ray cone's new spread. The includer defines `Bsdf` and
//   bsdf_setup(s, slot) -> Bsdf,
//   bsdf_eval2(b, wi_light, wi_bsdf, wo) -> f of both directions (no cosine; a direction with
//     z ≤ 0 is not needed), so a class whose evaluation walks a structure (glints) walks once,
//   bsdf_pdf(b, wi, wo) -> solid-angle pdf, bsdf_sample_wi(b, wo, u) -> a sampled direction,
//   bsdf_roughness(b) -> α of the lobe (for the cone),
// all in the local shading frame (z the normal).

#include "common/math.inc.wgsl"

// Random numbers of a bounce: 0..2 light choice and point, 3..5 BSDF sample, 6 the class's own
// (glints: the direction cell), 7 roulette.
fn shade(slot: u32) {
    let hit = path_get(R_HIT, slot);
    let prim = bitcast<u32>(hit.y);
    let o = path_get(R_ORIGIN, slot);
    let d = path_get(R_DIR, slot);
    var beta = path_get(R_BETA, slot);
    var l = path_get(R_L, slot);
    var i = info[slot];
    let wo_world = -d.xyz;
    let s = surface_at(prim, hit.z, hit.w, wo_world);
    // pbrt's rule: the vertex at max depth adds its emission (done in extend) and nothing more.
    if (i.z >= frame.max_depth) {
        info[slot].x = SLOT_ENDED;
        return;
    }
    let b = bsdf_setup(s, slot);
    let wo = to_local(s, wo_world);

    // Next-event estimation's direction and the continuation's, then both evaluated at once.
    // The light BVH is asked where the continuation ray will start (its origin, R_ORIGIN).
    let sel = offset_origin(s, s.ng);
    let ls = sample_light(s.p, sel, s.ng, path_rand(slot, 0u), vec2<f32>(path_rand(slot, 1u), path_rand(slot, 2u)));
    let nee = frame.strategy != STRATEGY_BSDF || ls.pdf <= 0.0;
    var wi_light = vec3<f32>(0.0, 0.0, -1.0);
    if (nee && any(ls.weight > vec3<f32>(0.0)) && dot(ls.wi, s.ng) > 0.0) {
        wi_light = to_local(s, ls.wi);
    }
    let wi_bsdf = bsdf_sample_wi(b, wo, vec3<f32>(path_rand(slot, 3u), path_rand(slot, 4u), path_rand(slot, 5u)));
    let f = bsdf_eval2(b, wi_light, wi_bsdf, wo);

    if (wi_light.z > 0.0) {
        let wi = wi_light;
        let w = light_sample_weight(ls.pdf, bsdf_pdf(b, wi, wo));
        let c = beta.xyz * f[0] * wi.z * ls.weight * w;
        if (any(c > vec3<f32>(0.0))) {
            let origin = offset_origin(s, ls.wi);
            let tmax = max(ls.dist - length(origin - s.p) - 2.0 * frame.ray_epsilon * (1.0 + ls.dist), 0.0);
            path_set(R_SHADOW_O, slot, vec4<f32>(origin, tmax));
            path_set(R_SHADOW_D, slot, vec4<f32>(ls.wi, 0.0));
            path_set(R_SHADOW_C, slot, vec4<f32>(c, 0.0));
            push(Q_SHADOW, slot);
        }
    }

    // Continuation by BSDF sampling.
    let wi_world = to_world(s, wi_bsdf);
    let pdf = bsdf_pdf(b, wi_bsdf, wo);
    if (pdf <= 0.0 || wi_bsdf.z <= 0.0 || dot(wi_world, s.ng) <= 0.0) {
        info[slot].x = SLOT_ENDED;
        return;
    }
    beta = vec4<f32>(beta.xyz * f[1] * wi_bsdf.z / pdf, pdf);
    if (!all(beta.xyz == beta.xyz) || all(beta.xyz <= vec3<f32>(0.0))) {
        info[slot].x = SLOT_ENDED;
        return;
    }
    // Ray cone: the spread grows by the curvature (2 k w) and by the lobe's width (2 atan α).
    let width = o.w;
    let spread = d.w + 2.0 * s.curvature * width + 2.0 * atan(bsdf_roughness(b));
    path_set(R_BETA, slot, beta);
    path_set(R_ORIGIN, slot, vec4<f32>(offset_origin(s, wi_world), width));
    path_set(R_PREV_N, slot, vec4<f32>(s.ng, 0.0));
    path_set(R_DIR, slot, vec4<f32>(wi_world, spread));
    info[slot] = vec4<u32>(SLOT_FLYING, i.y, i.z + 1u, i.w);
}

// ---- the microfacet pieces the stages share -----------------------------------------------

// Cosine-weighted hemisphere, pdf cos θ / π.
fn sample_cosine(u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
}
