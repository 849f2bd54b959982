// Evaluates TEA on pairs of keys, for the test that compares WGSL with Rust.

#include "glint/tea.inc.wgsl"

@group(0) @binding(0) var<storage, read> keys: array<vec2<u32>>;
@group(0) @binding(1) var<storage, read_write> hashes: array<vec4<u32>>;

@compute @workgroup_size(64)
fn tea_check(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i < arrayLength(&keys)) {
        let k = keys[i];
        hashes[i] = vec4<u32>(tea(k.x, k.y), bitcast<u32>(tea_unit(k.x, k.y)), 0u);
    }
}
