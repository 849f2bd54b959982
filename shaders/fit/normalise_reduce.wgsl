// The normalisation of the power iteration, on the GPU so that no read-back is needed per
// iteration, first pass: `reduce` (one workgroup) computes λ = Σ c_j y_j and the residual
// Σ c_j |y_j/λ − v_j| (the L1 change of the normalised NDF), stores both in stats[iteration]
// and advances the iteration. The second pass is normalise_rescale.wgsl.

#include "fit/node.inc.wgsl"

const WG: u32 = 256u;

@group(0) @binding(0) var<storage, read> nodes: array<Node>;
@group(0) @binding(1) var<storage, read_write> v: array<f32>;
@group(0) @binding(2) var<storage, read> y: array<f32>;
@group(0) @binding(3) var<storage, read_write> state: State;
@group(0) @binding(4) var<storage, read_write> stats: array<vec2<f32>>;

var<workgroup> partial: array<f32, WG>;

fn workgroup_sum(value: f32, lid: u32) -> f32 {
    partial[lid] = value;
    workgroupBarrier();
    for (var s = WG / 2u; s > 0u; s = s / 2u) {
        if (lid < s) {
            partial[lid] += partial[lid + s];
        }
        workgroupBarrier();
    }
    let total = partial[0];
    workgroupBarrier();
    return total;
}

@compute @workgroup_size(WG)
fn reduce(@builtin(local_invocation_id) lid: vec3<u32>) {
    let n = arrayLength(&v);
    var s = 0.0;
    for (var j = lid.x; j < n; j += WG) {
        s += nodes[j].norm_weight * y[j];
    }
    let lambda = workgroup_sum(s, lid.x);
    var r = 0.0;
    for (var j = lid.x; j < n; j += WG) {
        r += nodes[j].norm_weight * abs(y[j] / lambda - v[j]);
    }
    let residual = workgroup_sum(r, lid.x);
    if (lid.x == 0u) {
        let it = state.iteration;
        if (it < arrayLength(&stats)) {
            stats[it] = vec2<f32>(lambda, residual);
        }
        state.lambda = lambda;
        state.iteration = it + 1u;
    }
}
