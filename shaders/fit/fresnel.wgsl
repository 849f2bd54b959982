// The Fresnel average over the MERL grid: one workgroup per θd bin sums, over that bin's valid
// samples, x_ideal = D(θh) G2 / (4 cos θo) of the model. The CPU adds Σ x_data (the source's
// per-row sums, over the rows whose D is positive) and divides: F_j = Σ x_data / Σ x_ideal.
// The samples are uploaded once per source, sorted by θd bin; a model is two small tables
// (D per θh bin, Λ cos θ uniform in cos θ).

const WG: u32 = 256u;

// Rust: facet_fit::gpu::GpuSample.
struct Sample {
    // θh bin of the sample (D table index).
    i: u32,
    // cos θi, cos θo in steps of the Λ cos θ table.
    gi: f32,
    go: f32,
    inv_cos_i: f32,
    inv_cos_o: f32,
    // λ(φ) of the correlated G2.
    corr: f32,
    pad0: f32,
    pad1: f32,
}

@group(0) @binding(0) var<storage, read> samples: array<Sample>;
// Start of each θd bin's samples; offsets[j + 1] is its end.
@group(0) @binding(1) var<storage, read> offsets: array<u32>;
@group(0) @binding(2) var<storage, read> ndf: array<f32>;
@group(0) @binding(3) var<storage, read> lambda_cos: array<f32>;
@group(0) @binding(4) var<storage, read_write> sums: array<f32>;

var<workgroup> partial: array<f32, WG>;

fn lambda_at(x: f32, cos_inv: f32) -> f32 {
    let last = arrayLength(&lambda_cos) - 2u;
    let k = min(u32(x), last);
    let t = x - f32(k);
    return mix(lambda_cos[k], lambda_cos[k + 1u], t) * cos_inv;
}

@compute @workgroup_size(WG)
fn fresnel_sums(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    let j = wid.x;
    var acc = 0.0;
    for (var s = offsets[j] + lid.x; s < offsets[j + 1u]; s += WG) {
        let p = samples[s];
        let li = lambda_at(p.gi, p.inv_cos_i);
        let lo = lambda_at(p.go, p.inv_cos_o);
        // G2 = 1 / (1 + max(Λi, Λo) + λ(φ) min(Λi, Λo))
        let g2 = 1.0 / (1.0 + max(li, lo) + p.corr * min(li, lo));
        let ideal = ndf[p.i] * 0.25 * p.inv_cos_o * g2;
        if (ideal > 0.0) {
            acc += ideal;
        }
    }
    partial[lid.x] = acc;
    workgroupBarrier();
    for (var s = WG / 2u; s > 0u; s = s / 2u) {
        if (lid.x < s) {
            partial[lid.x] += partial[lid.x + s];
        }
        workgroupBarrier();
    }
    if (lid.x == 0u) {
        sums[j] = partial[0];
    }
}
