//! The diffuse lobe: f = ρd/π + F D G2 / (4 cos θi cos θo), with ρd (RGB) and F per θd bin
//! solved for a given D and G, and the separation of ρd from the tabulated NDF's extraction.
//!
//! **F and ρd for a given D and G.** With q = ρd/π, x_ideal = D G2 / (4 cos θo) and
//! μ = cos θi, the model is x = F_j x_ideal + q μ on the samples of θd bin j (x = f cos θi).
//! F and q minimise Σ w (x_data − F_j x_ideal − q μ)², w = 1 / (1 + x_data)²: the squared
//! difference of ln(1 + x) to first order, the metric's own space. The normal equations form
//! an arrowhead (one row per F_j, all coupled through q); eliminating the F_j gives q in closed
//! form. F is then clipped to [0, 1] and q to [0, 1/π], and the two blocks are solved in turn
//! until they agree: block coordinate descent on a convex quadratic with box constraints, which
//! converges to its constrained minimum.
//!
//! **Separation.** The power iteration reads only the backscattering slice f(o, o), and a
//! diffuse term there is indistinguishable from a floor of the NDF. Alternating "extract from
//! f − ρd/π, then solve ρd" does not separate them: ρd = 0 is a fixed point, because the first
//! extraction's NDF grows the floor that stands for ρd, and the solve then finds no diffuse term.
//! [`separate`] instead searches the diffuse albedo s (mean of RGB, in the colour of the
//! minimum of f(o, o)) on [0, π min f(o, o)]: each candidate extracts from f(o, o) − ρd/π,
//! solves its own F and ρd, and is scored by its error on the search grid. The search tests
//! the two ends first, where the minimum often lies, then runs Brent's method
//! (`separation_search`). The extraction that wins is the tabulated NDF; its ρd is the one
//! solved with it.

use crate::error::FitError;
use crate::extract::Extraction;
use crate::metric::grid::{GridSamples, fresnel_diffuse_and_error};
use crate::model::brdf::Brdf;
use crate::model::microfacet::{MicrofacetBrdf, Ndf};
use crate::model::rgb::{Rgb, mean};
use glam::DVec3;
use std::cell::RefCell;
use std::f64::consts::PI;
use std::sync::Arc;

/// A source with a diffuse term taken away: f − ρd/π, clamped at zero (what the power
/// iteration reads of it: the backscattering slice).
pub struct WithoutDiffuse<'a> {
    /// The measured source.
    pub src: &'a dyn Brdf,
    /// ρd removed.
    pub albedo: Rgb,
}

impl Brdf for WithoutDiffuse<'_> {
    fn name(&self) -> &str {
        self.src.name()
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        let f = self.src.eval(wi, wo)?;
        Some(std::array::from_fn(|c| {
            (f[c] - self.albedo[c] / PI).max(0.0)
        }))
    }

    fn is_isotropic(&self) -> bool {
        self.src.is_isotropic()
    }

    fn backscatter(&self, theta: f64, phi: f64) -> Option<Rgb> {
        let f = self.src.backscatter(theta, phi)?;
        Some(std::array::from_fn(|c| {
            (f[c] - self.albedo[c] / PI).max(0.0)
        }))
    }
}

/// The tabulated model of a separation: its extraction and the ρd solved with it.
pub struct Separation {
    /// The extraction from f − ρd/π that fitted best.
    pub extraction: Extraction,
    /// ρd removed before that extraction (the model's own ρd is solved with its F).
    pub removed: Rgb,
    /// The search grid's error of that model.
    pub error: f64,
    /// Extractions run.
    pub rounds: usize,
}

/// Relative tolerance of the separation's search in the diffuse albedo.
pub const SEPARATION_TOLERANCE: f64 = 5e-3;

/// The albedo below which the separation's tolerance is absolute (or below the largest
/// removable albedo, if smaller): [`SEPARATION_TOLERANCE`] of it, 2.5e-4, far below what a
/// render or the metric can tell apart.
const SEPARATION_FLOOR: f64 = 0.05;

/// The smallest removable albedo worth a search: below it ρd is still solved with F, but the
/// NDF is extracted from f itself.
const SEPARATION_MIN: f64 = 1e-4;

/// The tabulated model of `src` with a diffuse lobe (see the module docs): the mean removed
/// albedo searched on [0, π min f(o, o)] (`separation_search`) from its top, in the colour of
/// min f(o, o), where a diffuse term shows most (on the 100 proxies, tabulated median / p90
/// 0.0180 / 0.0603, against 0.0187 / 0.0613 in the colour of the analytic fits' ρd from their
/// mean). `first` is the extraction without removal (s = 0); `extract` runs one extraction.
pub fn separate(
    src: &dyn Brdf,
    search: &GridSamples,
    first: Extraction,
    extract: impl Fn(&dyn Brdf) -> Result<Extraction, FitError>,
) -> Result<Separation, FitError> {
    let score = |ex: &Extraction| -> f64 {
        let model = tabulated_model(ex);
        fresnel_diffuse_and_error(&model, search, 0).map_or(f64::INFINITY, |(_, _, e)| e)
    };
    let first_error = score(&first);
    let best = RefCell::new(Separation {
        extraction: first,
        removed: [0.0; 3],
        error: first_error,
        rounds: 1,
    });
    // The largest removable albedo per channel: f(o, o) ≥ ρd/π up to 85°.
    let mut limit = [f64::INFINITY; 3];
    for k in 0..=85 {
        if let Some(f) = src.backscatter((k as f64).to_radians(), 0.0) {
            (0..3).for_each(|c| limit[c] = limit[c].min(PI * f[c].max(0.0)));
        }
    }
    let colour = match mean(limit) {
        m if m > 1e-6 && m.is_finite() => limit.map(|k| k / m),
        _ => [1.0; 3],
    };
    let s_max = (0..3)
        .filter(|&c| colour[c] > 0.0)
        .map(|c| limit[c].min(1.0) / colour[c])
        .fold(f64::INFINITY, f64::min);
    if !(s_max > SEPARATION_MIN) || !s_max.is_finite() {
        return Ok(best.into_inner());
    }
    let failure = RefCell::new(None);
    let objective = |s: f64| -> f64 {
        if s == 0.0 {
            return first_error;
        }
        let albedo = colour.map(|k| k * s);
        let ex = match extract(&WithoutDiffuse { src, albedo }) {
            Ok(ex) => ex,
            Err(e) => {
                failure.borrow_mut().get_or_insert(e);
                return f64::INFINITY;
            }
        };
        let e = score(&ex);
        let mut b = best.borrow_mut();
        b.rounds += 1;
        if e < b.error {
            (b.extraction, b.removed, b.error) = (ex, albedo, e);
        }
        e
    };
    separation_search(objective, s_max, s_max);
    let best = best.into_inner();
    match failure.into_inner() {
        Some(e) if !best.error.is_finite() => Err(e),
        _ => Ok(best),
    }
}

/// The minimum of `error(s)` over s ∈ [0, hi] from `start`, to [`SEPARATION_TOLERANCE`] of
/// max(s, min([`SEPARATION_FLOOR`], hi)); error(0) is known (the extraction without removal).
/// The minimum often lies at an end: at 0 without a diffuse term, at hi where the lobe is wider
/// than the backscattering slice lets the search remove (delrin). Brent's method reaches an
/// end only by golden sections, an extraction each, so the ends are tested first. If error(0)
/// is below error(start), the minimum lies below the start: 0 if the error a step above 0 is
/// higher. Otherwise it lies above 0: hi if error(hi) is below error(start) and the error a
/// step inside hi is higher. Anywhere else, Brent's method on the bracket that is left.
fn separation_search(error: impl Fn(f64) -> f64, start: f64, hi: f64) -> f64 {
    let tol = |s: f64| SEPARATION_TOLERANCE * s.max(SEPARATION_FLOOR.min(hi));
    // Each s is extracted once (Brent's method starts by evaluating its start).
    let seen = RefCell::new(Vec::<(f64, f64)>::new());
    let error = |s: f64| {
        if let Some(&(_, e)) = seen.borrow().iter().find(|p| p.0 == s) {
            return e;
        }
        let e = error(s);
        seen.borrow_mut().push((s, e));
        e
    };
    let brent =
        |lo: f64, start: f64, hi: f64| crate::fitting::optim::brent_to(error, lo, start, hi, tol);
    let (step, inside) = (2.0 * tol(0.0), hi - 2.0 * tol(hi));
    let s0 = start.clamp(step, hi);
    if error(0.0) <= error(s0) {
        return match error(step) >= error(0.0) {
            true => 0.0,
            false => brent(0.0, step, s0),
        };
    }
    if error(hi) <= error(s0) {
        return match error(inside) >= error(hi) {
            true => hi,
            // Below hi: the minimum lies above the start, unless the start is hi.
            false => brent(if s0 < inside { s0 } else { 0.0 }, inside, hi),
        };
    }
    brent(0.0, s0, hi)
}

/// The tabulated model of an extraction, F and ρd still to be solved.
pub(crate) fn tabulated_model(ex: &Extraction) -> MicrofacetBrdf {
    MicrofacetBrdf::ideal("tabulated", Ndf::Tabulated(Arc::new(ex.ndf.clone())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::sums::LinearSums;
    use crate::model::merl_grid::THETA_D_RES;

    /// The separation's search finds minima at either end in two or three evaluations, and
    /// an interior one to its tolerance, from starts on either side of it.
    #[test]
    fn separation_search_finds_ends_and_interior_minima() {
        use std::cell::Cell;
        let hi = 0.4;
        let run = |e: &dyn Fn(f64) -> f64, start: f64| {
            let n = Cell::new(0);
            let s = separation_search(
                |s| {
                    // error(0) is known to the search: only other points count.
                    n.set(n.get() + usize::from(s != 0.0));
                    e(s)
                },
                start,
                hi,
            );
            (s, n.get())
        };
        // No diffuse term: the error rises from 0.
        assert_eq!(run(&|s| 1.0 + s, hi), (0.0, 2));
        assert_eq!(run(&|s| 1.0 + s, 0.0), (0.0, 1));
        // A lobe wider than the search may remove: the error falls up to hi.
        assert_eq!(run(&|s| 1.0 - s, hi), (hi, 2));
        assert_eq!(run(&|s| 1.0 - s, 0.1), (hi, 3));
        // Interior: within the tolerance (twice it, Brent's bracket) of the minimum.
        for m in [0.003, 0.13, 0.37] {
            for start in [0.0, 0.05, 0.2, hi] {
                let (s, n) = run(&|s: f64| 1.0 + (s - m).powi(2), start);
                let tol = SEPARATION_TOLERANCE * m.max(SEPARATION_FLOOR.min(hi));
                assert!((s - m).abs() <= 2.0 * tol, "minimum {m} from {start}: {s}");
                assert!(n <= 12, "minimum {m} from {start}: {n} evaluations");
            }
        }
    }

    /// Samples from a known F and q, no noise: the solve gives them back.
    #[test]
    fn solve_recovers_fresnel_and_diffuse() {
        let mut sums = LinearSums::zero();
        let (q, f) = ([0.05, 0.02, 0.0], |j: usize| {
            0.04 + 0.9 * (j as f64 / 90.0).powi(5)
        });
        for j in 0..THETA_D_RES {
            for n in 0..40 {
                let m = 0.01 * (1.0 + n as f64).powi(2) / (1.0 + j as f64);
                let mu = 0.05 + 0.9 * ((n * 7 + j) % 40) as f64 / 40.0;
                for (c, qc) in q.iter().enumerate() {
                    let x = f(j) * m + qc * mu;
                    let w = 1.0 / (1.0 + x).powi(2);
                    let b = &mut sums.bins[j][c];
                    b[0] += w * m * m;
                    b[1] += w * m * mu;
                    b[2] += w * m * x;
                    sums.diffuse[c][0] += w * mu * mu;
                    sums.diffuse[c][1] += w * mu * x;
                }
            }
        }
        let (fresnel, kd) = sums.solve();
        for c in 0..3 {
            assert!((kd[c] - q[c]).abs() < 1e-9, "{kd:?}");
        }
        for (j, fj) in fresnel.iter().enumerate() {
            assert!(
                fj.iter().all(|&v| (v - f(j)).abs() < 1e-9),
                "bin {j}: {fj:?}"
            );
        }
    }
}
