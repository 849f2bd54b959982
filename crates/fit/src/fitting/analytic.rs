//! GGX and Beckmann fitted to the source: α by slope moments (the paper's estimate, reported
//! for comparison) and by least squares in the metric's space, searched on coarse rows and
//! bracketed, then solved and measured on the full grid (coarse to fine).

use super::solve::Solved;
use super::{Fit, SingleLobe};
use crate::error::FitError;
use crate::extract::Extraction;
use crate::fitting::params::{
    candidates_of, fit_least_squares, fit_moments, least_squares_candidates, refine_by_bracket,
};
use crate::metric::grid::GridModel;
use crate::model::fresnel::FresnelTable;
use crate::model::material::{ParamRecord, Params};
use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};

/// The analytic model of `ndf` with F = 1 and no diffuse term, as the searches take it.
fn ideal(ndf: AnalyticNdf) -> MicrofacetBrdf {
    MicrofacetBrdf::ideal("lsq", Ndf::Analytic(ndf))
}

impl Fit<'_> {
    /// The GGX and Beckmann fits asked for, side by side: their searches' passes are short (a
    /// few hundred rows) and their steps between passes serial, which one fit alone leaves
    /// the second core idle for.
    pub(super) fn analytic_fits(
        &self,
        ex: &Extraction,
        single: Option<&SingleLobe>,
    ) -> Result<(Option<ParamRecord>, Option<ParamRecord>), FitError> {
        let models = self.cfg.models;
        let fit = |on: bool, kind| on.then(|| self.fit_analytic(kind, ex, single)).transpose();
        let (ggx, beckmann) = rayon::join(
            || fit(models.ggx, NdfKind::Ggx),
            || fit(models.beckmann, NdfKind::Beckmann),
        );
        Ok((ggx?, beckmann?))
    }

    /// One family fitted: α by least squares with F (and ρd) solved for it, α by moments with
    /// its error, and the physical Fresnel curves of the least-squares model.
    fn fit_analytic(
        &self,
        kind: NdfKind,
        ex: &Extraction,
        single: Option<&SingleLobe>,
    ) -> Result<ParamRecord, FitError> {
        let moments = fit_moments(kind, &ex.ndf);
        let (lsq, (lsq_fresnel, lsq_diffuse, error)) = if self.cfg.anisotropic {
            let lsq = fit_least_squares(moments, true, self.diffuse, &self.grids.search);
            (lsq, self.solve(&GridModel::new(ideal(lsq)))?)
        } else {
            self.isotropic_least_squares(kind, moments)?
        };
        let params = |n: &AnalyticNdf, e| Params {
            alpha_x: n.alpha_x,
            alpha_y: n.alpha_y,
            rotation: n.rotation,
            error: e,
        };
        let fresnel = FresnelTable::on_merl_bins(lsq_fresnel);
        Ok(ParamRecord {
            alpha_x: lsq.alpha_x,
            alpha_y: lsq.alpha_y,
            rotation: lsq.rotation,
            error,
            method: "least_squares".into(),
            moments: params(&moments, self.moments_error(moments, single)?),
            fresnel_fits: self.physical(&ideal(lsq), &fresnel, lsq_diffuse),
            fresnel,
            diffuse: lsq_diffuse,
        })
    }

    /// An isotropic α: the search's candidates compete on the coarse search rows, the bracket
    /// runs on the final steps' coarse rows with F (and ρd) averaged there (plain weighted
    /// least squares), and the α found is solved again on the full grid.
    fn isotropic_least_squares(
        &self,
        kind: NdfKind,
        moments: AnalyticNdf,
    ) -> Result<(AnalyticNdf, Solved), FitError> {
        let diffuse = self.diffuse;
        let starts: Vec<f64> = match &self.grids.coarse_search {
            // (`error` is `None` only for an anisotropic model.)
            Some(rows) => candidates_of(moments, |n| {
                rows.error(&ideal(n), diffuse).unwrap_or(f64::INFINITY)
            }),
            None => least_squares_candidates(moments, diffuse, &self.grids.search),
        }
        .iter()
        .map(|n| n.alpha_x.ln())
        .collect();
        let (t, e, solved) = refine_by_bracket(&starts, |t| {
            let m = GridModel::new(ideal(AnalyticNdf::isotropic(kind, t.exp())));
            match (&self.grids.coarse, &m.tables) {
                (Some(b), Some(tables)) => {
                    Ok::<_, FitError>((b.tables_error(tables, diffuse), None))
                }
                _ => self.solve(&m).map(|(f, kd, e)| (e, Some((f, kd)))),
            }
        })?;
        let ndf = AnalyticNdf::isotropic(kind, t.exp());
        Ok(match solved {
            Some((f, kd)) => (ndf, (f, kd, e)),
            None => (ndf, self.solve_reported(&GridModel::new(ideal(ndf)))?),
        })
    }

    /// The paper's estimate, α by moments: with the Fresnel of the extraction; with a diffuse
    /// lobe, with F and ρd solved for it and its error on the final steps' rows (a quarter of
    /// the grid; on the 100 MERL proxies within 0.6 % of the full grid's, median 0.04 %), as
    /// the physical curves' errors are: a comparison figure, which took a fifth of the
    /// analytic fits' time on the full grid.
    fn moments_error(
        &self,
        moments: AnalyticNdf,
        single: Option<&SingleLobe>,
    ) -> Result<f64, FitError> {
        let m = GridModel::new(ideal(moments));
        match single {
            Some((f, _)) => self.full_error(&m.with_fresnel(f, m.model.diffuse)),
            None => Ok(self.solve_for(&m, Some(&self.grids.final_steps))?.2),
        }
    }
}
