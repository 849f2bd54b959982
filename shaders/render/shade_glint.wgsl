// Shading stage of one glint material (Wang et al. 2018 over Jakob et al. 2014), dispatched once
// per glint material with its own DPF pyramid levels:
//   f = F(θd) G2 (h·ωo) count / (N a σ(γ) cos θi cos θh cos θo) + ρd/π   (glint/glint_brdf.inc.wgsl;
//   ρd the fit's diffuse lobe),
// the light sample's and the BSDF sample's counts from one walk over the flakes, each reading
// one direction cell chosen per sample with its blend weight (stochastic filtering),
// the count taken over the ray cone's footprint mapped into UV (an ellipse), replaced by its mean
// N a P once that exceeds the threshold. Sampling: the smooth lobe's visible normals, mixed with
// the cosine lobe by albedo where the fit has a diffuse term (as shade_microfacet.wgsl).
// Under a fit's coat (render/materials/coat.inc.wgsl) the flakes are the base's: the same counts, lit and
// seen along the directions refracted into the coat and attenuated by its transmission.

#include "render/frame.inc.wgsl"
#include "common/ndf_kind.inc.wgsl"
#include "common/microfacet.inc.wgsl"
#include "render/bvh.inc.wgsl"
#include "render/scene.inc.wgsl"
#include "render/shade.inc.wgsl"
#include "render/materials/lobe.inc.wgsl"
#include "render/materials/tabulated.inc.wgsl"
#include "glint/tea.inc.wgsl"

override Q_SHADE: u32;

@group(2) @binding(0) var<uniform> field: Field;
@group(2) @binding(1) var<uniform> params: EvalParams;
@group(2) @binding(2) var level0: texture_3d<f32>;
@group(2) @binding(3) var level1: texture_3d<f32>;
@group(2) @binding(4) var<storage, read> split_table: array<u32>;

#include "glint/flakes.inc.wgsl"
// Each query reads one direction cell (bsdf_setup's cell_u): a walk of two chains.
#include "glint/chains2.inc.wgsl"
#include "glint/lit.inc.wgsl"
#include "glint/glint_brdf.inc.wgsl"
#include "render/materials/coat.inc.wgsl"

struct Bsdf {
    material: u32,
    lobe: LobeBlock,
    ndf: AnalyticNdf,
    // The fit's tabulated NDF, when params.ndf_kind is NDF_KIND_TABULATED.
    tab: TabNdf,
    center: vec2<f32>,
    a: vec2<f32>,
    b: vec2<f32>,
    diffuse: vec3<f32>,
    p_spec: f32,
    // Picks the direction cell each query reads (glint_cell_u in glint/glint_brdf.inc.wgsl).
    cell_u: f32,
    // the specular and diffuse lobes' albedo estimates (luminance)
    albedo: f32,
    coat: Coat,
}

// A world vector in the tangent plane to UV: least squares through J = [dP/du dP/dv],
// (JᵀJ)⁻¹ Jᵀ t.
fn world_to_uv(s: Surface, t: vec3<f32>) -> vec2<f32> {
    let a = dot(s.dpdu, s.dpdu);
    let b = dot(s.dpdu, s.dpdv);
    let c = dot(s.dpdv, s.dpdv);
    let det = a * c - b * b;
    let r = vec2<f32>(dot(s.dpdu, t), dot(s.dpdv, t));
    return vec2<f32>(c * r.x - b * r.y, a * r.y - b * r.x) / det;
}

// Largest UV semi-axis: half the unit torus.
const MAX_AXIS: f32 = 0.5;

fn clamp_axis(v: vec2<f32>) -> vec2<f32> {
    let l = length(v);
    return select(v, v * (MAX_AXIS / l), l > MAX_AXIS);
}

fn bsdf_setup(s: Surface, slot: u32) -> Bsdf {
    let l = lobe_block(s.material, 0u);
    var b: Bsdf;
    b.material = s.material;
    b.lobe = l;
    b.ndf = AnalyticNdf(l.ndf_kind, l.alpha_x, l.alpha_y, l.rotation);
    if (params.ndf_kind == NDF_KIND_TABULATED) {
        b.tab = tab_ndf_at(l.table, l.alpha_x, l.alpha_y, l.rotation);
    }
    b.center = s.uv;
    // One of the blended direction cells per sample, chosen by its weight: the image converges
    // to the blended counts, and the walk follows one chain per query instead of up to four.
    b.cell_u = path_rand(slot, 6u);
    b.diffuse = l.diffuse;
    // Lobe choice by albedo, as for the smooth microfacet class.
    let spec = luminance(fresnel_table(l, 1.0));
    let diff = luminance(b.diffuse);
    b.p_spec = select(1.0, spec / (spec + diff), diff > 0.0);
    b.albedo = spec + diff;
    b.coat = coat_at(materials[s.material].coat);
    // The cone's circle of radius w/2 around the ray, projected onto the tangent plane: an
    // ellipse with semi-axes r (across the ray) and r / |cos θ| (along it).
    let d = path_get(R_DIR, slot).xyz;
    let r = max(0.5 * path_get(R_ORIGIN, slot).w, 1e-7);
    let cos_t = max(abs(dot(d, s.ng)), 0.05);
    var along = d - s.ng * dot(d, s.ng);
    if (dot(along, along) < 1e-12) {
        along = s.t;
    }
    along = normalize(along);
    let across = cross(s.ng, along);
    let det = dot(s.dpdu, s.dpdu) * dot(s.dpdv, s.dpdv) - dot(s.dpdu, s.dpdv) * dot(s.dpdu, s.dpdv);
    if (det > 1e-30) {
        b.a = clamp_axis(world_to_uv(s, across * r));
        b.b = clamp_axis(world_to_uv(s, along * (r / cos_t)));
    } else {
        // No UV mapping: the largest footprint, where the filter's mean takes over.
        b.a = vec2<f32>(MAX_AXIS, 0.0);
        b.b = vec2<f32>(0.0, MAX_AXIS);
    }
    // A degenerate ellipse has no area: give it a sliver so the count stays defined.
    if (abs(b.a.x * b.b.y - b.a.y * b.b.x) < 1e-14) {
        b.b += vec2<f32>(-b.a.y, b.a.x) * 1e-3 + vec2<f32>(1e-7, 1e-7);
    }
    return b;
}

// Both directions from one walk over the footprint's flakes.
fn base_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    glint_tab = b.tab;
    glint_cell_u = b.cell_u;
    let k = glint_factor_pair(wi_light, wi_bsdf, wo, b.center, b.a, b.b);
    var f: array<vec3<f32>, 2>;
    if (k.x > 0.0) {
        f[0] = fresnel_table(b.lobe, dot(wi_light, normalize(wi_light + wo))) * k.x;
    }
    if (k.y > 0.0) {
        f[1] = fresnel_table(b.lobe, dot(wi_bsdf, normalize(wi_bsdf + wo))) * k.y;
    }
    if (wo.z > 0.0) {
        f[0] += select(vec3<f32>(0.0), b.diffuse / PI, wi_light.z > 0.0);
        f[1] += select(vec3<f32>(0.0), b.diffuse / PI, wi_bsdf.z > 0.0);
    }
    return f;
}

// Λ of the material's NDF, for the glint BRDF's G2 (glint/glint_brdf.inc.wgsl). The stage is one
// material's, so params.ndf_kind is uniform; the tabulated NDF is the one at params' material.
var<private> glint_tab: TabNdf;

fn glint_lambda(w: vec3<f32>) -> f32 {
    if (params.ndf_kind == NDF_KIND_TABULATED) {
        return tab_lambda(glint_tab, w);
    }
    return ndf_lambda(AnalyticNdf(params.ndf_kind, params.alpha_x, params.alpha_y, params.rotation), w);
}

// The smooth lobe's visible normals: analytic, or the table's visible distribution.
fn base_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return 0.0;
    }
    let h = normalize(wi + wo);
    var spec: f32;
    if (params.ndf_kind == NDF_KIND_TABULATED) {
        spec = tab_pdf_visible(b.tab, wo, h) / (4.0 * abs(dot(wo, h)));
    } else {
        spec = lobe_pdf_h(b.ndf, wo, h) / (4.0 * abs(dot(wo, h)));
    }
    return b.p_spec * spec + (1.0 - b.p_spec) * wi.z / PI;
}

fn base_albedo(b: Bsdf) -> f32 {
    return b.albedo;
}

fn base_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    if (u.z >= b.p_spec) {
        return sample_cosine(u.xy);
    }
    var h: vec3<f32>;
    if (params.ndf_kind == NDF_KIND_TABULATED) {
        h = tab_sample_visible(b.tab, wo, u.xy);
    } else {
        h = lobe_sample_h(b.ndf, wo, u.xy);
    }
    return 2.0 * dot(wo, h) * h - wo;
}

fn bsdf_roughness(b: Bsdf) -> f32 {
    // The fit's effective α (GGX) for a table, √(αx αy) for an analytic NDF.
    var r = sqrt(b.ndf.alpha_x * b.ndf.alpha_y);
    if (params.ndf_kind == NDF_KIND_TABULATED) {
        r = b.lobe.cone_alpha;
    }
    return mix(1.0, r, b.p_spec);
}

@compute @workgroup_size(WG)
fn shade_glint(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_SHADE, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    shade(slot);
}
