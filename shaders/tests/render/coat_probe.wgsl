// bsdf_sample_wi and bsdf_pdf of render/materials/coat.inc.wgsl over a GGX + Lambertian base (sampled as
// shade_microfacet.wgsl samples an analytic fit: visible normals with probability p_spec, else
// the cosine lobe), read back by crates/render/tests/coat_sampling.rs for a χ² test against
// the CPU's pdf.

const WG: u32 = 64u;

// The base: GGX α, p_spec, its albedo estimate.
struct Base {
    alpha: f32,
    p_spec: f32,
    albedo: f32,
    pad: f32,
}

// The coat block (render/materials/coat.inc.wgsl) at 0.
@group(0) @binding(0) var<storage, read> tables: array<f32>;
@group(0) @binding(1) var<uniform> base: Base;
// (ωo.xyz, u0) and (u1, u2, -, -) per query.
@group(0) @binding(2) var<storage, read> inputs: array<vec4<f32>>;
// (ωi.xyz, pdf of ωi).
@group(0) @binding(3) var<storage, read_write> samples: array<vec4<f32>>;

#include "common/microfacet.inc.wgsl"
#include "render/materials/coat.inc.wgsl"

struct Bsdf {
    ndf: AnalyticNdf,
    p_spec: f32,
    albedo: f32,
    coat: Coat,
}

fn lobe_sample_h(n: AnalyticNdf, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    return ndf_sample_visible(n, wo, u);
}

fn lobe_pdf_h(n: AnalyticNdf, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    return ndf_pdf_visible(n, wo, h);
}

fn base_albedo(b: Bsdf) -> f32 {
    return b.albedo;
}

fn base_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    return array<vec3<f32>, 2>(vec3<f32>(0.0), vec3<f32>(0.0));
}

fn base_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wo);
    let spec = lobe_pdf_h(b.ndf, wo, h) / (4.0 * abs(dot(wo, h)));
    return b.p_spec * spec + (1.0 - b.p_spec) * wi.z / PI;
}

fn base_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    if (u.z < b.p_spec) {
        let h = lobe_sample_h(b.ndf, wo, u.xy);
        return 2.0 * dot(wo, h) * h - wo;
    }
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
}

@compute @workgroup_size(WG)
fn coat_sample(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (2u * i + 1u >= arrayLength(&inputs)) {
        return;
    }
    let a = inputs[2u * i];
    let c = inputs[2u * i + 1u];
    let b = Bsdf(AnalyticNdf(NDF_KIND_GGX, base.alpha, base.alpha, 0.0), base.p_spec, base.albedo, coat_at(0u));
    let wi = bsdf_sample_wi(b, a.xyz, vec3<f32>(a.w, c.x, c.y));
    samples[i] = vec4<f32>(wi, bsdf_pdf(b, wi, a.xyz));
}
