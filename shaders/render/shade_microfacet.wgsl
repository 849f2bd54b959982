// Shading stage of the fitted classes without glints (facet_render::materials::{analytic,
// tabulated, merl}), a fit's microfacet model (render/materials/lobe.inc.wgsl):
//   f = F(θd) D(h) G2(ωi, ωo) / (4 cos θi cos θo) + ρd / π,
// F the fit's Fresnel table, D and Λ analytic (GGX / Beckmann, TABULATED = 0) or the fit's
// tables (TABULATED = 1), the correlated G2. Sampling, with probability p_spec: the normals
// visible from ωo (by frame.ndf_sampling: analytic in closed form, tabulated by the table's
// visible slices); else the cosine lobe when the fit has a diffuse term.
// MEASURED = 1 (with TABULATED = 1): f is a measured MERL-grid table (render/materials/merl.inc.wgsl),
// sampled as its fit's tabulated model is. A fit that kept a coat is this model under its coat
// (render/materials/coat.inc.wgsl).

#include "render/frame.inc.wgsl"
#include "common/microfacet.inc.wgsl"
#include "render/bvh.inc.wgsl"
#include "render/scene.inc.wgsl"
#include "render/shade.inc.wgsl"
#include "render/materials/lobe.inc.wgsl"
#include "render/materials/tabulated.inc.wgsl"
#include "render/materials/merl.inc.wgsl"
#include "render/materials/coat.inc.wgsl"

override Q_SHADE: u32;
override TABULATED: bool;
override MEASURED: bool;

struct Bsdf {
    material: u32,
    lobe: LobeBlock,
    analytic: AnalyticNdf,
    tab: TabNdf,
    diffuse: vec3<f32>,
    p_spec: f32,
    // the specular and diffuse lobes' albedo estimates (luminance)
    albedo: f32,
    coat: Coat,
}

fn bsdf_setup(s: Surface, slot: u32) -> Bsdf {
    let l = lobe_block(s.material, 0u);
    var b: Bsdf;
    b.material = s.material;
    b.lobe = l;
    b.analytic = AnalyticNdf(l.ndf_kind, l.alpha_x, l.alpha_y, l.rotation);
    if (TABULATED) {
        b.tab = tab_ndf_at(l.table, l.alpha_x, l.alpha_y, l.rotation);
    }
    b.diffuse = l.diffuse;
    // Lobe choice by albedo: the specular lobe's is at most ~F(0); compare with ρd.
    let spec = luminance(fresnel_table(l, 1.0));
    let diff = luminance(b.diffuse);
    b.p_spec = select(1.0, spec / (spec + diff), diff > 0.0);
    b.albedo = spec + diff;
    b.coat = coat_at(materials[s.material].coat);
    if (frame.ndf_sampling == NDF_SAMPLING_COSINE) {
        b.p_spec = 0.0;
    }
    return b;
}

fn mf_d(b: Bsdf, h: vec3<f32>) -> f32 {
    if (TABULATED) {
        return tab_d(b.tab, h);
    }
    return ndf_d(b.analytic, h);
}

fn mf_lambda(b: Bsdf, w: vec3<f32>) -> f32 {
    if (TABULATED) {
        return tab_lambda(b.tab, w);
    }
    return ndf_lambda(b.analytic, w);
}

// pdf of the sampled normal over solid angle (visible normals for analytic NDFs).
fn mf_pdf_h(b: Bsdf, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    if (TABULATED) {
        if (frame.ndf_sampling == NDF_SAMPLING_D_COS) {
            return tab_pdf(b.tab, h);
        }
        return tab_pdf_visible(b.tab, wo, h);
    }
    return lobe_pdf_h(b.analytic, wo, h);
}

fn mf_sample_h(b: Bsdf, wo: vec3<f32>, u: vec2<f32>) -> vec3<f32> {
    if (TABULATED) {
        if (frame.ndf_sampling == NDF_SAMPLING_D_COS) {
            return tab_sample(b.tab, u);
        }
        return tab_sample_visible(b.tab, wo, u);
    }
    return lobe_sample_h(b.analytic, wo, u);
}

fn base_eval(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    if (MEASURED) {
        return merl_eval(merl_block(b.material, LOBE_BLOCK_WORDS).table, wi, wo);
    }
    let h = normalize(wi + wo);
    let f = fresnel_table(b.lobe, dot(wi, h));
    let g = g2_correlated(mf_lambda(b, wi), mf_lambda(b, wo), wi, wo);
    return f * mf_d(b, h) * g / (4.0 * wi.z * wo.z) + b.diffuse / PI;
}

fn base_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wo);
    // Reflection Jacobian: p(ωi) = p(h) / (4 |ωo·h|).
    let spec = mf_pdf_h(b, wo, h) / (4.0 * abs(dot(wo, h)));
    return b.p_spec * spec + (1.0 - b.p_spec) * wi.z / PI;
}

fn base_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    return array<vec3<f32>, 2>(base_eval(b, wi_light, wo), base_eval(b, wi_bsdf, wo));
}

fn base_albedo(b: Bsdf) -> f32 {
    return b.albedo;
}

fn base_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    var wi: vec3<f32>;
    if (u.z < b.p_spec) {
        let h = mf_sample_h(b, wo, u.xy);
        wi = 2.0 * dot(wo, h) * h - wo;
    } else {
        wi = sample_cosine(u.xy);
    }
    return wi;
}

fn bsdf_roughness(b: Bsdf) -> f32 {
    // The fit's effective α (GGX), the stretch included.
    return mix(1.0, b.lobe.cone_alpha, b.p_spec);
}

@compute @workgroup_size(WG)
fn shade_microfacet(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_SHADE, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    shade(slot);
}
