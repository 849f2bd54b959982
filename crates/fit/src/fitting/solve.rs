//! The questions every step of a fit asks of a model: F (and with a diffuse lobe ρd) solved
//! for its D and G, and its error on a grid; the physical Fresnel curves fitted to its table.

use super::{FINAL_IRLS, Fit};
use crate::error::FitError;
use crate::fitting::fresnel_fit::FitFresnelCurves;
use crate::metric::grid::{GridModel, GridSamples, microfacet_errors};
use crate::model::fresnel::FresnelTable;
use crate::model::fresnel_curves::FresnelFits;
use crate::model::microfacet::MicrofacetBrdf;
use crate::model::rgb::Rgb;

/// F per θd bin, the diffuse albedo ρd and the model's error with them.
pub(super) type Solved = (Vec<Rgb>, Rgb, f64);

impl Fit<'_> {
    /// F per θd bin averaged over the full grid for `m`'s D and G (on the fit's backend).
    pub(super) fn average(&self, m: &GridModel) -> Result<Vec<Rgb>, FitError> {
        self.eval.average(m, &self.grids.full, self.src.name())
    }

    /// `m`'s error on the full grid (on the fit's backend).
    pub(super) fn full_error(&self, m: &GridModel) -> Result<f64, FitError> {
        self.eval.error(m, &self.grids.full, self.src.name())
    }

    /// F (and with a diffuse lobe ρd) for `m`'s own D and G, and its error, on the full grid.
    pub(super) fn solve(&self, m: &GridModel) -> Result<Solved, FitError> {
        let full = &self.grids.full;
        if self.diffuse
            && let Some(r) = m.fresnel_diffuse_and_error(full, FINAL_IRLS)
        {
            return Ok(r);
        }
        if self.eval.is_gpu() {
            let f = self.average(m)?;
            let error = self.full_error(&m.with_fresnel(&f, m.model.diffuse))?;
            return Ok((f, [0.0; 3], error));
        }
        let (f, e) = m.fresnel_and_error(full);
        Ok((f, [0.0; 3], e))
    }

    /// `m`'s F and ρd, and its error on `rows` (the full grid where `None`): with a diffuse
    /// lobe F and ρd solved on the coarse rows (`FINAL_IRLS` reweighted steps), without one
    /// averaged over the grid (and the error on the grid).
    pub(super) fn solve_for(
        &self,
        m: &GridModel,
        rows: Option<&GridSamples>,
    ) -> Result<Solved, FitError> {
        let on_coarse = match (&self.grids.coarse, &m.tables) {
            (Some(c), Some(t)) if self.diffuse => {
                Some(c.tables_fresnel_diffuse_and_error(t, FINAL_IRLS))
            }
            _ => None,
        };
        let Some((f, kd, _)) = on_coarse else {
            return self.solve(m);
        };
        let with = m.with_fresnel(&f, kd);
        let e = match rows {
            Some(rows) => with.error(rows),
            None => self.full_error(&with)?,
        };
        Ok((f, kd, e))
    }

    /// [`Fit::solve_for`] with the error on the full grid: what a reported model gets.
    pub(super) fn solve_reported(&self, m: &GridModel) -> Result<Solved, FitError> {
        self.solve_for(m, None)
    }

    /// With a diffuse lobe, the physical Fresnel curves fitted to a model's table, each with
    /// its error on the final steps' rows: one pass over a quarter of the grid for the three,
    /// which on the 100 MERL proxies came within 0.85 % of the full grid's (the sixteenth:
    /// 1.33 %).
    pub(super) fn physical(
        &self,
        m: &MicrofacetBrdf,
        table: &FresnelTable,
        albedo: Rgb,
    ) -> Option<FresnelFits> {
        self.diffuse.then(|| {
            let with = MicrofacetBrdf {
                diffuse: albedo,
                ..m.clone()
            };
            let mut fits = FresnelFits::of(table, |curves| {
                let e = microfacet_errors(&with, curves, &self.grids.final_steps);
                std::array::from_fn(|n| e[n])
            });
            fits.used = self.cfg.fresnel;
            fits
        })
    }
}
