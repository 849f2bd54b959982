// Include-only. The glint BRDF without its Fresnel factor (Rust twin:
// facet_glint::glint_brdf::glint_eval): P from two DPF pyramid levels bracketing γ (R32Float 3D
// textures read at cell centres), the flake count over the footprint (or its mean N a P above the
// threshold when filtering), the correlated G2:
//   f / F = G2 (h·ωo) count / (N a σ(γ) cos θi cos θh cos θo).
// Needs from the includer: `glint_lambda(w) -> Λ(w)` of the material's NDF, `field: Field`,
// `params: EvalParams`, `level0`, `level1`
// (texture_3d<f32>), glint/tea.inc.wgsl, common/microfacet.inc.wgsl, glint/flakes.inc.wgsl and
// glint/lit.inc.wgsl.

#include "common/math.inc.wgsl"

// Rust: facet_glint::gpu::GlintEvalParams.
struct EvalParams {
    gamma: f32,
    // σ(γ) and σ of the two levels; t the weight of the second.
    sigma: f32,
    sigma0: f32,
    sigma1: f32,
    level_t: f32,
    n_theta: u32,
    n_dphi: u32,
    // NDF_KIND_*: GGX, Beckmann, or the renderer's tabulated NDF (alpha, rotation: its stretch).
    ndf_kind: u32,
    alpha_x: f32,
    alpha_y: f32,
    rotation: f32,
    pad0: u32,
}

// Trilinear between cell centres (k + ½)·step, clamped: facet_glint::dpf::DpfTable::lookup.
fn level_lookup(tex: texture_3d<f32>, theta_o: f32, theta_i: f32, dphi: f32) -> f32 {
    let nt = params.n_theta;
    let np = params.n_dphi;
    let st = 0.5 * PI / f32(nt);
    let sp = PI / f32(np);
    let xo = clamp(theta_o / st - 0.5, 0.0, f32(nt - 1u));
    let xi = clamp(theta_i / st - 0.5, 0.0, f32(nt - 1u));
    let xp = clamp(dphi / sp - 0.5, 0.0, f32(np - 1u));
    let o0 = min(u32(xo), max(nt, 2u) - 2u);
    let i0 = min(u32(xi), max(nt, 2u) - 2u);
    let p0 = min(u32(xp), max(np, 2u) - 2u);
    let o1 = min(o0 + 1u, nt - 1u);
    let i1 = min(i0 + 1u, nt - 1u);
    let p1 = min(p0 + 1u, np - 1u);
    let to = xo - f32(o0);
    let ti = xi - f32(i0);
    let tp = xp - f32(p0);
    let a00 = mix(textureLoad(tex, vec3<u32>(p0, i0, o0), 0).x, textureLoad(tex, vec3<u32>(p1, i0, o0), 0).x, tp);
    let a01 = mix(textureLoad(tex, vec3<u32>(p0, i1, o0), 0).x, textureLoad(tex, vec3<u32>(p1, i1, o0), 0).x, tp);
    let a10 = mix(textureLoad(tex, vec3<u32>(p0, i0, o1), 0).x, textureLoad(tex, vec3<u32>(p1, i0, o1), 0).x, tp);
    let a11 = mix(textureLoad(tex, vec3<u32>(p0, i1, o1), 0).x, textureLoad(tex, vec3<u32>(p1, i1, o1), 0).x, tp);
    return mix(mix(a00, a01, ti), mix(a10, a11, ti), to);
}

fn azimuth(w: vec3<f32>) -> f32 {
    return atan2(w.y, w.x);
}

// atan(x) for 0 ≤ x ≤ 1 to f32 accuracy: two half-angle steps, tan(θ/2) = x / (1 + √(1 + x²)),
// bring x below tan(π/16) ≈ 0.2, where the series to x⁹ errs by < 1e-8 (the driver's atan2 may
// err by 1e-4, which moves the blend of direction cells visibly against the CPU).
fn atan_unit(x: f32) -> f32 {
    let x1 = x / (1.0 + sqrt(1.0 + x * x));
    let x2 = x1 / (1.0 + sqrt(1.0 + x1 * x1));
    let t = x2 * x2;
    return 4.0 * x2 * (1.0 - t * (1.0 / 3.0 - t * (0.2 - t * (1.0 / 7.0 - t / 9.0))));
}

// The polar angle of h (h.z ≥ 0) from (r = |h.xy|, h.z).
fn polar_precise(r: f32, z: f32) -> f32 {
    if (z <= 0.0) {
        return atan2(r, z);
    }
    if (r <= z) {
        return atan_unit(r / z);
    }
    return 0.5 * PI - atan_unit(z / r);
}

// The half vector in cells: facet_glint::flakes::direction_coords.
fn direction_coords(wi: vec3<f32>, wo: vec3<f32>) -> vec2<f32> {
    let h = normalize(wi + wo);
    let r = length(h.xy);
    let theta = polar_precise(r, h.z);
    let k = select(1.0, theta / r, r > 1e-12);
    return h.xy * (k / (params.gamma / sqrt(2.0)));
}

// P(ωi, ωo, γ) from the two levels: P/σ interpolated between them, times σ(γ).
fn glint_dpf(wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let theta_o = acos(clamp(wo.z, -1.0, 1.0));
    let theta_i = acos(clamp(wi.z, -1.0, 1.0));
    var dphi = azimuth(wo) - azimuth(wi);
    dphi = dphi - 2.0 * PI * floor(dphi / (2.0 * PI));
    if (dphi > PI) {
        dphi = 2.0 * PI - dphi;
    }
    let d0 = level_lookup(level0, theta_o, theta_i, dphi) / params.sigma0;
    let d1 = level_lookup(level1, theta_o, theta_i, dphi) / params.sigma1;
    return (d0 * (1.0 - params.level_t) + select(0.0, d1 * params.level_t, params.level_t > 0.0)) * params.sigma;
}

// A uniform that picks one of the blended direction cells per query (select_cell in
// glint/lit.inc.wgsl), set by an includer that draws it per sample; negative (the default): the
// cells are blended, as facet_glint::glint_brdf does.
var<private> glint_cell_u: f32 = -1.0;

// f / F of two light directions wi.x, wi.y (one shading point's light sample and BSDF sample)
// for one view wo over the footprint ellipse (center, a, b) in UV, the flakes walked once; 0
// below either horizon.
fn glint_factor_pair(wi0: vec3<f32>, wi1: vec3<f32>, wo: vec3<f32>, center: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    if (wo.z <= 0.0) {
        return vec2<f32>(0.0);
    }
    let ok = vec2<bool>(wi0.z > 0.0, wi1.z > 0.0);
    let p = select(vec2<f32>(0.0), vec2<f32>(glint_dpf(wi0, wo), glint_dpf(wi1, wo)), ok);
    var c0 = direction_coords(wi0, wo);
    var c1 = direction_coords(wi1, wo);
    if (glint_cell_u >= 0.0 && field.blend != 0u) {
        c0 = select_cell(c0, glint_cell_u);
        c1 = select_cell(c1, glint_cell_u);
    }
    let q = Query(center, a, b, p, c0, c1);
    let count = count_pair(q);
    let area = footprint_area(a, b);
    return vec2<f32>(glint_scale(wi0, wo, count.x, area), glint_scale(wi1, wo, count.y, area));
}

// f / F for one light direction: glint_factor_pair with no second query.
fn glint_factor(wi: vec3<f32>, wo: vec3<f32>, center: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> f32 {
    return glint_factor_pair(wi, vec3<f32>(0.0, 0.0, -1.0), wo, center, a, b).x;
}

// f / F = G2 (h·ωo) count / (N a σ(γ) cos θi cos θh cos θo).
fn glint_scale(wi: vec3<f32>, wo: vec3<f32>, count: f32, area: f32) -> f32 {
    if (count == 0.0 || wi.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wo);
    let g2 = g2_correlated(glint_lambda(wi), glint_lambda(wo), wi, wo);
    return g2 * dot(h, wo) * count / (field.density * area * params.sigma * wi.z * h.z) / wo.z;
}
