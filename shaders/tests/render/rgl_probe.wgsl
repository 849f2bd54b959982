// RglBsdf's eval, pdf and sample on the GPU (shaders/render/materials/rgl.inc.wgsl) at given directions,
// read back by crates/render/tests/rgl_gpu.rs and compared with the CPU's
// (facet_fit::sources::rgl::RglBsdf::{eval, pdf, sample}).

const WG: u32 = 64u;

// tables[0] (bits) is the block's offset, so that the block is read away from word 0.
@group(0) @binding(0) var<storage, read> tables: array<f32>;
// Per probe, two vec4: (ωi.xyz, u0) and (ωo.xyz, u1).
@group(0) @binding(1) var<storage, read> probes: array<vec4<f32>>;
// Per probe, two vec4: (f(ωi, ωo).rgb, pdf(ωi, ωo)) and (the ωo sampled for ωi from u, -).
@group(0) @binding(2) var<storage, read_write> results: array<vec4<f32>>;

#include "render/materials/rgl.inc.wgsl"

@compute @workgroup_size(WG)
fn rgl_probe(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (2u * i + 1u >= arrayLength(&probes)) {
        return;
    }
    let a = probes[2u * i];
    let b = probes[2u * i + 1u];
    let t = rgl_at(bitcast<u32>(tables[0]));
    results[2u * i] = vec4<f32>(rgl_eval(t, a.xyz, b.xyz), rgl_pdf(t, a.xyz, b.xyz));
    results[2u * i + 1u] = vec4<f32>(rgl_sample(t, a.xyz, vec2<f32>(a.w, b.w)), 0.0);
}
