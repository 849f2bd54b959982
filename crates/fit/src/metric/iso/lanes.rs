//! Sums in a fixed order of lanes, whatever the vector width the CPU gives the loops: the
//! passes' results do not depend on the path taken ([`super::rows`]).

/// Σ of f32 values in f64, in four lanes (a fixed order the compiler can vectorise).
#[inline(always)]
pub(super) fn sum_f64(v: &[f32]) -> f64 {
    let mut acc = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().map(|&x| x as f64).sum();
    for c in chunks {
        for l in 0..4 {
            acc[l] += c[l] as f64;
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + rest
}

/// Σ of eight lanes in f64.
#[inline(always)]
pub(super) fn lanes_total(acc: &[f32; 8]) -> f64 {
    acc.iter().map(|&a| a as f64).sum()
}

/// Σ of a row's values in eight f32 lanes (a fixed order, whatever the vector width), in f64.
#[inline(always)]
fn lanes_sum<const P: usize>(v: &[f32; P]) -> f64 {
    let mut acc = [0.0f32; 8];
    for c in v.chunks_exact(8) {
        for l in 0..8 {
            acc[l] += c[l];
        }
    }
    lanes_total(&acc)
}

/// Σ of a row's values over its valid bins, in eight lanes.
#[inline(always)]
pub(super) fn valid_sum<const P: usize>(valid: &[bool; P], v: &[f32; P]) -> f64 {
    let mut masked = [0.0f32; P];
    for k in 0..P {
        masked[k] = if valid[k] { v[k] } else { 0.0 };
    }
    lanes_sum(&masked)
}

/// The 8-bin chunks of a row that hold a valid bin, from the first to the last: a row's valid
/// bins lie between its two horizons (cos θi > 0 and cos θo > 0), and the chunks outside them,
/// a quarter of the grid's, add nothing to a pass's sums.
#[inline(always)]
pub(super) fn valid_chunks<const P: usize>(valid: &[bool; P]) -> std::ops::Range<usize> {
    let any = |n: usize| valid[8 * n..8 * n + 8].iter().any(|&v| v);
    let chunks = P / 8;
    let first = (0..chunks).find(|&n| any(n)).unwrap_or(chunks);
    let end = (first..chunks)
        .rev()
        .find(|&n| any(n))
        .map_or(first, |n| n + 1);
    first..end
}
