//! The grids a fit reads, built once from the source's samples on the MERL grid: the full grid
//! of the reported errors, the final steps' rows, the searches' rows and their coarse (every
//! fourth φd bin) versions.

use super::{FINAL_STRIDE, FitConfig};
use crate::error::FitError;
use crate::metric::grid::{CoarseGrid, GridSamples};
use crate::metric::iso_tables::MAX_X;
use crate::model::brdf::Brdf;
use crate::model::merl_grid::{MIN_VALID_SAMPLES, MerlTable};
use std::borrow::Cow;

/// Every grid of one fit.
pub(super) struct Grids<'a> {
    /// An isotropic source's MERL-grid table, sampled once (a neural proxy's costs about as
    /// much as the fit): the grid in the other metric is built from it too.
    pub table: Option<Cow<'a, MerlTable>>,
    /// Every valid sample: the reported errors and the Fresnel average.
    pub full: GridSamples,
    /// The final steps' rows: with a diffuse lobe about a quarter of the rows
    /// ([`GridSamples::diagonal`]), the full grid without.
    pub final_steps: GridSamples,
    /// Every fourth φd bin of the final steps' rows ([`GridSamples::coarse`]): the analytic
    /// fits' α bracket runs on them, and with a diffuse lobe every model's F / ρd solve and the
    /// tabulated NDF's refinement. `None` when neither needs them.
    pub coarse: Option<CoarseGrid>,
    /// The least-squares searches' rows ([`FitConfig::search_stride`]).
    pub search: GridSamples,
    /// An isotropic fit's α search on every fourth φd bin of the searches' rows.
    pub coarse_search: Option<CoarseGrid>,
    /// Whether every model carries a diffuse lobe: asked for, and the source isotropic.
    pub diffuse: bool,
}

impl<'a> Grids<'a> {
    /// The grids of `src`, or an error naming it when it has no valid sample or a value the
    /// passes cannot sum.
    pub fn new(src: &'a dyn Brdf, cfg: &FitConfig) -> Result<Self, FitError> {
        let table = src.is_isotropic().then(|| src.merl_table());
        let full = match &table {
            Some(t) => GridSamples::from_table(t, cfg.metric),
            None => GridSamples::for_metric(src, cfg.metric),
        };
        check(src, &full)?;
        // The diffuse lobe is solved on the isotropic grid, on the CPU.
        let diffuse = cfg.diffuse && !cfg.anisotropic && full.iso.is_some();
        // (A sparse source may hold no sample on the quarter: then the full grid.)
        let final_steps = match diffuse.then(|| full.diagonal(FINAL_STRIDE)) {
            Some(rows) if !rows.is_empty() => rows,
            _ => full.subsample(1),
        };
        let analytic = cfg.models.ggx || cfg.models.beckmann;
        let coarse = (analytic || diffuse)
            .then(|| final_steps.coarse())
            .flatten();
        let search = full.subsample(cfg.search_stride);
        let coarse_search = (analytic && !cfg.anisotropic)
            .then(|| search.coarse())
            .flatten();
        Ok(Grids {
            table,
            full,
            final_steps,
            coarse,
            search,
            coarse_search,
            diffuse,
        })
    }
}

/// A set the passes can use: at least [`MIN_VALID_SAMPLES`], every x = f_r cos θi finite and
/// within ±[`MAX_X`].
fn check(src: &dyn Brdf, set: &GridSamples) -> Result<(), FitError> {
    if set.len() < MIN_VALID_SAMPLES {
        return Err(FitError::Extraction {
            name: src.name().into(),
            problem: format!(
                "{} valid samples on the MERL grid; a fit needs at least {MIN_VALID_SAMPLES}",
                set.len()
            ),
        });
    }
    if let Some(s) = set.out_of_range() {
        let (i, j, max) = (s.i, s.j, MAX_X);
        return Err(FitError::Extraction {
            name: src.name().into(),
            problem: format!(
                "f_r cos θi = {:?} at θh bin {i}, θd bin {j} is outside ±{max:e}",
                s.x
            ),
        });
    }
    Ok(())
}
