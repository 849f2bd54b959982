// Include-only. The glint BRDF without its Fresnel factor (Rust twin:
// facet_glint::glint_brdf::glint_eval): P from two DPF pyramid levels bracketing γ (R32Float 3D
// textures read at cell centres), the flake count over the footprint (or its mean N a P above the
// threshold when filtering), the correlated G2:
//   f / F = G2 (h·ωo) count / (N a σ(γ) cos θi cos θh cos θo).
// Needs from the includer: `field: Field`, `params: EvalParams`, `level0`, `level1`
// (texture_3d<f32>), glint/tea.inc.wgsl, common/microfacet.inc.wgsl and glint/flakes.inc.wgsl.

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
    // 0 GGX, 1 Beckmann.
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
    let st = 0.5 * PI_F / f32(nt);
    let sp = PI_F / f32(np);
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

// The direction cell: facet_glint::flakes::direction_cell.
fn direction_cell(wi: vec3<f32>, wo: vec3<f32>) -> vec2<u32> {
    let h = normalize(wi + wo);
    let r = length(h.xy);
    let theta = acos(clamp(h.z, -1.0, 1.0));
    let k = select(1.0, theta / r, r > 1e-12);
    let side = params.gamma / sqrt(2.0);
    return vec2<u32>(u32(i32(floor(h.x * k / side)) + (1 << 24u)), u32(i32(floor(h.y * k / side)) + (1 << 24u)));
}

// P(ωi, ωo, γ) from the two levels: P/σ interpolated between them, times σ(γ).
fn glint_dpf(wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let theta_o = acos(clamp(wo.z, -1.0, 1.0));
    let theta_i = acos(clamp(wi.z, -1.0, 1.0));
    var dphi = azimuth(wo) - azimuth(wi);
    dphi = dphi - 2.0 * PI_F * floor(dphi / (2.0 * PI_F));
    if (dphi > PI_F) {
        dphi = 2.0 * PI_F - dphi;
    }
    let d0 = level_lookup(level0, theta_o, theta_i, dphi) / params.sigma0;
    let d1 = level_lookup(level1, theta_o, theta_i, dphi) / params.sigma1;
    return (d0 * (1.0 - params.level_t) + select(0.0, d1 * params.level_t, params.level_t > 0.0)) * params.sigma;
}

// f / F for the footprint ellipse (center, a, b) in UV; 0 below either horizon.
fn glint_factor(wi: vec3<f32>, wo: vec3<f32>, center: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> f32 {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let p = glint_dpf(wi, wo);
    let q = Query(center, a, b, p, 0u, 0u, 0u, 0u, 0u);
    let area = footprint_area(q);
    let expected = field.density * area * p;
    var count = 0.0;
    if (field.filtered != 0u && expected > field.threshold) {
        count = expected;
    } else {
        let cell = direction_cell(wi, wo);
        count = f32(count_footprint(q, tea(cell.x, cell.y)));
    }
    if (count == 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wo);
    // λ(φ) of the correlated G2, φ the azimuth between wi and wo.
    let li = length(wi.xy);
    let lo = length(wo.xy);
    var phi = 0.0;
    if (li > 1e-6 && lo > 1e-6) {
        phi = acos(clamp(dot(wi.xy, wo.xy) / (li * lo), -1.0, 1.0));
    }
    let corr = 4.41 * phi / (4.41 * phi + 1.0);
    let ndf = AnalyticNdf(params.ndf_kind, params.alpha_x, params.alpha_y, params.rotation);
    let lam_i = ndf_lambda(ndf, wi);
    let lam_o = ndf_lambda(ndf, wo);
    let g2 = 1.0 / (1.0 + max(lam_i, lam_o) + corr * min(lam_i, lam_o));
    return g2 * dot(h, wo) * count / (field.density * area * params.sigma * wi.z * h.z) / wo.z;
}
