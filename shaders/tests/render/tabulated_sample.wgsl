// Samples normals visible from ωo from a tabulated NDF with their pdf (the twin of
// facet_fit::tabulated::TabulatedNdf::{sample_visible, pdf_visible}), for the CPU comparison
// in crates/render/tests/tabulated_sampling.rs; the shading stage uses the same functions.

const WG: u32 = 64u;

// The tabulated block as facet_render::materials::tabulated::tabulated_block lays it out.
@group(0) @binding(0) var<storage, read> tables: array<f32>;
// (αx, αy, rotation, -).
@group(0) @binding(1) var<uniform> stretch: vec4<f32>;
// (ωo.xyz, u0) and (u1, -, -, -) per query, packed as two vec4.
@group(0) @binding(2) var<storage, read> inputs: array<vec4<f32>>;
// (h.xyz, pdf of h).
@group(0) @binding(3) var<storage, read_write> samples: array<vec4<f32>>;

#include "render/materials/tabulated.inc.wgsl"

@compute @workgroup_size(WG)
fn tabulated_sample(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (2u * i + 1u >= arrayLength(&inputs)) {
        return;
    }
    let a = inputs[2u * i];
    let b = inputs[2u * i + 1u];
    let t = tab_ndf_at(0u, stretch.x, stretch.y, stretch.z);
    let h = tab_sample_visible(t, a.xyz, vec2<f32>(a.w, b.x));
    samples[i] = vec4<f32>(h, tab_pdf_visible(t, a.xyz, h));
}
