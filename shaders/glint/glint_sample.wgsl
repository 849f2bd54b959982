// Samples ωi for given ωo from the glint BRDF's smooth lobe, with its pdf (the twin of
// facet_glint::glint_brdf::glint_sample): h from the normals visible from ωo, ωo reflected
// about it, pdf = D_ωo(h) / (4 |ωo·h|); pdf 0 marks a sample below the horizon.

#include "common/microfacet.inc.wgsl"

const WG: u32 = 64u;

@group(0) @binding(0) var<uniform> ndf: AnalyticNdf;
// (ωo.xyz, u0) and (u1, -, -, -) per query, packed as two vec4.
@group(0) @binding(1) var<storage, read> inputs: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> samples: array<vec4<f32>>;

@compute @workgroup_size(WG)
fn glint_sample(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (2u * i + 1u >= arrayLength(&inputs)) {
        return;
    }
    let a = inputs[2u * i];
    let b = inputs[2u * i + 1u];
    let wo = a.xyz;
    let h = ndf_sample_visible(ndf, wo, vec2<f32>(a.w, b.x));
    let c = dot(wo, h);
    let wi = 2.0 * c * h - wo;
    if (c <= 0.0 || wi.z <= 0.0) {
        samples[i] = vec4<f32>(wi, 0.0);
        return;
    }
    samples[i] = vec4<f32>(wi, ndf_pdf_visible(ndf, wo, h) / (4.0 * abs(c)));
}
