//! The coat step: a clear coat ([`crate::model::coat`]) searched over the single-layer fit and
//! kept only where the coated model looks closer to the source.
//!
//! For a candidate coat the base is what the data must be under it, seen from inside
//! (`SeenFromInside`: f_base(ωi', ωo') = η² (f(ωi, ωo) − coat lobe) / (T(θi) T(θo)) at the
//! outside directions of each inside pair; pairs past the critical angle have none and are
//! missing), fitted by the same pipeline as any source. The candidate's score is the coated
//! model's error on the source's own samples. The search ([`search`]): a 4 × 3 grid of α and
//! weight, α by Brent's method at each weight from its best, the best of those, its weight,
//! and α again within ±10 % and finer, on a cheap base fit (32 extraction nodes, the tabulated
//! model alone, no refinement, every ninth φd bin of every second θd row) scored on every 64th
//! row of the source; then one full fit of the base at the coat found. The coat is kept when
//! the coated tabulated model's look ([`SphereScene`]) is at least [`LOOK_MARGIN`] below the
//! single layer's.

use crate::error::FitError;
use crate::fitting::optim::brent;
use crate::fitting::{CoatSearch, FitConfig, Models};
use crate::metric::grid::{GridSamples, error_metric};
use crate::metric::look::SphereScene;
use crate::model::brdf::Brdf;
use crate::model::coat::{Coat, CoatLayer, Coated};
use crate::model::fresnel::dielectric;
use crate::model::geometry::azimuth_between;
use crate::model::material::{CoatRecord, CoatedModels, FittedMaterial};
use crate::model::merl_grid::MerlTable;
use crate::model::merl_grid::{
    GridPoint, PHI_D_RES, SAMPLES, THETA_D_RES, THETA_H_RES, bin_angles, bin_directions, bin_of,
    index,
};
use crate::model::microfacet::{
    AnalyticNdf, MicrofacetBrdf, NdfKind, correlation, g2, lambda_from_alpha_tan,
};
use crate::model::rgb::Rgb;
use crate::sources::merl::MerlBrdf;
use glam::DVec3;
use rayon::prelude::*;
use std::sync::{Mutex, OnceLock};

/// The coat's index of refraction: a clear lacquer's (car paints' coats are 1.45–1.55).
pub const COAT_ETA: f64 = 1.5;
/// [`CoatSearch::Auto`] searches a coat where the single layer's look (the report's
/// point-light sphere, [`SphereScene::REPORT`]) differs from the data by more than this
/// ΔE2000.
pub const TRY_ABOVE: f64 = 0.9;
/// A coat is kept when it lowers the look's ΔE2000 by at least this.
pub const LOOK_MARGIN: f64 = 0.1;
/// The search's α stays in this range.
const ALPHA_RANGE: (f64, f64) = (0.003, 0.6);
/// The search scores every coat of this grid first: α about a factor of 3 apart over a
/// lacquer's range (chrome's coat, 0.0028, to a satin's), ...
const COARSE_ALPHAS: [f64; 4] = [0.012, 0.036, 0.11, 0.33];
/// ... at each of these weights (the score has several minima on real paints, and at an α
/// off the true one a lower weight hides the mismatch).
const COARSE_WEIGHTS: [f64; 3] = [0.15, 0.5, 1.0];
/// The search scores candidates on every `SEARCH_STRIDE`-th (θh, θd) row of the source.
const SEARCH_STRIDE: usize = 64;
/// The search's base fits see every `SEARCH_STRIDES.0`-th θd row and every
/// `SEARCH_STRIDES.1`-th φd bin of the data under the coat (a ninth of the bins at 4 × 3:
/// 1.7–2× faster fits and the same coats as every fourth φd bin on the MERL-100).
const SEARCH_STRIDES: (usize, usize) = (2, 9);
/// The search's base fits extract on this many nodes.
const SEARCH_RESOLUTION: usize = 32;

/// A coat the search found, with the base fitted under it in full, and how it looks
/// ([`SphereScene::delta_e_to_table`]).
#[derive(Clone, Debug)]
pub struct CoatCandidate {
    /// The coat and the base's models under it.
    pub models: CoatedModels,
    /// The coated tabulated model's look: ΔE2000 against the source's table.
    pub look: f64,
}

impl CoatCandidate {
    /// Whether the fit keeps the coat over a single layer of look `single`: it looks better by
    /// [`LOOK_MARGIN`].
    pub fn keeps(&self, single: f64) -> bool {
        self.look < single - LOOK_MARGIN
    }

    /// The coat kept, with the coated models' errors on `full` (computed only for a kept
    /// coat: each pass evaluates the coated model on every sample).
    pub fn kept(self, full: &GridSamples) -> CoatedFit {
        let (layer, base) = (&self.models.layer, &self.models.base);
        let error = |m: &MicrofacetBrdf| coated_error(layer, m, full);
        CoatedFit {
            error: error(&base.tabulated),
            ggx_error: base.ggx.as_ref().map(error),
            beckmann_error: base.beckmann.as_ref().map(error),
            models: self.models,
        }
    }
}

/// A coat kept by the fit: the layer and the base fitted under it.
#[derive(Clone, Debug)]
pub struct CoatedFit {
    /// The coat and the base's models under it.
    pub models: CoatedModels,
    /// The coated tabulated model's error on the source's full grid.
    pub error: f64,
    /// The coated GGX and Beckmann models' errors, where fitted.
    pub ggx_error: Option<f64>,
    /// See `ggx_error`.
    pub beckmann_error: Option<f64>,
}

impl CoatedFit {
    /// What the fit JSON holds of it.
    pub fn record(&self) -> CoatRecord {
        CoatRecord {
            coat: self.models.layer.coat,
            error: self.error,
            ggx_error: self.ggx_error,
            beckmann_error: self.beckmann_error,
            base: Box::new(self.models.base.record.clone()),
        }
    }
}

/// The data as the base must be under `layer`, at the inside directions of the grid's bins.
struct SeenFromInside<'a> {
    /// The measurement on the MERL grid.
    data: &'a MerlTable,
    /// The coat over the base.
    layer: &'a CoatLayer,
    /// The coat's lobe at the grid's bins.
    lobe: LobeAtBins,
    /// Where each inside bin's outside pair falls on the grid.
    places: &'a GridPlaces,
}

/// An inside bin's outside pair and where it falls on the grid.
type Placed = (DVec3, DVec3, GridPoint);

/// The outside pair of each inside bin a table under the coat holds (every `strides.0`-th θd
/// row, every `strides.1`-th φd bin) and where it falls on the grid: they depend on η alone,
/// so a search (one η) refracts and places its bins once for every candidate and a single fit
/// as it goes. Placing a pair (its θh, θd and φd) cost as much as the rest of a table.
pub struct GridPlaces {
    /// A coat of the η placed for (its α and weight play no part in refraction).
    coat: Coat,
    /// The θd and φd strides of the bins held.
    strides: (usize, usize),
    placed: Option<Vec<Option<Placed>>>,
}

impl GridPlaces {
    /// The bins of every `strides.0`-th θd row and `strides.1`-th φd bin (divisors of
    /// [`THETA_D_RES`] and [`PHI_D_RES`]) under a coat of index `eta`, placed now.
    pub fn placed(eta: f64, strides: (usize, usize)) -> Self {
        debug_assert!(THETA_D_RES.is_multiple_of(strides.0));
        debug_assert!(PHI_D_RES.is_multiple_of(strides.1));
        let (rows, per_row) = (THETA_D_RES / strides.0, PHI_D_RES / strides.1);
        let mut places = GridPlaces {
            coat: Coat::new(eta, COARSE_ALPHAS[0], 1.0),
            strides,
            placed: None,
        };
        let placed = (0..THETA_H_RES * rows * per_row)
            .into_par_iter()
            .map(|n| {
                let (ij, k) = (n / per_row, n % per_row);
                let (i, j) = (ij / rows, ij % rows);
                places.place(i, j * strides.0, k * strides.1)
            })
            .collect();
        places.placed = Some(placed);
        places
    }

    /// Every bin under a coat of index `eta`, placed when asked.
    pub fn on_demand(eta: f64) -> Self {
        GridPlaces {
            coat: Coat::new(eta, COARSE_ALPHAS[0], 1.0),
            strides: (1, 1),
            placed: None,
        }
    }

    /// Bin (i, j, k)'s outside pair and its place; `None` for a bin the table does not hold,
    /// below the horizon, or past the critical angle.
    fn get(&self, i: usize, j: usize, k: usize) -> Option<Placed> {
        let (sj, sk) = self.strides;
        if !j.is_multiple_of(sj) || !k.is_multiple_of(sk) {
            return None;
        }
        let (rows, per_row) = (THETA_D_RES / sj, PHI_D_RES / sk);
        match &self.placed {
            Some(p) => p[(i * rows + j / sj) * per_row + k / sk],
            None => self.place(i, j, k),
        }
    }

    /// Bin (i, j, k)'s directions refracted out of the coat, and their place on the grid.
    fn place(&self, i: usize, j: usize, k: usize) -> Option<Placed> {
        let (wi, wo) = bin_directions(i, j, k);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let (wi, wo) = (self.coat.refract_out(wi)?, self.coat.refract_out(wo)?);
        Some((wi, wo, GridPoint::of(wi, wo)))
    }
}

/// Where tan²θh / α_c² is below this the coat's lobe is subtracted on the grid (D_c above
/// 1/101² of its peak); elsewhere at the point.
const SHARP_LOBE: f64 = 100.0;

/// The coat's lobe w F D G2 / (4 cos θi cos θo) at the MERL grid's bins, as
/// [`CoatLayer::reflection`] gives it at [`bin_directions`], from tables: D per θh bin, F per θd
/// bin (the bin's half vector and θd are exact), and the azimuthal correlation λ(φ) per bin,
/// computed once for every candidate coat. The subtraction near the lobe's peak evaluates it at
/// 8 corners of most cells of every candidate's table: the acos of φ dominated the search.
struct LobeAtBins {
    weight: f64,
    alpha2: f64,
    d: [f64; THETA_H_RES],
    f: [f64; THETA_D_RES],
}

impl LobeAtBins {
    fn new(coat: &Coat) -> Self {
        let ndf = AnalyticNdf::isotropic(NdfKind::Ggx, coat.alpha);
        LobeAtBins {
            weight: coat.weight,
            alpha2: coat.alpha * coat.alpha,
            d: std::array::from_fn(|a| {
                let (s, c) = bin_angles(a, 0, 0).theta_h.sin_cos();
                ndf.d(DVec3::new(s, 0.0, c))
            }),
            f: std::array::from_fn(|b| dielectric(bin_angles(0, b, 0).theta_d.cos(), coat.eta)),
        }
    }

    /// The lobe at bin (a, b, c); 0 where a direction is below the horizon.
    fn at(&self, a: usize, b: usize, c: usize) -> f64 {
        let (wi, wo) = bin_directions(a, b, c);
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        // Λ of GGX at α² tan²θ = α² (x² + y²) / z²
        let lambda = |w: DVec3| {
            let a2t2 = (w.x * w.x + w.y * w.y) * self.alpha2 / (w.z * w.z);
            lambda_from_alpha_tan(NdfKind::Ggx, a2t2)
        };
        let g = g2(lambda(wi), lambda(wo), bin_correlation()[index(a, b, c)]);
        self.weight * self.f[b] * self.d[a] * g / (4.0 * wi.z * wo.z)
    }
}

/// λ(φ) of G2's correlation at every bin of the MERL grid, φ the azimuth between the bin's two
/// directions (11.7 MB, built on first use).
fn bin_correlation() -> &'static [f64] {
    static TABLE: OnceLock<Vec<f64>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..SAMPLES)
            .into_par_iter()
            .map(|n| {
                let (a, b, c) = bin_of(n);
                let (wi, wo) = bin_directions(a, b, c);
                correlation(azimuth_between(wi, wo))
            })
            .collect()
    })
}

impl<'a> SeenFromInside<'a> {
    /// `data` as a base under `layer` must be, at the bins `places` holds.
    fn new(data: &'a MerlTable, layer: &'a CoatLayer, places: &'a GridPlaces) -> Self {
        debug_assert_eq!(places.coat.eta, layer.coat.eta);
        let lobe = LobeAtBins::new(&layer.coat);
        SeenFromInside {
            data,
            layer,
            lobe,
            places,
        }
    }

    /// The base's value at bin (i, j, k): the data less the coat's lobe at the bin's outside
    /// pair, divided by T(θi) T(θo) / η², clamped at 0.
    fn at_bin(&self, i: usize, j: usize, k: usize) -> Option<Rgb> {
        let (wi, wo, at) = self.places.get(i, j, k)?;
        let t = self.layer.base_factor(wi, wo);
        Some(self.less_coat(wi, wo, &at)?.map(|v| (v / t).max(0.0)))
    }

    /// The data less the coat's lobe at outside directions (i, o), placed on the grid at `at`.
    /// Near the lobe's peak the lobe is subtracted at each grid sample before interpolating
    /// ([`MerlTable::interpolate_less`]): the grid's interpolation of a sharp lobe is off by
    /// far more than a base's values.
    fn less_coat(&self, i: DVec3, o: DVec3, at: &GridPoint) -> Option<Rgb> {
        let h = (i + o).normalize();
        let a2 = self.layer.coat.alpha * self.layer.coat.alpha;
        if (1.0 - h.z * h.z) / (h.z * h.z) > SHARP_LOBE * a2 {
            let r = self.layer.reflection(i, o);
            return Some(
                self.data
                    .interpolate_less(at, |_, _, _| 0.0)?
                    .map(|v| v - r),
            );
        }
        self.data
            .interpolate_less(at, |a, b, c| self.lobe.at(a, b, c))
    }
}

/// The base fitted under `layer` with `cfg`, on the bins `places` holds.
pub fn fit_base(
    src: &dyn Brdf,
    data: &MerlTable,
    layer: &CoatLayer,
    cfg: &FitConfig,
    places: &GridPlaces,
) -> Result<FittedMaterial, FitError> {
    let seen = SeenFromInside::new(data, layer, places);
    let name = format!("{}-base", src.name());
    let table = MerlTable::from_bins(|i, j, k| seen.at_bin(i, j, k));
    let under = MerlBrdf::from_table(&name, table).map_err(|problem| FitError::Extraction {
        name: name.clone(),
        problem: format!("under a coat {:?}: {problem}", layer.coat),
    })?;
    let cfg = FitConfig {
        coat: CoatSearch::Off,
        ..*cfg
    };
    crate::fitting::fit_layer(&under, &name, &cfg)
}

/// The coated model's error on `set`.
pub fn coated_error(layer: &CoatLayer, base: &MicrofacetBrdf, set: &GridSamples) -> f64 {
    error_metric(
        &Coated {
            layer: layer.clone(),
            base: base.clone(),
        },
        set,
    )
}

/// The search's candidates on one source: each coat's score is the coated model's error on
/// every 16th row of the source with a cheap base fit (infinite where the data
/// under the coat cannot be fitted), computed once per coat.
pub struct Scorer<'a> {
    src: &'a dyn Brdf,
    data: &'a MerlTable,
    cfg: FitConfig,
    set: GridSamples,
    places: GridPlaces,
    scored: Mutex<Vec<(Coat, f64)>>,
}

impl<'a> Scorer<'a> {
    /// The scorer of `src` (`data` its table, `full` its samples) under fits made with `cfg`.
    pub fn new(
        src: &'a dyn Brdf,
        data: &'a MerlTable,
        cfg: &FitConfig,
        full: &GridSamples,
    ) -> Self {
        let mut cheap = FitConfig {
            models: Models {
                tabulated: true,
                ggx: false,
                beckmann: false,
            },
            refine: false,
            ..*cfg
        };
        cheap.extract.resolution = SEARCH_RESOLUTION;
        Scorer {
            src,
            data,
            cfg: cheap,
            set: full.subsample(SEARCH_STRIDE),
            places: GridPlaces::placed(COAT_ETA, SEARCH_STRIDES),
            scored: Mutex::new(Vec::new()),
        }
    }

    /// The score of `coat`, from the scores kept when it was scored before: Brent's method
    /// starts each phase at a coat already scored.
    pub fn score(&self, coat: Coat) -> f64 {
        let known = |s: &[(Coat, f64)]| s.iter().find(|(c, _)| *c == coat).map(|&(_, e)| e);
        if let Some(e) = known(&self.scored.lock().expect("no panic holds it")) {
            return e;
        }
        let e = self.fit_and_score(coat);
        self.scored
            .lock()
            .expect("no panic holds it")
            .push((coat, e));
        e
    }

    fn fit_and_score(&self, coat: Coat) -> f64 {
        let Ok(layer) = CoatLayer::new(coat) else {
            return f64::INFINITY;
        };
        match fit_base(self.src, self.data, &layer, &self.cfg, &self.places) {
            Ok(base) => coated_error(&layer, &base.tabulated, &self.set),
            Err(_) => f64::INFINITY,
        }
    }
}

/// The coat that scores best: every coat of the coarse grid (α 0.012, 0.036, 0.11, 0.33 ×
/// weight 0.15, 0.5, 1) side by side; at each weight, from its best α, Brent's method in ln α
/// between that α's neighbours (at an α off the true one a lower weight hides the mismatch, so
/// each weight keeps its own α); then the best of those, and its weight by Brent's method.
pub fn search(scorer: &Scorer) -> Coat {
    let n = COARSE_WEIGHTS.len();
    let cells: Vec<Coat> = COARSE_ALPHAS
        .iter()
        .flat_map(|&a| COARSE_WEIGHTS.map(|w| Coat::new(COAT_ETA, a, w)))
        .collect();
    let scores: Vec<f64> = cells.par_iter().map(|&c| scorer.score(c)).collect();
    let refined: Vec<(f64, Coat)> = (0..n)
        .into_par_iter()
        .map(|w| {
            let a = (0..COARSE_ALPHAS.len())
                .min_by(|&x, &y| scores[x * n + w].total_cmp(&scores[y * n + w]))
                .expect("COARSE_ALPHAS is not empty");
            // Between the neighbours on the grid (past the ends, the range's ends).
            let lo = a.checked_sub(1).map_or(ALPHA_RANGE.0, |j| COARSE_ALPHAS[j]);
            let hi = COARSE_ALPHAS.get(a + 1).copied().unwrap_or(ALPHA_RANGE.1);
            let coat = by_alpha(scorer, cells[a * n + w], (lo, hi), 0.01);
            (scorer.score(coat), coat)
        })
        .collect();
    let coat = refined
        .into_iter()
        .min_by(|x, y| x.0.total_cmp(&y.0))
        .map(|(_, c)| c)
        .expect("COARSE_WEIGHTS is not empty");
    let weight = brent(
        |w| scorer.score(Coat { weight: w, ..coat }),
        0.0,
        coat.weight,
        1.0,
        0.01,
    );
    // α again within ±10 %, finer: a sharp coat's lobe left in the data by 1 % of α is a
    // spike the base's NDF takes up (the base's α moves about 3 % per 1 % of the coat's).
    let coat = Coat { weight, ..coat };
    by_alpha(scorer, coat, (coat.alpha / 1.1, coat.alpha * 1.1), 0.0004)
}

/// `coat` with its α by Brent's method in ln α on [lo, hi], to `tol` times |ln α| (0.01: about
/// 3 % of α at 0.05; 0.0004: about 0.1 %).
fn by_alpha(scorer: &Scorer, coat: Coat, (lo, hi): (f64, f64), tol: f64) -> Coat {
    let score = |x: f64| {
        scorer.score(Coat {
            alpha: x.exp(),
            ..coat
        })
    };
    let alpha = brent(score, lo.ln(), coat.alpha.ln(), hi.ln(), tol).exp();
    Coat { alpha, ..coat }
}

/// The coat step of a fit: the coat found by [`search`] on `data` (the source's MERL-grid
/// table), its base fitted in full and its look; `None` where the base cannot be fitted.
/// Whether the fit keeps it is [`CoatCandidate::keeps`].
pub fn fit_coat(
    src: &dyn Brdf,
    data: &MerlTable,
    cfg: &FitConfig,
    full: &GridSamples,
) -> Result<Option<CoatCandidate>, FitError> {
    let coat = search(&Scorer::new(src, data, cfg, full));
    let layer = CoatLayer::new(coat).map_err(|problem| FitError::Extraction {
        name: src.name().into(),
        problem,
    })?;
    let places = GridPlaces::on_demand(coat.eta);
    let Ok(base) = fit_base(src, data, &layer, cfg, &places) else {
        return Ok(None);
    };
    let coated = Coated {
        layer,
        base: base.tabulated.clone(),
    };
    let look = SphereScene::REPORT.delta_e_to_table(data, &coated);
    Ok(Some(CoatCandidate {
        models: CoatedModels {
            layer: coated.layer,
            base,
        },
        look,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tabulated lobe is [`CoatLayer::reflection`] at the bins' directions, to rounding
    /// (relative 1e-12: D and F from the bins' exact angles, not from the normalised sum of
    /// the two directions), for a sharp and a rough coat at grazing, backscattering and
    /// forward bins, and 0 where a direction is below the horizon.
    #[test]
    fn the_lobe_at_bins_is_the_layers_reflection() {
        for coat in [Coat::new(1.5, 0.004, 0.3), Coat::new(1.5, 0.4, 1.0)] {
            let (layer, bins) = (CoatLayer::new(coat).unwrap(), LobeAtBins::new(&coat));
            let (mut checked, mut below) = (0, 0);
            for a in (0..THETA_H_RES).step_by(7).chain([THETA_H_RES - 1]) {
                for b in (0..THETA_D_RES).step_by(11).chain([THETA_D_RES - 1]) {
                    for c in (0..PHI_D_RES).step_by(13).chain([PHI_D_RES - 1]) {
                        let (wi, wo) = bin_directions(a, b, c);
                        let (got, want) = (bins.at(a, b, c), layer.reflection(wi, wo));
                        assert!(
                            (got - want).abs() <= 1e-12 * want.abs(),
                            "{coat:?} at bin ({a}, {b}, {c}): {got} against {want}"
                        );
                        checked += 1;
                        below += usize::from(wi.z <= 0.0 || wo.z <= 0.0);
                    }
                }
            }
            assert!(below > 0 && below < checked, "{below} of {checked} below");
        }
    }
}
