// Shading stage of glTF metallic-roughness materials (glTF 2.0, Appendix B, with the specular
// weight of KHR_materials_specular): GGX α = roughness², F0 = mix(0.04 · specular, base, metallic),
//   f = (1 − metallic)(1 − specular · F) base/π + F D G2 / (4 cos θi cos θo).
// Specular weight 0 and metallic 0 is a pure Lambertian surface.

#include "render/frame.inc.wgsl"
#include "common/microfacet.inc.wgsl"
#include "render/bvh.inc.wgsl"
#include "render/scene.inc.wgsl"
#include "render/shade.inc.wgsl"

override Q_SHADE: u32;

struct Bsdf {
    base: vec3<f32>,
    metallic: f32,
    specular: f32,
    ndf: AnalyticNdf,
    // probability of sampling the specular lobe
    p_spec: f32,
}

fn bsdf_setup(s: Surface, slot: u32) -> Bsdf {
    let m = materials[s.material];
    var base = m.base_color.xyz;
    var metallic = m.metallic;
    var roughness = m.roughness;
    if (m.tex_base != NONE) {
        base *= texture_sample(m.tex_base, s.uv).xyz;
    }
    if (m.tex_mr != NONE) {
        let mr = texture_sample(m.tex_mr, s.uv);
        roughness *= mr.y;
        metallic *= mr.z;
    }
    let alpha = max(roughness * roughness, 1e-3);
    var b: Bsdf;
    b.base = base;
    b.metallic = clamp(metallic, 0.0, 1.0);
    b.specular = m.emissive.w;
    b.ndf = AnalyticNdf(0u, alpha, alpha, 0.0);
    b.p_spec = b.metallic + (1.0 - b.metallic) * 0.5 * min(b.specular, 1.0);
    return b;
}

fn schlick(f0: vec3<f32>, c: f32) -> vec3<f32> {
    let x = 1.0 - clamp(c, 0.0, 1.0);
    let x2 = x * x;
    return f0 + (1.0 - f0) * x2 * x2 * x;
}

fn bsdf_eval(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let h = normalize(wi + wo);
    let c = dot(wi, h);
    let f_dielectric = schlick(vec3<f32>(0.04), c).x * b.specular;
    var f = (1.0 - b.metallic) * (1.0 - f_dielectric) * b.base / PI;
    if (b.p_spec > 0.0) {
        let g = g2_correlated(ndf_lambda(b.ndf, wi), ndf_lambda(b.ndf, wo), wi, wo);
        f += mix(vec3<f32>(f_dielectric), schlick(b.base, c), b.metallic) * ndf_d(b.ndf, h) * g / (4.0 * wi.z * wo.z);
    }
    return f;
}

fn bsdf_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wo);
    let spec = lobe_pdf_h(b.ndf, wo, h) / (4.0 * abs(dot(wo, h)));
    return b.p_spec * spec + (1.0 - b.p_spec) * wi.z / PI;
}

fn bsdf_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    return array<vec3<f32>, 2>(bsdf_eval(b, wi_light, wo), bsdf_eval(b, wi_bsdf, wo));
}

fn bsdf_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    var wi: vec3<f32>;
    if (u.z < b.p_spec) {
        let h = lobe_sample_h(b.ndf, wo, u.xy);
        wi = 2.0 * dot(wo, h) * h - wo;
    } else {
        wi = sample_cosine(u.xy);
    }
    return wi;
}

fn bsdf_roughness(b: Bsdf) -> f32 {
    return mix(1.0, b.ndf.alpha_x, b.p_spec);
}

@compute @workgroup_size(WG)
fn shade_diffuse(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_SHADE, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    shade(slot);
}
