// Include-only. The isotropic MERL grid in rows, as the CPU passes hold it
// (`crates/fit/src/metric/merl_geometry.rs`, `metric/iso/`): row r = θd bin + THETA_D · θh bin, of ROW
// φd bins. Its geometry is uploaded once per fitter: ROW + 1 cosines μ_k a row (bin k's
// cos θo = μ_k, cos θi = μ_(ROW − k)) and λ(φ) of G2 per bin. A source adds its validity
// flags (one bit a bin), and a model D per θh bin and Λ cos θ uniform in cos θ. Bindings 0–4
// of the passes over the grid (`fresnel.wgsl`, `error.wgsl`), which run a workgroup of WG
// invocations per θd bin and add its terms with `bin_total`.

const WG: u32 = 256u;

// φd bins per row.
override ROW: u32;
// ROW rounded up to eight: the stride of the stored rows.
override PADDED: u32;
// θd bins: rows per θh bin.
override THETA_D: u32;

@group(0) @binding(0) var<storage, read> mu: array<f32>;
@group(0) @binding(1) var<storage, read> corr: array<f32>;
// Bit k % 32 of word r · ceil(PADDED / 32) + k / 32: bin k of row r holds a valid sample.
@group(0) @binding(2) var<storage, read> valid: array<u32>;
@group(0) @binding(3) var<storage, read> ndf: array<f32>;
@group(0) @binding(4) var<storage, read> lambda_cos: array<f32>;

fn valid_bin(r: u32, k: u32) -> bool {
    let words = (PADDED + 31u) / 32u;
    return ((valid[r * words + k / 32u] >> (k % 32u)) & 1u) != 0u;
}

// Λ(μ) = (Λ cos θ)(μ) / μ, the table linear in μ over [0, 1].
fn lambda_of(m: f32) -> f32 {
    let last = arrayLength(&lambda_cos) - 1u;
    let x = clamp(m * f32(last), 0.0, f32(last));
    let k = min(u32(x), last - 1u);
    return mix(lambda_cos[k], lambda_cos[k + 1u], x - f32(k)) / m;
}

// cos θi of bin k of row r.
fn cos_i(r: u32, k: u32) -> f32 {
    return mu[r * (ROW + 1u) + ROW - k];
}

// x_ideal = D(θh) G2 / (4 cos θo) at bin k of row r, θh bin i,
// G2 = 1 / (1 + max(Λi, Λo) + λ(φ) min(Λi, Λo)).
fn x_ideal(r: u32, i: u32, k: u32) -> f32 {
    let mo = mu[r * (ROW + 1u) + k];
    let lo = lambda_of(mo);
    let li = lambda_of(cos_i(r, k));
    let g2 = 1.0 / (1.0 + max(li, lo) + corr[r * ROW + k] * min(li, lo));
    return ndf[i] * 0.25 / mo * g2;
}

var<workgroup> partial: array<f32, WG>;

// The workgroup's total of `acc` (its invocations' sums) at invocation 0: a tree in f32.
fn bin_total(lid: u32, acc: f32) -> f32 {
    partial[lid] = acc;
    workgroupBarrier();
    for (var s = WG / 2u; s > 0u; s = s / 2u) {
        if (lid < s) {
            partial[lid] += partial[lid + s];
        }
        workgroupBarrier();
    }
    return partial[0];
}
