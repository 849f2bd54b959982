// merl_eval (render/materials/merl.inc.wgsl) at given direction pairs, read back by
// crates/render/tests/measured.rs and compared with the CPU lookup.

@group(0) @binding(0) var<storage, read> tables: array<f32>;
// wi, then wo (xyz each)
@group(0) @binding(1) var<storage, read> pairs: array<array<vec4<f32>, 2>>;
@group(0) @binding(2) var<storage, read_write> results: array<vec4<f32>>;

#include "render/materials/merl.inc.wgsl"

@compute @workgroup_size(64)
fn probe(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if (i >= arrayLength(&pairs)) {
        return;
    }
    let p = pairs[i];
    results[i] = vec4<f32>(merl_eval(0u, p[0].xyz, p[1].xyz), 0.0);
}
