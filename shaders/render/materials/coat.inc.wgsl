// Include-only. A fit's clear coat, a layer over a fitted class's base BSDF (Rust:
// facet_render::materials::coat; twin: facet_brdf::model::coat::Coated):
//   f = w F(η, ωi·h) D_c(h) G2_c / (4 cos θi cos θo) + T(θi) T(θo) f_base(ωi', ωo') / η²,
// D_c GGX of the coat's α, ωi' and ωo' refracted into the coat (sin θ' = sin θ / η), T = 1 − w E_c(θ)
// with E_c the coat lobe's directional albedo, tabulated in the coat's block in `tables`, which the
// material's header names (Material.coat): [n, w, α, η, E_c at cos θ = (k + ½)/n for k < n].
// Sampling: the coat's lobe (its normals, as lobe_sample_h) with probability
//   p = w E_c(θo) / (w E_c(θo) + T(θo) max(base_albedo(b), 0.02)),
// else the base's sampling from ωo', folded into the cone that leaves the coat (coat_fold: a
// direction past the critical angle would be lost) and refracted out;
// pdf = p pdf_coat + (1 − p) q(ωi') cos θi / (η² cos θi'), with q the folded base density,
// q(ω') = pdf_base(ω') + pdf_base(unfold(ω')) cos θ' / (k cos θ_unfolded).
// The includer's Bsdf has a field `coat: Coat` (coat_at), and the includer defines
//   base_eval2(b, wi_light, wi_bsdf, wo), base_pdf(b, wi, wo), base_sample_wi(b, wo, u),
//   base_albedo(b) (an estimate of the base's albedo, for p),
// from which this file defines bsdf_eval2, bsdf_pdf and bsdf_sample_wi for shade.inc.wgsl. A
// material without a coat (coat.block == NONE) is its base, unchanged.

#include "common/microfacet.inc.wgsl"
#include "render/none.inc.wgsl"

struct Coat {
    block: u32,
    weight: f32,
    eta: f32,
    ndf: AnalyticNdf,
}

// The coat whose block is at `o` in `tables` (NONE: none).
fn coat_at(o: u32) -> Coat {
    if (o == NONE) {
        return Coat(NONE, 0.0, 1.0, AnalyticNdf(NDF_KIND_GGX, 1.0, 1.0, 0.0));
    }
    let alpha = tables[o + 2u];
    return Coat(o, tables[o + 1u], tables[o + 3u], AnalyticNdf(NDF_KIND_GGX, alpha, alpha, 0.0));
}

// Into the coat: sin θ' = sin θ / η; a direction below the surface stays below it.
fn coat_in(c: Coat, w: vec3<f32>) -> vec3<f32> {
    if (w.z <= 0.0) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    let s = w.xy / c.eta;
    return vec3<f32>(s, sqrt(max(1.0 - dot(s, s), 0.0)));
}

// Out of the coat; z = −1 at or past the critical angle.
fn coat_out(c: Coat, w: vec3<f32>) -> vec3<f32> {
    let s = w.xy * c.eta;
    let c2 = 1.0 - dot(s, s);
    if (c2 <= 0.0 || w.z <= 0.0) {
        return vec3<f32>(0.0, 0.0, -1.0);
    }
    return vec3<f32>(s, sqrt(c2));
}

// The fold of a direction past the critical angle into the cone (twin: Coat::fold_in): on the
// projected disc sin θ = r > s = 1/η goes to r'² = k (r² − s²), k = s² / (1 − s²), azimuth kept.
fn coat_fold(c: Coat, w: vec3<f32>) -> vec3<f32> {
    let s2 = 1.0 / (c.eta * c.eta);
    let r2 = dot(w.xy, w.xy);
    if (w.z <= 0.0 || r2 <= s2) {
        return w;
    }
    let r2_in = s2 / (1.0 - s2) * (r2 - s2);
    return vec3<f32>(w.xy * sqrt(r2_in / r2), sqrt(max(1.0 - r2_in, 0.0)));
}

// The folded base density q(ω') at ω' inside the cone (see the header; twin: Coat::unfold and
// Coat::fold_density): r² = s² + r'² / k unfolds it.
fn coat_folded_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let c = b.coat;
    let s2 = 1.0 / (c.eta * c.eta);
    let k = s2 / (1.0 - s2);
    let r2_in = dot(wi.xy, wi.xy);
    let r2 = min(s2 + r2_in / k, 1.0);
    let dir = select(vec2<f32>(1.0, 0.0), wi.xy * inverseSqrt(r2_in), r2_in > 0.0);
    let pre = vec3<f32>(dir * sqrt(r2), sqrt(max(1.0 - r2, 0.0)));
    let folded = base_pdf(b, pre, wo) * wi.z / (k * max(pre.z, 1e-7));
    return base_pdf(b, wi, wo) + folded;
}

// E_c(θ), linear in cos θ between the block's nodes.
fn coat_lobe_albedo(c: Coat, cos_theta: f32) -> f32 {
    let n = u32(tables[c.block]);
    let x = max(clamp(cos_theta, 0.0, 1.0) * f32(n) - 0.5, 0.0);
    let k = min(u32(x), n - 2u);
    let t = min(x - f32(k), 1.0);
    return mix(tables[c.block + 4u + k], tables[c.block + 5u + k], t);
}

// T(θ) = 1 − w E_c(θ).
fn coat_transmission(c: Coat, cos_theta: f32) -> f32 {
    return 1.0 - c.weight * coat_lobe_albedo(c, cos_theta);
}

// Unpolarised Fresnel reflectance of a dielectric of relative index η.
fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (r_parl * r_parl + r_perp * r_perp);
}

// The coat's own reflection, w F D G2 / (4 cos θi cos θo).
fn coat_reflection(c: Coat, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let h = normalize(wi + wo);
    let g = g2_correlated(ndf_lambda(c.ndf, wi), ndf_lambda(c.ndf, wo), wi, wo);
    return c.weight * fresnel_dielectric(dot(wi, h), c.eta) * ndf_d(c.ndf, h) * g / (4.0 * wi.z * wo.z);
}

// The probability of sampling the coat's lobe from ωo: its share of the layers' albedos (the
// base's estimate at least 0.02, so that a base that estimates none is still sampled).
fn coat_probability(b: Bsdf, wo: vec3<f32>) -> f32 {
    let r = b.coat.weight * coat_lobe_albedo(b.coat, wo.z);
    let t = coat_transmission(b.coat, wo.z) * max(base_albedo(b), 0.02);
    return select(1.0, r / (r + t), r + t > 0.0);
}

// The coated f for one direction, given the base's value at the refracted pair.
fn coated(c: Coat, wi: vec3<f32>, wo: vec3<f32>, base: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let t = coat_transmission(c, wi.z) * coat_transmission(c, wo.z) / (c.eta * c.eta);
    return vec3<f32>(coat_reflection(c, wi, wo)) + t * base;
}

fn bsdf_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    let c = b.coat;
    if (c.block == NONE) {
        return base_eval2(b, wi_light, wi_bsdf, wo);
    }
    let base = base_eval2(b, coat_in(c, wi_light), coat_in(c, wi_bsdf), coat_in(c, wo));
    return array<vec3<f32>, 2>(coated(c, wi_light, wo, base[0]), coated(c, wi_bsdf, wo, base[1]));
}

fn bsdf_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let c = b.coat;
    if (c.block == NONE) {
        return base_pdf(b, wi, wo);
    }
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let p = coat_probability(b, wo);
    let h = normalize(wi + wo);
    let coat = lobe_pdf_h(c.ndf, wo, h) / (4.0 * abs(dot(wo, h)));
    let wi_in = coat_in(c, wi);
    // dωi' / dωi = cos θi / (η² cos θi')
    let base = coat_folded_pdf(b, wi_in, coat_in(c, wo)) * wi.z / (c.eta * c.eta * wi_in.z);
    return p * coat + (1.0 - p) * base;
}

fn bsdf_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    let c = b.coat;
    if (c.block == NONE) {
        return base_sample_wi(b, wo, u);
    }
    let p = coat_probability(b, wo);
    if (u.z < p) {
        let h = lobe_sample_h(c.ndf, wo, u.xy);
        return 2.0 * dot(wo, h) * h - wo;
    }
    let wi_in = base_sample_wi(b, coat_in(c, wo), vec3<f32>(u.xy, (u.z - p) / (1.0 - p)));
    return coat_out(c, coat_fold(c, wi_in));
}
