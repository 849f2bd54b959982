// The error metric over the MERL grid: one workgroup per θd bin sums, over that bin's valid
// samples and the three channels, |ln(1 + x_model) − ln(1 + x_data)|, with
// x_model = F(θd) x_ideal + ρd/π cos θi. The CPU adds the bins' sums in f64 and divides by
// three times the samples. The grid, the source's flags and the model's tables:
// `grid.inc.wgsl`.

#include "fit/grid.inc.wgsl"

// ln(1 + x_data/ε) of the source as the CPU stores it (ε of the fit's metric; F and ρd/π come
// divided by ε): row r, channel c at (3 r + c) · PADDED.
@group(0) @binding(5) var<storage, read> log_x: array<f32>;
// F per θd bin (rgb), then ρd/π.
@group(0) @binding(6) var<storage, read> fresnel: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> sums: array<f32>;

@compute @workgroup_size(WG)
fn error_sums(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let j = wid.x;
    let f = fresnel[j].xyz;
    let kd = fresnel[arrayLength(&fresnel) - 1u].xyz;
    var acc = 0.0;
    // The bin's rows, one per θh bin, ROW bins each.
    for (var n = lid.x; n < arrayLength(&ndf) * ROW; n += WG) {
        let i = n / ROW;
        let k = n % ROW;
        let r = i * THETA_D + j;
        if (valid_bin(r, k)) {
            // x = F x_ideal + ρd/π cos θi, clamped at 0 as the CPU's ln(1 + max(x, 0))
            let x = max(f * x_ideal(r, i, k) + kd * cos_i(r, k), vec3(0.0));
            let at = 3u * r * PADDED + k;
            let data = vec3(log_x[at], log_x[at + PADDED], log_x[at + 2u * PADDED]);
            let e = abs(log(1.0 + x) - data);
            acc += e.x + e.y + e.z;
        }
    }
    let total = bin_total(lid.x, acc);
    if (lid.x == 0u) {
        sums[j] = total;
    }
}
