//! The grid of an isotropic source built from its MERL table: every row's ln(1 + x), validity
//! flags, Σ x and count, filled rows side by side (rayon over θh bins, AVX-512 or AVX2 where the
//! CPU has it).

use super::lanes::sum_f64;
use super::{IsoData, IsoSamples, PADDED};
use crate::metric::fast_log::ln_1p;
use crate::metric::iso_tables::MAX_X;
use crate::metric::merl_geometry::{
    COARSE_ROW, COARSE_STRIDE, MU_ROW, MerlGeometry, ROW, ROWS, merl_geometry,
};
use crate::model::merl_grid::{MerlTable, SCALE, THETA_D_RES};
use crate::numerics::stats::median_in_place;
use rayon::prelude::*;
use std::mem::MaybeUninit;
use std::sync::Arc;

impl IsoSamples {
    /// The samples of an isotropic source from its MERL table, in the space of the metric
    /// whose scale is `scale` (1/ε: ln(1 + x/ε) is stored).
    pub fn new(table: &MerlTable, scale: f32) -> Self {
        let geo = merl_geometry();
        let per_i = THETA_D_RES;
        // Allocated, not zeroed: the rows write every value, padding included (zeroing the
        // 19 MB first, which a reused allocation costs in full, took 1.6 ms serially).
        let (n_log, n_valid) = (3 * ROWS * PADDED, ROWS * PADDED);
        let mut log_x: Vec<f32> = Vec::with_capacity(n_log);
        let mut valid: Vec<bool> = Vec::with_capacity(n_valid);
        crate::io::huge_pages::advise(&mut log_x.spare_capacity_mut()[..n_log]);
        crate::io::huge_pages::advise(&mut valid.spare_capacity_mut()[..n_valid]);
        let mut sum_x = vec![[0.0f64; 3]; ROWS];
        let mut sum_coarse_x = vec![[0.0f64; 3]; ROWS];
        let mut count = vec![0u16; ROWS];
        let channels = [table.channel(0), table.channel(1), table.channel(2)];
        let out_of_range = log_x.spare_capacity_mut()[..n_log]
            .par_chunks_mut(3 * per_i * PADDED)
            .zip(valid.spare_capacity_mut()[..n_valid].par_chunks_mut(per_i * PADDED))
            .zip(sum_x.par_chunks_mut(per_i))
            .zip(sum_coarse_x.par_chunks_mut(per_i))
            .zip(count.par_chunks_mut(per_i))
            .enumerate()
            .map(|(i, ((((log_x, valid), sum_x), sum_coarse_x), count))| {
                let rows = RowsOut {
                    first: i * per_i,
                    log_x,
                    valid,
                    sum_x,
                    sum_coarse_x,
                    count,
                };
                build_rows(rows, channels, geo, scale)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .next();
        // SAFETY: `build_rows` wrote every element of both, each row's bins and its padding
        // (a panic there unwinds before this line, leaving them empty).
        unsafe {
            log_x.set_len(n_log);
            valid.set_len(n_valid);
        }
        let data = IsoData {
            slot: Vec::new(),
            log_x,
            scale,
            x: Vec::new(),
            valid,
            sum_x,
            sum_coarse_x,
            count,
            out_of_range,
        };
        Self::rows_of(Arc::new(data))
    }
}

/// The median of x = f_r cos θi over a MERL table's valid samples and its three channels,
/// from every [`MEDIAN_STRIDE`]-th bin: the material's typical brightness, to which the
/// metric's floor is tied ([`crate::metric::Metric::floor`]). (The mean is no such figure: the
/// grid's θh bins crowd the specular peak, whose values dominate it.)
pub(crate) fn median_x(table: &MerlTable) -> f64 {
    let geo = merl_geometry();
    let channels = [table.channel(0), table.channel(1), table.channel(2)];
    let mut xs = Vec::with_capacity(3 * ROWS * ROW / MEDIAN_STRIDE + 3);
    for s in (0..ROWS * ROW).step_by(MEDIAN_STRIDE) {
        let (r, k) = (s / ROW, s % ROW);
        let mu = geo.mu_row(r);
        // cos θi of bin k: the row's cosine at 180 − k; cos θo at k.
        let (mu_i, mu_o) = (mu[ROW - k] as f64, mu[k] as f64);
        let v: [f64; 3] = std::array::from_fn(|c| f64::from_le_bytes(channels[c][s]));
        if mu_i > 0.0 && mu_o > 0.0 && v.iter().all(|&v| v >= 0.0 && v.is_finite()) {
            xs.extend((0..3).map(|c| v[c] * SCALE[c] * mu_i));
        }
    }
    median_in_place(&mut xs)
}

/// [`median_x`] reads every `MEDIAN_STRIDE`-th bin (a prime: no alias with the 180 φd bins).
const MEDIAN_STRIDE: usize = 31;

/// The outputs of consecutive rows of an [`IsoData`] being built.
struct RowsOut<'a> {
    first: usize,
    /// Uninitialised on entry; every value is written, the padding with 0.
    log_x: &'a mut [MaybeUninit<f32>],
    /// Uninitialised on entry; every flag is written, the padding with `false`.
    valid: &'a mut [MaybeUninit<bool>],
    sum_x: &'a mut [[f64; 3]],
    sum_coarse_x: &'a mut [[f64; 3]],
    count: &'a mut [u16],
}

/// Fills rows from the MERL channels (AVX-512 or AVX2 where the CPU has it, as the passes);
/// returns the first sample out of range.
fn build_rows(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
    scale: f32,
) -> Option<(usize, [f32; 3])> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F, checked just above.
            return unsafe { build_rows_avx512(out, raw, geo, scale) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { build_rows_avx2(out, raw, geo, scale) };
        }
    }
    build_rows_baseline(out, raw, geo, scale)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn build_rows_avx512(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
    scale: f32,
) -> Option<(usize, [f32; 3])> {
    build_rows_baseline(out, raw, geo, scale)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn build_rows_avx2(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
    scale: f32,
) -> Option<(usize, [f32; 3])> {
    build_rows_baseline(out, raw, geo, scale)
}

#[inline(always)]
fn build_rows_baseline(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
    scale: f32,
) -> Option<(usize, [f32; 3])> {
    let mut bad = None;
    let sums = out.sum_x.iter_mut().zip(out.sum_coarse_x.iter_mut());
    for (n, ((sum, sum_coarse), count)) in sums.zip(out.count.iter_mut()).enumerate() {
        let r = out.first + n;
        let mu: &[f32; MU_ROW] = geo.mu_row(r).try_into().unwrap();
        // The row's flags and values are formed here and written out whole, padding included.
        let mut valid = [false; PADDED];
        // The stored values, little-endian as in the file, read in place.
        let v: [&[[u8; 8]; ROW]; 3] =
            std::array::from_fn(|c| raw[c][r * ROW..(r + 1) * ROW].try_into().unwrap());
        // cos θi of bin k: the cosine at 180 − k (the cosines 1..=180 reversed).
        let mut mu_i = [0.0f32; ROW];
        for (o, &m) in mu_i.iter_mut().zip(mu[1..].iter().rev()) {
            *o = m;
        }
        // Valid: both directions above the horizon and no channel missing (negative; a NaN
        // is a value, refused below as out of range). `&`, not `&&`: no branch in the loop.
        for k in 0..ROW {
            let missing = (0..3).fold(false, |m, c| m | (f64::from_le_bytes(v[c][k]) < 0.0));
            valid[k] = (mu_i[k] > 0.0) & (mu[k] > 0.0) & !missing;
        }
        // x = f_r cos θi, 0 where invalid
        let x = |c: usize, k: usize| {
            let x = (f64::from_le_bytes(v[c][k])
                * crate::model::merl_grid::SCALE[c]
                * mu_i[k] as f64) as f32;
            if valid[k] { x } else { 0.0 }
        };
        // x of each channel, then ln(1 + x) over it in place.
        let mut in_range = true;
        for c in 0..3 {
            let mut row = [0.0f32; PADDED];
            for (k, v) in row[..ROW].iter_mut().enumerate() {
                *v = x(c, k);
                in_range &= v.abs() <= MAX_X;
            }
            sum[c] = sum_f64(&row[..ROW]);
            let mut coarse = [0.0f32; COARSE_ROW];
            for (j, x) in coarse.iter_mut().enumerate() {
                *x = row[COARSE_STRIDE * j];
            }
            sum_coarse[c] = sum_f64(&coarse);
            let at = (3 * n + c) * PADDED;
            // ln(1 + x/ε), ln(1 + 0) = 0 on the padding.
            for (o, x) in out.log_x[at..at + PADDED].iter_mut().zip(row) {
                o.write(ln_1p(x * scale));
            }
        }
        for (o, v) in out.valid[n * PADDED..(n + 1) * PADDED]
            .iter_mut()
            .zip(valid)
        {
            o.write(v);
        }
        if bad.is_none() && !in_range {
            bad = (0..ROW)
                .find(|&k| (0..3).any(|c| !(x(c, k).abs() <= MAX_X)))
                .map(|k| (r * ROW + k, std::array::from_fn(|c| x(c, k))));
        }
        *count = valid.iter().filter(|&&v| v).count() as u16;
    }
    bad
}
