// Shading stage of glTF metallic-roughness materials (facet_render::materials::gltf) (glTF 2.0, Appendix B, with the specular
// weight of KHR_materials_specular): GGX α = roughness², F0 = mix(0.04 · specular, base, metallic),
//   f = (1 − metallic)(1 − specular · F) base/π + F D G2 / (4 cos θi cos θo).
// Specular weight 0 and metallic 0 is a pure Lambertian surface.
// KHR_materials_clearcoat (facet_render::scene::Clearcoat), the extension's layering:
//   f_coated = (1 − c F_c) f + c F_c D_c G2_c / (4 |n_c·ωi| |n_c·ωo|), F_c = F_schlick(0.04, ωo·h),
// D_c GGX of α = roughness² about the coat's normal n_c (the vertex normal or the coat's own map),
// sampled with probability c F_c(n_c·ωo) against the base's estimated albedo.

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
    // the clear coat: factor (0: none), GGX, its frame in the shading frame (z its normal)
    cc: f32,
    cc_ndf: AnalyticNdf,
    cc_t: vec3<f32>,
    cc_b: vec3<f32>,
    cc_n: vec3<f32>,
}

fn bsdf_setup(s: Surface, slot: u32) -> Bsdf {
    let m = gltf_block(s.material, 0u);
    var base = m.base_color;
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
    b.specular = m.specular;
    b.ndf = AnalyticNdf(0u, alpha, alpha, 0.0);
    b.p_spec = b.metallic + (1.0 - b.metallic) * 0.5 * min(b.specular, 1.0);
    b.cc = 0.0;
    if (m.clearcoat > 0.0) {
        clearcoat_setup(&b, s, m);
    }
    return b;
}

fn clearcoat_setup(b: ptr<function, Bsdf>, s: Surface, m: GltfBlock) {
    var cc = m.clearcoat;
    var roughness = m.clearcoat_roughness;
    if (m.tex_clearcoat != NONE) {
        cc *= texture_sample(m.tex_clearcoat, s.uv).x;
    }
    if (m.tex_clearcoat_roughness != NONE) {
        roughness *= texture_sample(m.tex_clearcoat_roughness, s.uv).y;
    }
    var n = s.n_vertex;
    if (m.tex_clearcoat_normal != NONE) {
        n = normal_mapped(n, s.tangent, m.tex_clearcoat_normal, m.clearcoat_normal_scale, s.uv);
    }
    var nc = to_local(s, n);
    if (nc.z <= 1e-4) {
        nc = vec3<f32>(0.0, 0.0, 1.0);
    }
    nc = normalize(nc);
    var t = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(nc.x) > 0.9);
    t = normalize(t - nc * dot(nc, t));
    (*b).cc = clamp(cc, 0.0, 1.0);
    let alpha = max(roughness * roughness, 1e-3);
    (*b).cc_ndf = AnalyticNdf(NDF_KIND_GGX, alpha, alpha, 0.0);
    (*b).cc_n = nc;
    (*b).cc_t = t;
    (*b).cc_b = cross(nc, t);
}

fn to_coat(b: Bsdf, w: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(w, b.cc_t), dot(w, b.cc_b), dot(w, b.cc_n));
}

fn from_coat(b: Bsdf, w: vec3<f32>) -> vec3<f32> {
    return w.x * b.cc_t + w.y * b.cc_b + w.z * b.cc_n;
}

// c F_c(ωo·h): the weight of the coat's lobe, and 1 − it the base's.
fn clearcoat_weight(b: Bsdf, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    return b.cc * schlick(vec3<f32>(0.04), abs(dot(wo, h))).x;
}

// D_c G2_c / (4 |n_c·ωi| |n_c·ωo|) in the coat's frame.
fn clearcoat_lobe(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let i = to_coat(b, wi);
    let o = to_coat(b, wo);
    if (i.z <= 0.0 || o.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(i + o);
    let g = g2_correlated(ndf_lambda(b.cc_ndf, i), ndf_lambda(b.cc_ndf, o), i, o);
    return ndf_d(b.cc_ndf, h) * g / (4.0 * i.z * o.z);
}

// The probability of sampling the coat: c F_c(n_c·ωo) against the base's estimated albedo.
fn clearcoat_probability(b: Bsdf, wo: vec3<f32>) -> f32 {
    let r = b.cc * schlick(vec3<f32>(0.04), to_coat(b, wo).z).x;
    let base = max(luminance(b.base) * (1.0 - b.metallic) + b.p_spec, 0.05);
    return r / (r + (1.0 - r) * base);
}

fn schlick(f0: vec3<f32>, c: f32) -> vec3<f32> {
    let x = 1.0 - clamp(c, 0.0, 1.0);
    let x2 = x * x;
    return f0 + (1.0 - f0) * x2 * x2 * x;
}

fn bsdf_eval(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (b.cc > 0.0) {
        if (wi.z <= 0.0 || wo.z <= 0.0) {
            return vec3<f32>(0.0);
        }
        let w = clearcoat_weight(b, wo, normalize(wi + wo));
        return (1.0 - w) * base_eval(b, wi, wo) + vec3<f32>(w * clearcoat_lobe(b, wi, wo));
    }
    return base_eval(b, wi, wo);
}

fn base_eval(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
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
    if (b.cc > 0.0) {
        let p = clearcoat_probability(b, wo);
        let i = to_coat(b, wi);
        let o = to_coat(b, wo);
        var coat = 0.0;
        if (i.z > 0.0 && o.z > 0.0) {
            let h = normalize(i + o);
            coat = lobe_pdf_h(b.cc_ndf, o, h) / (4.0 * abs(dot(o, h)));
        }
        return p * coat + (1.0 - p) * base_pdf(b, wi, wo);
    }
    return base_pdf(b, wi, wo);
}

fn base_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let h = normalize(wi + wo);
    let spec = lobe_pdf_h(b.ndf, wo, h) / (4.0 * abs(dot(wo, h)));
    return b.p_spec * spec + (1.0 - b.p_spec) * wi.z / PI;
}

fn bsdf_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    return array<vec3<f32>, 2>(bsdf_eval(b, wi_light, wo), bsdf_eval(b, wi_bsdf, wo));
}

fn bsdf_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    if (b.cc > 0.0) {
        let p = clearcoat_probability(b, wo);
        if (u.z < p) {
            let o = to_coat(b, wo);
            if (o.z <= 0.0) {
                return vec3<f32>(0.0, 0.0, -1.0);
            }
            let h = lobe_sample_h(b.cc_ndf, o, u.xy);
            return from_coat(b, 2.0 * dot(o, h) * h - o);
        }
        return base_sample_wi(b, wo, vec3<f32>(u.xy, (u.z - p) / (1.0 - p)));
    }
    return base_sample_wi(b, wo, u);
}

fn base_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
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
