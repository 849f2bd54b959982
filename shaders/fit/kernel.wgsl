// The matrix-free kernel–vector product of the power iteration (Dupuy et al. 2015):
//   y_q = row_q Σ_j col_j k(q, j) v_j
// k = ∫ <q,h>+ dφ in closed form (isotropic) or <q,h>+ (anisotropic). Rows are iteration
// nodes (y = K v) or table queries (y = I(q), the clamped-cosine convolution behind D and G1).
// Each workgroup stages a tile of nodes (direction and col_j v_j) in workgroup memory.

#include "common/math.inc.wgsl"
#include "fit/node.inc.wgsl"

const WG: u32 = 64u;

@group(0) @binding(0) var<storage, read> nodes: array<Node>;
@group(0) @binding(1) var<storage, read> queries: array<Node>;
@group(0) @binding(2) var<storage, read> v: array<f32>;
@group(0) @binding(3) var<storage, read_write> y: array<f32>;

var<workgroup> tile: array<vec4<f32>, WG>;

// ∫₀^{2π} max(0, a + b cos φ) dφ with a = cos θq cos θh, b = sin θq sin θh (b ≥ 0).
fn azimuthal(q: vec3<f32>, h: vec3<f32>) -> f32 {
    let sq = length(q.xy);
    let sh = length(h.xy);
    let a = q.z * h.z;
    let b = sq * sh;
    if (a >= b) {
        return 2.0 * PI * a;
    }
    if (a <= -b) {
        return 0.0;
    }
    let c = -a / b;
    return 2.0 * (a * acos(c) + b * sqrt(max(1.0 - c * c, 0.0)));
}

fn product(q: Node, count: u32, lid: u32, isotropic: bool) -> f32 {
    let qd = vec3<f32>(q.x, q.y, q.z);
    var acc = 0.0;
    for (var base = 0u; base < count; base += WG) {
        let j = base + lid;
        if (j < count) {
            let n = nodes[j];
            tile[lid] = vec4<f32>(n.x, n.y, n.z, n.col_weight * v[j]);
        } else {
            tile[lid] = vec4<f32>(0.0);
        }
        workgroupBarrier();
        let m = min(WG, count - base);
        for (var k = 0u; k < m; k++) {
            let t = tile[k];
            if (isotropic) {
                acc += t.w * azimuthal(qd, t.xyz);
            } else {
                acc += t.w * max(dot(qd, t.xyz), 0.0);
            }
        }
        workgroupBarrier();
    }
    return q.row_scale * acc;
}

// Isotropic (closed-form azimuth) or anisotropic kernel: one pipeline per value.
override ISOTROPIC: bool = true;

@compute @workgroup_size(WG)
fn kernel(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>,
          @builtin(num_workgroups) nwg: vec3<u32>) {
    let q = gid.x + gid.y * nwg.x * WG;
    let nq = arrayLength(&queries);
    let node = queries[min(q, nq - 1u)];
    let r = product(node, arrayLength(&nodes), lid.x, ISOTROPIC);
    if (q < nq) {
        y[q] = r;
    }
}
