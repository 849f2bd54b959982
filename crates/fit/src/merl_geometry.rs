//! The geometry of the isotropic MERL grid in compact form, built once per process.
//!
//! A row is one (θh, θd) bin pair; its 180 φd bins share everything but φd. With
//! a = cos θh cos θd and b = sin θh sin θd, cos θo = a + b cos φd and cos θi = a − b cos φd
//! (`geometry::from_half_diff`), and since cos(π − φd) = −cos φd, cos θi of bin k is cos θo of
//! "bin" 180 − k. So a row stores 181 cosines μ_k = a + b cos(kπ/180), k = 0..=180: μo(k) = μ_k,
//! μi(k) = μ_(180−k). The correlation λ(φ) of G2 (φ the azimuth between wi and wo) is the
//! other per-bin quantity; it is symmetric under k ↔ 180 − k, so half of it is computed.
//! The tables take 12 MB and about 10 ms to build on two cores (one acos per bin pair).

use crate::merl::{PHI_D_RES, THETA_D_RES, THETA_H_RES, bin_angles};
use crate::microfacet::correlation;
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

fn build() -> MerlGeometry {
    let cos_phi: Vec<(f64, f64)> = (0..MU_ROW)
        .map(|k| (k as f64 * std::f64::consts::PI / PHI_D_RES as f64).sin_cos())
        .map(|(s, c)| (c, s))
        .collect();
    let per_i = THETA_D_RES;
    let mut mu = vec![0.0f32; ROWS * MU_ROW];
    let mut corr = vec![0.0f32; ROWS * ROW];
    crate::huge_pages::advise(&mut mu);
    crate::huge_pages::advise(&mut corr);
    mu.par_chunks_mut(per_i * MU_ROW)
        .zip(corr.par_chunks_mut(per_i * ROW))
        .enumerate()
        .for_each(|(i, (mu, corr))| {
            let (sh, ch) = bin_angles(i, 0, 0).theta_h.sin_cos();
            for j in 0..THETA_D_RES {
                let (sd, cd) = bin_angles(0, j, 0).theta_d.sin_cos();
                let (a, b) = (ch * cd, sh * sd);
                let mu = &mut mu[j * MU_ROW..(j + 1) * MU_ROW];
                for (m, &(c, _)) in mu.iter_mut().zip(&cos_phi) {
                    *m = (a + b * c) as f32; // cos θo = a + b cos φd
                }
                // wi_xy = (p + q, r), wo_xy = (p − q, −r): p = sin θh cos θd,
                // q = cos θh sin θd cos φd, r = sin θd sin φd.
                let p = sh * cd;
                let corr = &mut corr[j * ROW..(j + 1) * ROW];
                for k in 0..=ROW / 2 {
                    let (c, s) = cos_phi[k];
                    let (q, r) = (ch * sd * c, sd * s);
                    let (a2, b2) = ((p + q).powi(2) + r * r, (p - q).powi(2) + r * r);
                    let phi = if a2 < 1e-24 || b2 < 1e-24 {
                        0.0
                    } else {
                        acos((p * p - q * q - r * r) / (a2 * b2).sqrt())
                    };
                    let l = correlation(phi) as f32;
                    corr[k] = l;
                    if k > 0 {
                        corr[ROW - k] = l; // φd ↔ π − φd swaps wi and wo
                    }
                }
            }
        });
    MerlGeometry { row: ROW, mu, corr }
}

/// acos x, x clamped to [−1, 1], to 2e-8 absolute (Abramowitz & Stegun 4.4.46:
/// acos |x| = √(1 − |x|) P(|x|), P of degree 7): cheaper than libm's f32 acos, which took a
/// fifth of the grid's build (737 000 angles).
fn acos(x: f64) -> f64 {
    const P: [f64; 8] = [
        1.570_796_305_0,
        -0.214_598_801_6,
        0.088_978_987_4,
        -0.050_174_304_6,
        0.030_891_881_0,
        -0.017_088_125_6,
        0.006_670_090_1,
        -0.001_262_491_1,
    ];
    let a = x.abs().min(1.0);
    let p = P.iter().rev().fold(0.0, |acc, &c| acc * a + c);
    let r = (1.0 - a).sqrt() * p;
    if x < 0.0 { std::f64::consts::PI - r } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{azimuth_between, from_half_diff};
    use crate::merl::index;

    #[test]
    fn polynomial_acos_is_within_its_bound() {
        let worst = (0..=200_000)
            .map(|n| -1.0 + n as f64 / 100_000.0)
            .map(|x: f64| (acos(x) - x.acos()).abs())
            .fold(0.0, f64::max);
        assert!(worst < 2.5e-8, "{worst:e}");
        assert_eq!(acos(1.5), 0.0);
        assert!((acos(-1.5) - std::f64::consts::PI).abs() < 2.5e-8);
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
