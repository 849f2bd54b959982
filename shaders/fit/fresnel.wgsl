// The Fresnel average over the MERL grid: one workgroup per θd bin sums, over that bin's valid
// samples, x_ideal = D(θh) G2 / (4 cos θo) of the model. The CPU adds Σ x_data (the source's
// per-row sums, over the rows whose D is positive) and divides: F_j = Σ x_data / Σ x_ideal.
// The grid, the source's flags and the model's tables: `grid.inc.wgsl`.

#include "fit/grid.inc.wgsl"

@group(0) @binding(5) var<storage, read_write> sums: array<f32>;

@compute @workgroup_size(WG)
fn fresnel_sums(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let j = wid.x;
    var acc = 0.0;
    // The bin's rows, one per θh bin, ROW bins each.
    for (var n = lid.x; n < arrayLength(&ndf) * ROW; n += WG) {
        let i = n / ROW;
        let k = n % ROW;
        let r = i * THETA_D + j;
        if (valid_bin(r, k)) {
            let ideal = x_ideal(r, i, k);
            if (ideal > 0.0) {
                acc += ideal;
            }
        }
    }
    let total = bin_total(lid.x, acc);
    if (lid.x == 0u) {
        sums[j] = total;
    }
}
