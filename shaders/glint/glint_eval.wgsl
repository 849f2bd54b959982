// The glint BRDF on the GPU, the twin of facet_glint::glint_brdf::glint_eval: one thread per
// query, f = F(θd) × glint_factor (shaders/glint/glint_brdf.inc.wgsl).

#include "glint/tea.inc.wgsl"
#include "common/microfacet.inc.wgsl"

const WG: u32 = 64u;

// Rust: facet_glint::gpu::GlintEvalQuery.
struct EvalQuery {
    wi: vec4<f32>,
    wo: vec4<f32>,
    center: vec2<f32>,
    a: vec2<f32>,
    b: vec2<f32>,
    pad: vec2<f32>,
}

@group(0) @binding(0) var<uniform> field: Field;
@group(0) @binding(1) var<uniform> params: EvalParams;
@group(0) @binding(2) var level0: texture_3d<f32>;
@group(0) @binding(3) var level1: texture_3d<f32>;
// F per θd bin (1° apart from 0), rgb.
@group(0) @binding(4) var<storage, read> fresnel: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> queries: array<EvalQuery>;
@group(0) @binding(6) var<storage, read_write> out: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> split_table: array<u32>;

#include "glint/flakes.inc.wgsl"
#include "glint/chains8.inc.wgsl"
#include "glint/lit.inc.wgsl"
#include "glint/glint_brdf.inc.wgsl"

// Λ of the analytic NDF the evaluation takes.
fn glint_lambda(w: vec3<f32>) -> f32 {
    return ndf_lambda(AnalyticNdf(params.ndf_kind, params.alpha_x, params.alpha_y, params.rotation), w);
}

@compute @workgroup_size(WG)
fn glint_eval(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let idx = gid.x + gid.y * nwg.x * WG;
    if (idx >= arrayLength(&queries)) {
        return;
    }
    let e = queries[idx];
    let wi = e.wi.xyz;
    let wo = e.wo.xyz;
    let scale = glint_factor(wi, wo, e.center, e.a, e.b);
    if (scale == 0.0) {
        out[idx] = vec4<f32>(0.0);
        return;
    }
    let h = normalize(wi + wo);
    let theta_d = acos(clamp(dot(wi, h), 0.0, 1.0));
    let n = arrayLength(&fresnel);
    let x = clamp(theta_d / (0.5 * PI / f32(n)), 0.0, f32(n - 1u));
    let j = min(u32(x), n - 2u);
    let f = mix(fresnel[j].xyz, fresnel[j + 1u].xyz, x - f32(j));
    out[idx] = vec4<f32>(f * scale, 0.0);
}
