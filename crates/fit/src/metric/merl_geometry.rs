//! The geometry of the isotropic MERL grid in compact form, built once per process.
//!
//! A row is one (θh, θd) bin pair; its 180 φd bins share everything but φd. With
//! a = cos θh cos θd and b = sin θh sin θd, cos θo = a + b cos φd and cos θi = a − b cos φd
//! (`geometry::from_half_diff`), and since cos(π − φd) = −cos φd, cos θi of bin k is cos θo of
//! "bin" 180 − k. So a row stores 181 cosines μ_k = a + b cos(kπ/180), k = 0..=180: μo(k) = μ_k,
//! μi(k) = μ_(180−k). The correlation λ(φ) of G2 (φ the azimuth between wi and wo) is the
//! other per-bin quantity; it is symmetric under k ↔ 180 − k, so half of it is computed.
//! The tables take 12 MB; the build, vectorised (a polynomial acos, square roots and divisions
//! over each half row), takes 14 M instructions, 57 M one bin at a time.

use crate::model::geometry::acos_poly;
use crate::model::merl_grid::{PHI_D_RES, THETA_D_RES, THETA_H_RES, bin_angles};
use crate::model::microfacet::correlation;
use rayon::prelude::*;
use std::sync::OnceLock;

/// Rows of the grid: (θh, θd) bin pairs, row r = θd bin + 90 θh bin.
pub(crate) const ROWS: usize = THETA_H_RES * THETA_D_RES;
/// Bins per row: the φd bins.
pub(crate) const ROW: usize = PHI_D_RES;
/// Cosines per row: μ_k for k = 0..=180.
pub(crate) const MU_ROW: usize = PHI_D_RES + 1;
/// The coarse rows' φd stride: bins k = 4j and cosines μ_4j. It divides 180, so a coarse row
/// keeps the symmetry k ↔ 180 − k (j ↔ 45 − j).
pub(crate) const COARSE_STRIDE: usize = 4;
/// Bins per coarse row.
pub(crate) const COARSE_ROW: usize = ROW / COARSE_STRIDE;
/// Cosines per coarse row.
pub(crate) const COARSE_MU_ROW: usize = COARSE_ROW + 1;
const _: () = assert!(ROW.is_multiple_of(COARSE_STRIDE));

/// Per-row cosines and per-bin correlations of the MERL grid.
pub(crate) struct MerlGeometry {
    /// Bins per row: `ROW`, or `COARSE_ROW` for the coarse rows.
    row: usize,
    /// μ_k = cos θh cos θd + sin θh sin θd cos(kπ/180), `row` + 1 per row.
    pub mu: Vec<f32>,
    /// λ(φ) of G2 for each bin, `row` per row (the flat MERL bin order).
    pub corr: Vec<f32>,
}

impl MerlGeometry {
    /// μ_k of row `r`, k = 0..=180 (coarse: μ_4j, j = 0..=45).
    #[inline]
    pub fn mu_row(&self, r: usize) -> &[f32] {
        let n = self.row + 1;
        &self.mu[r * n..(r + 1) * n]
    }

    /// λ(φ) of the bins of row `r`.
    #[inline]
    pub fn corr_row(&self, r: usize) -> &[f32] {
        &self.corr[r * self.row..(r + 1) * self.row]
    }
}

/// The grid's geometry, computed on first use.
pub(crate) fn merl_geometry() -> &'static MerlGeometry {
    static GEOMETRY: OnceLock<MerlGeometry> = OnceLock::new();
    GEOMETRY.get_or_init(build)
}

/// The geometry of rows of `N` bins: the full grid's (`N` = `ROW`) or the coarse rows'
/// (`N` = `COARSE_ROW`, gathered from the full one on first use).
#[inline]
pub(crate) fn row_geometry<const N: usize>() -> &'static MerlGeometry {
    static COARSE: OnceLock<MerlGeometry> = OnceLock::new();
    match N {
        ROW => merl_geometry(),
        COARSE_ROW => COARSE.get_or_init(|| coarse(merl_geometry())),
        _ => unreachable!("rows of {N} bins: {ROW} or {COARSE_ROW}"),
    }
}

/// Every `COARSE_STRIDE`-th cosine and bin of each row of `full`.
fn coarse(full: &MerlGeometry) -> MerlGeometry {
    let mut mu = vec![0.0f32; ROWS * COARSE_MU_ROW];
    let mut corr = vec![0.0f32; ROWS * COARSE_ROW];
    for r in 0..ROWS {
        let (from, to) = (
            full.mu_row(r),
            &mut mu[r * COARSE_MU_ROW..][..COARSE_MU_ROW],
        );
        for (j, m) in to.iter_mut().enumerate() {
            *m = from[COARSE_STRIDE * j];
        }
        let (from, to) = (full.corr_row(r), &mut corr[r * COARSE_ROW..][..COARSE_ROW]);
        for (j, c) in to.iter_mut().enumerate() {
            *c = from[COARSE_STRIDE * j];
        }
    }
    MerlGeometry {
        row: COARSE_ROW,
        mu,
        corr,
    }
}

/// μ_k and λ(φ) of the rows of θh bin `i` (`mu` and `corr` are its rows'), `cos` and `sin` of
/// kπ/180 given: with AVX2 where the CPU has it, as the row passes (the same IEEE operations in
/// the same order, so the same bits at any vector width).
fn build_theta_h(
    i: usize,
    mu: &mut [f32],
    corr: &mut [f32],
    cos: &[f64; MU_ROW],
    sin: &[f64; MU_ROW],
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { build_theta_h_avx2(i, mu, corr, cos, sin) };
    }
    build_theta_h_baseline(i, mu, corr, cos, sin)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn build_theta_h_avx2(
    i: usize,
    mu: &mut [f32],
    corr: &mut [f32],
    cos: &[f64; MU_ROW],
    sin: &[f64; MU_ROW],
) {
    build_theta_h_baseline(i, mu, corr, cos, sin)
}

/// The bins k = 0..=90 of a row, whose mirror k ↔ 180 − k gives the others' λ(φ).
const HALF: usize = ROW / 2 + 1;

#[inline(always)]
fn build_theta_h_baseline(
    i: usize,
    mu: &mut [f32],
    corr: &mut [f32],
    cos: &[f64; MU_ROW],
    sin: &[f64; MU_ROW],
) {
    let (sh, ch) = bin_angles(i, 0, 0).theta_h.sin_cos();
    for j in 0..THETA_D_RES {
        let (sd, cd) = bin_angles(0, j, 0).theta_d.sin_cos();
        let (a, b) = (ch * cd, sh * sd);
        let mu: &mut [f32; MU_ROW] = (&mut mu[j * MU_ROW..(j + 1) * MU_ROW]).try_into().unwrap();
        for k in 0..MU_ROW {
            mu[k] = (a + b * cos[k]) as f32; // cos θo = a + b cos φd
        }
        // wi_xy = (p + q, r), wo_xy = (p − q, −r): p = sin θh cos θd,
        // q = cos θh sin θd cos φd, r = sin θd sin φd; φ = acos(wi_xy · wo_xy / |wi_xy| |wo_xy|).
        let p = sh * cd;
        let mut half = [0.0f32; HALF];
        for k in 0..HALF {
            let (q, r) = (ch * sd * cos[k], sd * sin[k]);
            let (a2, b2) = ((p + q) * (p + q) + r * r, (p - q) * (p - q) + r * r);
            let phi = acos_poly((p * p - q * q - r * r) / (a2 * b2).sqrt());
            // A direction along the normal: no azimuth between them.
            let phi = if a2 < 1e-24 || b2 < 1e-24 { 0.0 } else { phi };
            half[k] = correlation(phi) as f32;
        }
        let corr: &mut [f32; ROW] = (&mut corr[j * ROW..(j + 1) * ROW]).try_into().unwrap();
        corr[..HALF].copy_from_slice(&half);
        // φd ↔ π − φd swaps wi and wo.
        for k in 1..HALF - 1 {
            corr[ROW - k] = half[k];
        }
    }
}

fn build() -> MerlGeometry {
    // cos(kπ/180) and sin(kπ/180), k = 0..=180.
    let angles: [(f64, f64); MU_ROW] =
        std::array::from_fn(|k| (k as f64 * std::f64::consts::PI / PHI_D_RES as f64).sin_cos());
    let (sin, cos) = (angles.map(|a| a.0), angles.map(|a| a.1));
    let per_i = THETA_D_RES;
    let mut mu = vec![0.0f32; ROWS * MU_ROW];
    let mut corr = vec![0.0f32; ROWS * ROW];
    crate::io::huge_pages::advise(&mut mu);
    crate::io::huge_pages::advise(&mut corr);
    mu.par_chunks_mut(per_i * MU_ROW)
        .zip(corr.par_chunks_mut(per_i * ROW))
        .enumerate()
        .for_each(|(i, (mu, corr))| build_theta_h(i, mu, corr, &cos, &sin));
    MerlGeometry { row: ROW, mu, corr }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::geometry::{azimuth_between, from_half_diff};
    use crate::model::merl_grid::index;

    /// The build, vectorised where the CPU allows, gives every bin the bits of the formula
    /// evaluated one bin at a time: μ_k = a + b cos φd, and λ of the angle between the
    /// directions' projections (0 where one lies along the normal), bin 180 − k mirroring k.
    #[test]
    fn vectorised_build_equals_the_formula_per_bin() {
        let g = merl_geometry();
        for i in 0..THETA_H_RES {
            let (sh, ch) = bin_angles(i, 0, 0).theta_h.sin_cos();
            for j in 0..THETA_D_RES {
                let (sd, cd) = bin_angles(0, j, 0).theta_d.sin_cos();
                let r = j + THETA_D_RES * i;
                let (mu, corr) = (g.mu_row(r), g.corr_row(r));
                for k in 0..MU_ROW {
                    let (s, c) = (k as f64 * std::f64::consts::PI / PHI_D_RES as f64).sin_cos();
                    let want = (ch * cd + sh * sd * c) as f32;
                    assert_eq!(mu[k].to_bits(), want.to_bits(), "row {r} μ_{k}");
                    let (p, q, rr) = (sh * cd, ch * sd * c, sd * s);
                    let (a2, b2) = ((p + q).powi(2) + rr * rr, (p - q).powi(2) + rr * rr);
                    let phi = if a2 < 1e-24 || b2 < 1e-24 {
                        0.0
                    } else {
                        acos_poly((p * p - q * q - rr * rr) / (a2 * b2).sqrt())
                    };
                    // Bins k ≤ 90 hold it, and so do their mirrors 180 − k.
                    let want = correlation(phi) as f32;
                    if k <= ROW / 2 {
                        assert_eq!(corr[k].to_bits(), want.to_bits(), "row {r} λ bin {k}");
                        if k > 0 {
                            let m = corr[ROW - k];
                            assert_eq!(m.to_bits(), want.to_bits(), "row {r} λ bin {}", ROW - k);
                        }
                    }
                }
            }
        }
    }

    /// The compact tables give the cosines and the correlation of `from_half_diff`'s
    /// directions: f32 storage, so to a few f32 ulps.
    #[test]
    fn compact_geometry_matches_the_directions() {
        let g = merl_geometry();
        for (i, j, k) in [
            (0, 0, 0),
            (10, 45, 17),
            (45, 30, 90),
            (89, 89, 179),
            (30, 80, 0),
        ] {
            let (wi, wo) = from_half_diff(bin_angles(i, j, k));
            let r = index(i, j, 0) / ROW;
            let mu = g.mu_row(r);
            assert!((mu[k] as f64 - wo.z).abs() < 1e-6, "{i} {j} {k}");
            assert!((mu[ROW - k] as f64 - wi.z).abs() < 1e-6, "{i} {j} {k}");
            let c = correlation(azimuth_between(wi, wo));
            assert!((g.corr_row(r)[k] as f64 - c).abs() < 1e-5, "{i} {j} {k}");
        }
    }
}
