//! Physical Fresnel curves fitted to an extracted table F(θd): a Schlick F0 per channel, a
//! dielectric of one index η, a conductor of index η + i k per channel.
//!
//! Each is fitted by least squares on the table's bins with θd ≤ `MAX_THETA_D` (the last bins
//! hold few samples and the most noise), all bins weighted alike: Schlick in closed form
//! (F − s = F0 (1 − s), s = (1 − cos θd)⁵), the dielectric by Brent's method on η ∈ [1, 4], the
//! conductor per channel in Gulbrandsen's reflectivity and edge-tint coordinates (a grid, then
//! alternating Brent steps). The record keeps every fit with its RMS distance to the
//! table and its error in Facet's metric, and names the one the renderer uses (`used`).

use crate::fitting::optim::brent;
use crate::model::fresnel::{Fresnel, FresnelTable, conductor, dielectric};
use crate::model::fresnel_curves::{FitQuality, FresnelChoice, FresnelFits};
use crate::model::rgb::Rgb;
use rayon::prelude::*;

/// The largest θd fitted, degrees.
pub const MAX_THETA_D: f64 = 80.0;

/// The fitting of the record's Fresnel curves ([`FresnelFits`] is facet-brdf's, read by the
/// renderer; fitting it is the fitter's).
pub trait FitFresnelCurves: Sized {
    /// The three fits of `table`; `errors` gives the metric's errors of the candidate Fresnels
    /// (Schlick, dielectric, conductor), all three at once so that one pass can measure them.
    fn of(table: &FresnelTable, errors: impl FnOnce(&[Fresnel; 3]) -> [f64; 3]) -> Self;
}

impl FitFresnelCurves for FresnelFits {
    fn of(table: &FresnelTable, errors: impl FnOnce(&[Fresnel; 3]) -> [f64; 3]) -> Self {
        let bins: Vec<(f64, Rgb)> = table
            .theta_d
            .iter()
            .zip(&table.rgb)
            .filter(|(t, _)| t.to_degrees() <= MAX_THETA_D + 1e-9)
            .map(|(t, f)| (t.cos(), *f))
            .collect();
        let rms = |fresnel: &Fresnel| {
            let s: f64 = bins
                .iter()
                .map(|(c, f)| {
                    let g = fresnel.eval(*c);
                    (0..3).map(|i| (g[i] - f[i]).powi(2)).sum::<f64>()
                })
                .sum();
            (s / (3 * bins.len().max(1)) as f64).sqrt()
        };
        let schlick_f0 = fit_schlick(&bins);
        let dielectric_eta = fit_dielectric(&bins);
        let (conductor_eta, conductor_k) = fit_conductor(&bins);
        let curves = [
            Fresnel::Schlick { f0: schlick_f0 },
            Fresnel::Dielectric {
                eta: dielectric_eta,
            },
            Fresnel::Conductor {
                eta: conductor_eta,
                k: conductor_k,
            },
        ];
        let e = errors(&curves);
        let quality = |n: usize| FitQuality {
            rms: rms(&curves[n]),
            error: e[n],
        };
        FresnelFits {
            schlick_f0,
            schlick: quality(0),
            dielectric_eta,
            dielectric: quality(1),
            conductor_eta,
            conductor_k,
            conductor: quality(2),
            used: FresnelChoice::Table,
        }
    }
}

/// F0 per channel minimising Σ (F0 + (1 − F0) s − F)², clipped to [0, 1].
fn fit_schlick(bins: &[(f64, Rgb)]) -> Rgb {
    std::array::from_fn(|c| {
        let (mut num, mut den) = (0.0, 0.0);
        for (cos, f) in bins {
            let s = (1.0 - cos).powi(5);
            num += (f[c] - s) * (1.0 - s);
            den += (1.0 - s) * (1.0 - s);
        }
        if den > 0.0 {
            (num / den).clamp(0.0, 1.0)
        } else {
            0.0
        }
    })
}

/// One η for all channels minimising the squared difference, η ∈ [1, 4].
fn fit_dielectric(bins: &[(f64, Rgb)]) -> f64 {
    let cost = |eta: f64| -> f64 {
        bins.iter()
            .map(|(c, f)| {
                let d = dielectric(*c, eta);
                f.iter().map(|v| (v - d).powi(2)).sum::<f64>()
            })
            .sum()
    };
    // Start from the η whose F(0) = ((η − 1)/(η + 1))² matches the mean F at normal incidence.
    let f0 = bins
        .first()
        .map_or(0.04, |(_, f)| f.iter().sum::<f64>() / 3.0);
    let r = f0.clamp(1e-6, 0.6).sqrt();
    let start = ((1.0 + r) / (1.0 - r)).clamp(1.0, 4.0);
    brent(cost, 1.0, start, 4.0, 1e-6)
}

/// (η, k) per channel minimising the squared difference, searched in Gulbrandsen's (2014)
/// coordinates: reflectivity r = F(0) and edge tint g, both in [0, 1], nearly independent where
/// (η, k) run along a curved valley. An 8 × 8 grid over (r, g) (16 × 16 gave gold's η and k
/// to the same 1e-6, at 2.5× the time), then alternating Brent steps, each channel a task.
fn fit_conductor(bins: &[(f64, Rgb)]) -> (Rgb, Rgb) {
    // The channels are independent: one task each.
    let per_channel: Vec<(f64, f64)> = (0..3)
        .into_par_iter()
        .map(|c| {
            let cost = |r: f64, g: f64| -> f64 {
                let (e, kk) = gulbrandsen(r, g);
                bins.iter()
                    .map(|(cos, f)| (conductor(*cos, e, kk) - f[c]).powi(2))
                    .sum()
            };
            const N: usize = 8;
            const R_MAX: f64 = 0.999;
            let mut best = (f64::INFINITY, 0.5, 0.5);
            for a in 0..N {
                let r = R_MAX * (a as f64 + 0.5) / N as f64;
                for b in 0..N {
                    let g = (b as f64 + 0.5) / N as f64;
                    let v = cost(r, g);
                    if v < best.0 {
                        best = (v, r, g);
                    }
                }
            }
            let (_, mut r, mut g) = best;
            for _ in 0..8 {
                let (r0, g0) = (r, g);
                r = brent(|x| cost(x, g), 0.0, r, R_MAX, 1e-7);
                g = brent(|x| cost(r, x), 0.0, g, 1.0, 1e-7);
                // Converged: a round that moves neither by more than Brent's own tolerance.
                if (r - r0).abs() <= 1e-7 * r0.max(1e-3) && (g - g0).abs() <= 1e-7 * g0.max(1e-3) {
                    break;
                }
            }
            gulbrandsen(r, g)
        })
        .collect();
    (
        std::array::from_fn(|c| per_channel[c].0),
        std::array::from_fn(|c| per_channel[c].1),
    )
}

/// (η, k) of reflectivity r and edge tint g (Gulbrandsen, "Artist friendly metallic Fresnel",
/// JCGT 2014): η = g (1 − r)/(1 + r) + (1 − g)(1 + √r)/(1 − √r),
/// k = sqrt((r (η + 1)² − (η − 1)²) / (1 − r)).
fn gulbrandsen(r: f64, g: f64) -> (f64, f64) {
    let sr = r.sqrt();
    let n = g * (1.0 - r) / (1.0 + r) + (1.0 - g) * (1.0 + sr) / (1.0 - sr);
    let k2 = (r * (n + 1.0).powi(2) - (n - 1.0).powi(2)) / (1.0 - r);
    (n.max(1e-4), k2.max(0.0).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table_of(f: &Fresnel) -> FresnelTable {
        FresnelTable::on_merl_bins(
            (0..90)
                .map(|j| f.eval((j as f64).to_radians().cos()))
                .collect(),
        )
    }

    /// Each fit recovers the curve it was made from.
    #[test]
    fn fits_recover_their_own_curves() {
        let gold = table_of(&Fresnel::GOLD);
        let fits = FresnelFits::of(&gold, |_| [0.0; 3]);
        assert!(fits.conductor.rms < 1e-4, "{fits:?}");
        let Fresnel::Conductor { eta, k } = Fresnel::GOLD else {
            unreachable!()
        };
        for c in 0..3 {
            assert!(
                (fits.conductor_eta[c] / eta[c] - 1.0).abs() < 0.02,
                "{fits:?}"
            );
            assert!((fits.conductor_k[c] / k[c] - 1.0).abs() < 0.02, "{fits:?}");
        }
        let glass = FresnelFits::of(&table_of(&Fresnel::Dielectric { eta: 1.5 }), |_| [0.0; 3]);
        assert!((glass.dielectric_eta - 1.5).abs() < 1e-3, "{glass:?}");
        assert!(glass.dielectric.rms < 1e-6);
        let schlick = Fresnel::Schlick {
            f0: [0.04, 0.5, 0.9],
        };
        let s = FresnelFits::of(&table_of(&schlick), |_| [0.0; 3]);
        for (a, b) in s.schlick_f0.iter().zip([0.04, 0.5, 0.9]) {
            assert!((a - b).abs() < 1e-9, "{s:?}");
        }
    }
}
