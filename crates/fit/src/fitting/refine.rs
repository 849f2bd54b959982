//! The tabulated NDF refined in the space of the error metric, after the power iteration.
//!
//! On the isotropic MERL grid D enters the model only through its θh bin, so with F, ρd and G
//! held the metric splits into 90 problems of one unknown: the scale s_i of D in bin i. Each
//! sample's error |ln(1 + s a + b) − ln(1 + x)| is least at s* = (x − b) / a with slopes ±w on
//! either side, so a bin's error is least at the weighted median of its samples' s*
//! ([`IsoSamples::bin_medians`], one pass over the rows, w taken at the current s; on the 100
//! proxies, medians over every row rather than half of them gave tabulated median / p90
//! 0.0187 / 0.0613 against 0.0188 / 0.0621, 40 fits better and 12 worse by more than 0.2 %).
//! A round moves every bin to its median, bounded to ±`SPAN` in ln s (halving every round), and
//! solves F and ρd again for the new D. The rounds run on the rows given (in the fit, every
//! fourth φd bin of the final steps' rows, [`crate::metric::grid::CoarseGrid`]: a sixteenth of the
//! grid, every (θh, θd) row kept), from the start's F and ρd ([`Refinement::start`], whose
//! G2 / (4 cos θo) and plain sums they reuse), and stop when a round gains less than
//! `MIN_GAIN`. The
//! bin scales, interpolated in θ, then multiply the D table, which is renormalised
//! (∫ D cos θh dω = 1); G1 is either recomputed by Smith's relation from the new D or held,
//! whichever fits better. The result is kept only if its error on the set is lower than the
//! start's.

use crate::extract::azimuthal_ab;
use crate::metric::iso::{IsoSamples, MEDIAN_BUCKETS, RowIdeals, RowSums};
use crate::metric::iso_tables::IsoTables;
use crate::model::merl_grid::{THETA_H_RES, bin_angles};
use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf};
use crate::model::rgb::Rgb;
use crate::model::tabulated::{NdfTables, Stretch, TabulatedNdf, theta_node, u_node_theta};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

/// Rounds at most. On the 100 proxies, tabulated median / p90 after one round 0.0203 / 0.0620,
/// two 0.0193 / 0.0619, three 0.0188 / 0.0621, four 0.0188 / 0.0621 (eight rounds of the
/// earlier seven-scale scans: 0.0209 / 0.0622).
const ROUNDS: usize = 3;
/// The first round moves ln s by at most SPAN (a factor e² ≈ 7.4 in D); the bound halves every
/// round. With a first bound of 0.5, most bins (50–90 of 90 on delrin) hit it in every round.
const SPAN: f64 = 2.0;
/// Reweighted steps of the start's and the final candidates' F / ρd solves, as the fit's final
/// steps take (towards the metric's L1 minimum, which the bin medians minimise: a plain
/// weighted least-squares solve would undo part of their gain).
const IRLS: usize = 2;
/// Reweighted steps of the solve after each round's medians. On the 100 proxies with the
/// earlier scans, tabulated median / p90: one 0.0209 / 0.0636, two 0.0210 / 0.0630 (and
/// slower); none leaves 3 of them worse than their best analytic fit.
const ROUND_IRLS: usize = 1;
/// A round that lowers the error by less than this fraction ends the refinement.
const MIN_GAIN: f64 = 1e-3;

/// A refined tabulated model.
pub(crate) struct Refined {
    /// The refined NDF and G1.
    pub ndf: TabulatedNdf,
    /// F per θd bin solved with it.
    pub fresnel: Vec<Rgb>,
    /// ρd solved with it.
    pub albedo: Rgb,
    /// Its error on the refinement's set.
    pub error: f64,
    /// Rounds run.
    pub rounds: usize,
}

/// A model of `ndf` whose F and ρd are still to be solved.
pub(crate) fn model_of(ndf: &TabulatedNdf) -> MicrofacetBrdf {
    MicrofacetBrdf::ideal("refined", Ndf::Tabulated(Arc::new(ndf.clone())))
}

/// F per θd bin, ρd and the mean error per sample and channel of a model on a set, as
/// [`crate::metric::grid::fresnel_diffuse_and_error`] gives them.
pub(crate) type Solved = (Vec<Rgb>, Rgb, f64);

/// An isotropic tabulated NDF on the rows of a set, with what its start and its refinement
/// share: its G2 / (4 cos θo) on those rows and their plain weighted sums (G is held through
/// the rounds: only D changes).
pub(crate) struct Refinement<'a, const N: usize, const M: usize, const P: usize> {
    ndf: &'a TabulatedNdf,
    sub: &'a IsoSamples<N, M, P>,
    /// Samples in the set (the mean error's divisor, over three channels).
    samples: usize,
    tables: IsoTables,
    ideals: RowIdeals<P>,
    plain: RowSums,
}

impl<'a, const N: usize, const M: usize, const P: usize> Refinement<'a, N, M, P> {
    /// `None` when the NDF is not isotropic.
    pub fn new(ndf: &'a TabulatedNdf, sub: &'a IsoSamples<N, M, P>) -> Option<Self> {
        let tables = IsoTables::new(&model_of(ndf)).filter(|_| ndf.is_isotropic())?;
        let ideals = sub.ideals(&tables);
        let plain = sub.row_sums(&ideals);
        Some(Refinement {
            ndf,
            sub,
            samples: sub.count.max(1),
            tables,
            ideals,
            plain,
        })
    }

    /// F and ρd solved for the NDF as it is (with `IRLS` reweighted steps), and its error: the
    /// refinement's start, as `crate::metric::grid::fresnel_diffuse_and_error` gives it (the plain
    /// sums cached, equal to f64 rounding).
    pub fn start(&self) -> Solved {
        let (f, q, e) = self.sub.fresnel_diffuse_and_error_sum_with(
            &self.tables,
            IRLS,
            &self.ideals,
            Some(&self.plain),
        );
        (f, q.map(|q| q * PI), self.mean(e))
    }

    /// The mean error per sample and channel of an error sum.
    fn mean(&self, sum: f64) -> f64 {
        sum / (3 * self.samples) as f64
    }

    /// The NDF refined from `start` ([`Self::start`]); `None` when nothing better was found.
    pub fn run(&self, start: &Solved) -> Option<Refined> {
        let (sub, ideals, plain) = (self.sub, &self.ideals, &self.plain);
        let mut tables = self.tables.clone();
        let d0 = tables.d32;
        tables.set_fresnel(&start.0);
        tables.diffuse = start.1.map(|a| a / PI);
        let solve = |tables: &mut IsoTables| {
            let (f, q, e) =
                sub.fresnel_diffuse_and_error_sum_with(tables, ROUND_IRLS, ideals, Some(plain));
            tables.set_fresnel(&f);
            tables.diffuse = q;
            e
        };
        let mut e = start.2 * (3 * self.samples) as f64;
        let (mut ln_s, mut best) = ([0.0f64; THETA_H_RES], ([0.0f64; THETA_H_RES], e));
        let (mut span, mut rounds) = (SPAN, 0);
        while rounds < ROUNDS {
            rounds += 1;
            let medians = sub.bin_medians(&tables, ideals, span as f32);
            for (i, h) in medians.iter().enumerate() {
                ln_s[i] += weighted_median(h, span);
                tables.d32[i] = (d0[i] as f64 * ln_s[i].exp()) as f32;
            }
            let next = solve(&mut tables);
            let gain = (e - next) / e;
            if next < best.1 {
                best = (ln_s, next);
            }
            e = next;
            span *= 0.5;
            if !(gain >= MIN_GAIN) {
                break;
            }
        }
        // A final candidate's F, ρd and error; one whose G is the rounds' (G1 held) reuses their
        // G2 / (4 cos θo) and plain sums.
        let solve_final = |ndf: &TabulatedNdf| {
            let t = IsoTables::new(&model_of(ndf))?;
            let (f, q, e) = if t.lambda_cos == self.tables.lambda_cos {
                sub.fresnel_diffuse_and_error_sum_with(&t, IRLS, ideals, Some(plain))
            } else {
                sub.fresnel_diffuse_and_error_sum(&t, IRLS)
            };
            Some((f, q.map(|q| q * PI), self.mean(e)))
        };
        let ndf = self.ndf;
        let d = rescaled_d(ndf, &best.0);
        let held = ndf.tables().g1.clone();
        let smith = smith_g1(&d, ndf.tables().ng)?;
        [smith, held]
            .into_iter()
            .filter_map(|g1| {
                let t = ndf.tables();
                let tables = NdfTables {
                    d: d.clone(),
                    g1,
                    ..t.clone()
                };
                let ndf = TabulatedNdf::new(tables, Stretch::IDENTITY).ok()?;
                let (fresnel, albedo, error) = solve_final(&ndf)?;
                Some(Refined {
                    ndf,
                    fresnel,
                    albedo,
                    error,
                    rounds,
                })
            })
            .filter(|r| r.error < start.2)
            .min_by(|a, b| a.error.total_cmp(&b.error))
    }
}

/// The weighted median of a [`IsoSamples::bin_medians`] histogram in ln s over
/// [−span, span], linear within its bucket; 0 for an empty bin.
fn weighted_median(h: &[f64; MEDIAN_BUCKETS + 2], span: f64) -> f64 {
    let half = 0.5 * h.iter().sum::<f64>();
    if !(half > 0.0) {
        return 0.0;
    }
    let width = 2.0 * span / MEDIAN_BUCKETS as f64;
    let mut below = 0.0;
    for (b, &w) in h.iter().enumerate() {
        if below + w >= half {
            return match b {
                0 => -span,
                b if b == MEDIAN_BUCKETS + 1 => span,
                b => -span + width * ((b - 1) as f64 + (half - below) / w),
            };
        }
        below += w;
    }
    span
}

/// The D table times the bin scales exp(ln s) interpolated linearly in θ between the bins'
/// θh (held beyond the first and last), renormalised to ∫ D cos θ dω = 1.
fn rescaled_d(ndf: &TabulatedNdf, ln_s: &[f64; THETA_H_RES]) -> Vec<f64> {
    let t = ndf.tables();
    let theta: Vec<f64> = (0..THETA_H_RES)
        .map(|i| bin_angles(i, 0, 0).theta_h)
        .collect();
    let at = |th: f64| -> f64 {
        let i = theta.partition_point(|&x| x <= th);
        if i == 0 {
            return ln_s[0];
        }
        if i == THETA_H_RES {
            return ln_s[THETA_H_RES - 1];
        }
        let w = (th - theta[i - 1]) / (theta[i] - theta[i - 1]);
        ln_s[i - 1] + w * (ln_s[i] - ln_s[i - 1])
    };
    let mut d: Vec<f64> = (0..t.nu)
        .map(|k| t.d[k] * at(u_node_theta(k, t.nu)).exp())
        .collect();
    let norm = projected_area(&d);
    if norm > 0.0 {
        d.iter_mut().for_each(|v| *v /= norm);
    }
    d
}

/// ∫ D cos θ dω of an isotropic D table on u nodes, by the cells the sampler uses.
fn projected_area(d: &[f64]) -> f64 {
    let nu = d.len();
    (0..nu - 1)
        .map(|k| {
            let (ta, tb) = (u_node_theta(k, nu), u_node_theta(k + 1, nu));
            0.5 * (d[k] + d[k + 1]) * (0.5 * (ta + tb)).cos() * (ta.cos() - tb.cos()) * 2.0 * PI
        })
        .sum()
}

/// G1 by Smith's relation from an isotropic D table: G1(θo) = cos θo / ∫ D(h) ⟨o, h⟩₊ dh,
/// the integral as ∫ D(θh) sin θh A(θo, θh) dθh with A the azimuthal integral, by the midpoint
/// rule in u = sqrt(θh / (π/2)) over 512 cells (as close to the closed form as 2048 cells: 3e-4
/// on a tabulated GGX of α 0.05, the D table's interpolation error). `None` if D is zero.
fn smith_g1(d: &[f64], ng: usize) -> Option<Vec<f64>> {
    let nu = d.len();
    let tables = NdfTables {
        nu,
        nphi: 1,
        d: d.to_vec(),
        ng: 2,
        g1: vec![1.0; 2],
    };
    let ndf = TabulatedNdf::new(tables, Stretch::IDENTITY).ok()?;
    const CELLS: usize = 512;
    // (cos θ, sin θ, weight) per cell: the 512 × 512 azimuthal integrals take no trigonometry.
    let nodes: Vec<(f64, f64, f64)> = (0..CELLS)
        .map(|a| {
            let u = (a as f64 + 0.5) / CELLS as f64;
            let th = u * u * FRAC_PI_2;
            // dθ = π u du
            let w = ndf.base_d(th, 0.0) * th.sin() * PI * u / CELLS as f64;
            (th.cos(), th.sin(), w)
        })
        .collect();
    Some(
        (0..ng)
            .into_par_iter()
            .map(|k| {
                let to = theta_node(k, ng);
                let (c, s) = (to.cos(), to.sin());
                // ∫ D(h) ∫ <o, h>+ dφ: azimuthal_integral(θo, θh) with the cosines given
                let i: f64 = nodes
                    .iter()
                    .map(|&(ch, sh, w)| w * azimuthal_ab(c * ch, s * sh))
                    .sum();
                if i > 0.0 {
                    (to.cos().max(0.0) / i).min(1.0)
                } else {
                    0.0
                }
            })
            .collect(),
    )
}

/// An analytic NDF as isotropic tables of `nu` D nodes and `ng` G1 nodes (G1 = 1 / (1 + Λ)).
pub(crate) fn tabulate(ndf: AnalyticNdf, nu: usize, ng: usize) -> Option<TabulatedNdf> {
    let n = Ndf::Analytic(ndf);
    let dir = |th: f64| DVec3::new(th.sin(), 0.0, th.cos());
    let d = (0..nu).map(|k| n.d(dir(u_node_theta(k, nu)))).collect();
    // G1 = 1 / (1 + Λ), 0 at θ = π/2 where Λ is infinite (G1 ∝ cos θ there, as extracted).
    let g1 = (0..ng)
        .map(|k| {
            let th = theta_node(k, ng);
            if th >= FRAC_PI_2 {
                0.0
            } else {
                1.0 / (1.0 + n.lambda(dir(th)))
            }
        })
        .collect();
    let tables = NdfTables {
        nu,
        nphi: 1,
        d,
        ng,
        g1,
    };
    TabulatedNdf::new(tables, Stretch::IDENTITY).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::grid::GridSamples;
    use crate::model::microfacet::NdfKind;

    /// The isotropic Λ of a stretched tabulated NDF is its general Λ(ω) (the same G1₀
    /// interpolated at the same θ₀, computed by atan2 instead of acos: 1e-12 of rounding), at
    /// grazing cosines and near the normal too.
    #[test]
    fn isotropic_lambda_of_a_stretched_table_is_the_general_one() {
        let base = tabulate(AnalyticNdf::isotropic(NdfKind::Beckmann, 0.4), 128, 64).unwrap();
        let stretch = Stretch {
            alpha_x: 0.55,
            alpha_y: 0.55,
            rotation: 0.7,
        };
        let t = TabulatedNdf::new(base.tables().clone(), stretch).unwrap();
        assert!(t.is_isotropic());
        for k in 1..=4096 {
            let mu = k as f64 / 4096.0;
            let w = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let (a, b) = (t.lambda_isotropic(mu), t.lambda(w));
            assert!((a - b).abs() <= 1e-12 * b.max(1.0), "μ = {mu}: {a} vs {b}");
        }
        assert_eq!(t.lambda_isotropic(0.0), f64::INFINITY);
    }

    /// Smith's G1 recomputed from a tabulated GGX D matches GGX's closed form, 1 / (1 + Λ).
    #[test]
    fn smith_g1_of_tabulated_ggx_matches_closed_form() {
        for alpha in [0.05, 0.3, 1.0] {
            let ggx = AnalyticNdf::isotropic(NdfKind::Ggx, alpha);
            let t = tabulate(ggx, 256, 64).unwrap();
            let g1 = smith_g1(&t.tables().d, 64).unwrap();
            for (k, (&a, &b)) in g1.iter().zip(&t.tables().g1).enumerate().take(60) {
                // The tabulated D's interpolation error in u costs ~1e-3 for α = 0.05.
                assert!((a - b).abs() < 3e-3, "α {alpha} node {k}: {a} vs {b}");
            }
        }
    }

    /// The D table of an analytic NDF is normalised: ∫ D cos θ dω = 1.
    #[test]
    fn tabulated_ggx_has_unit_projected_area() {
        for alpha in [0.05, 0.3, 1.0] {
            let t = tabulate(AnalyticNdf::isotropic(NdfKind::Ggx, alpha), 256, 16).unwrap();
            let a = projected_area(&t.tables().d);
            assert!((a - 1.0).abs() < 2e-3, "α {alpha}: {a}");
        }
    }

    /// Each θh bin's weighted median is the scale of D that brings the model back to its data:
    /// data from a GGX with a diffuse term, the model the same with D of chosen bins scaled by
    /// e^c, and one round's medians give −c per bin. Every sample of a bin then meets its data
    /// at the same s*, so the median is exact but for the histogram (half a bucket, span / 129)
    /// and the tables' Λ against the data's exact G (1e-3 in the metric,
    /// `tests/grid.rs`): 0.02 in ln s. A bin asked to move beyond the span stops at it.
    #[test]
    fn bin_medians_recover_scaled_bins() {
        let src =
            crate::model::analytic::parse_analytic("ggx?alpha=0.3&f0=0.5&kd=0.2,0.1,0.05").unwrap();
        let set = GridSamples::new(&src).diagonal(8);
        let iso = set.iso.as_ref().unwrap();
        let mut tables = IsoTables::new(&src).unwrap();
        let shifts: [(usize, f64); 5] = [(5, 0.4), (20, -0.7), (40, 1.1), (60, -0.3), (75, 3.0)];
        for &(i, c) in &shifts {
            tables.d32[i] *= (c as f32).exp();
        }
        let span = SPAN;
        let ideals = iso.ideals(&tables);
        let medians = iso.bin_medians(&tables, &ideals, span as f32);
        for (i, h) in medians.iter().enumerate().take(80) {
            let c = shifts.iter().find(|s| s.0 == i).map_or(0.0, |s| s.1);
            let want = (-c).clamp(-span, span);
            let got = weighted_median(h, span);
            assert!(
                (got - want).abs() < 0.02,
                "θh bin {i}: {got} against {want}"
            );
        }
    }

    /// The weighted median of a histogram: linear within the bucket that holds half the
    /// weight, the ends for weight beyond the span, 0 for an empty bin.
    #[test]
    fn weighted_median_of_histograms() {
        let width = 2.0 * SPAN / MEDIAN_BUCKETS as f64;
        let mut h = [0.0; MEDIAN_BUCKETS + 2];
        assert_eq!(weighted_median(&h, SPAN), 0.0);
        // Weight 1 in bucket 10 and 3 in bucket 20: half (2) lies a third into bucket 20.
        (h[11], h[21]) = (1.0, 3.0);
        let want = -SPAN + width * (20.0 + 1.0 / 3.0);
        assert!((weighted_median(&h, SPAN) - want).abs() < 1e-12);
        h[MEDIAN_BUCKETS + 1] = 10.0;
        assert_eq!(weighted_median(&h, SPAN), SPAN);
        h[0] = 30.0;
        assert_eq!(weighted_median(&h, SPAN), -SPAN);
    }
}
