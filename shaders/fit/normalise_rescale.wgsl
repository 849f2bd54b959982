// The normalisation of the power iteration, second pass: `rescale` sets v = y / λ, λ as
// normalise_reduce.wgsl stored it (the same bindings).

#include "fit/node.inc.wgsl"

const WG: u32 = 256u;

@group(0) @binding(1) var<storage, read_write> v: array<f32>;
@group(0) @binding(2) var<storage, read> y: array<f32>;
@group(0) @binding(3) var<storage, read_write> state: State;

@compute @workgroup_size(WG)
fn rescale(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let j = gid.x + gid.y * nwg.x * WG;
    if (j < arrayLength(&v)) {
        v[j] = y[j] / state.lambda;
    }
}
