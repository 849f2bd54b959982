// Include-only. A fit's microfacet lobe (Rust: facet_render::materials::lobe), the block the
// fitted classes share at word 0 of their class block (LobeBlock, render/materials/blocks.inc.wgsl):
//   f = F(θd) D(h) G2(ωi, ωo) / (4 cos θi cos θo) + ρd / π,
// F a table over θd in `tables`, D analytic (common/microfacet.inc.wgsl) or a table
// (render/materials/tabulated.inc.wgsl) stretched by (αx, αy) and rotated. The includer
// includes render/scene.inc.wgsl first.

// ---- Fresnel tables (θd nodes evenly spaced over [0, π/2], inclusive) ----------------------

fn fresnel_table(l: LobeBlock, cos_d: f32) -> vec3<f32> {
    let n = l.fresnel_nodes;
    let theta_d = acos(clamp(cos_d, 0.0, 1.0));
    let x = clamp(theta_d / (0.5 * PI) * f32(n - 1u), 0.0, f32(n - 1u));
    let j = min(u32(x), n - 2u);
    let o = l.fresnel + 3u * j;
    let a = vec3<f32>(tables[o], tables[o + 1u], tables[o + 2u]);
    let b = vec3<f32>(tables[o + 3u], tables[o + 4u], tables[o + 5u]);
    return mix(a, b, x - f32(j));
}
