//! The tabulated model: the extracted NDF with the paper's single lobe (F averaged), or with a
//! diffuse lobe separated from it and the NDF refined in the metric's space, started from the
//! extraction and, where an analytic fit is still better, from that fit's NDF tabulated.

use super::{Fit, SingleLobe};
use crate::error::FitError;
use crate::extract::Extraction;
use crate::fitting::diffuse::{separate, tabulated_model};
use crate::fitting::refine::{Refinement, model_of, tabulate};
use crate::metric::grid::{CoarseGrid, GridModel};
use crate::model::material::ParamRecord;
use crate::model::microfacet::{AnalyticNdf, NdfKind};
use crate::model::rgb::Rgb;
use crate::model::tabulated::TabulatedNdf;

/// A tabulated candidate: its NDF, F per θd bin and ρd.
type Candidate = (TabulatedNdf, Vec<Rgb>, Rgb);

/// The tabulated model as the fit chose it.
pub(super) struct TabulatedFit {
    /// The extraction it came from (the diffuse lobe's, when one was separated).
    pub extraction: Extraction,
    /// The NDF.
    pub ndf: TabulatedNdf,
    /// F per θd bin.
    pub fresnel: Vec<Rgb>,
    /// ρd.
    pub diffuse: Rgb,
    /// Its error on the full grid (`None` when the tabulated model was not asked for).
    pub error: Option<f64>,
    /// Where the NDF came from: `power_iteration`, or the analytic family it was tabulated
    /// from.
    pub origin: &'static str,
    /// Extractions run to separate the diffuse lobe (1 without one).
    pub separation_rounds: usize,
    /// Rounds of the refinement.
    pub refine_rounds: usize,
}

impl Fit<'_> {
    /// The paper's single lobe: F averaged for the extraction's D and G; on the CPU the
    /// tabulated model's error shares G2 with the average.
    pub(super) fn single_lobe_fresnel(&self, ex: &Extraction) -> Result<SingleLobe, FitError> {
        let model = GridModel::new(tabulated_model(ex));
        Ok(if !self.eval.is_gpu() && self.cfg.models.tabulated {
            let (f, e) = model.fresnel_and_error(&self.grids.full);
            (f, Some(e))
        } else {
            (self.average(&model)?, None)
        })
    }

    /// The single lobe's tabulated model: the extracted NDF with its averaged F, its error
    /// measured now where the average did not give it.
    pub(super) fn single_lobe_tabulated(
        &self,
        ex: Extraction,
        (f, e): SingleLobe,
    ) -> Result<TabulatedFit, FitError> {
        let error = match e {
            Some(e) => Some(e),
            None if self.cfg.models.tabulated => {
                let m = GridModel::new(tabulated_model(&ex));
                Some(self.full_error(&m.with_fresnel(&f, m.model.diffuse))?)
            }
            None => None,
        };
        Ok(TabulatedFit {
            ndf: ex.ndf.clone(),
            extraction: ex,
            fresnel: f,
            diffuse: [0.0; 3],
            error,
            origin: "power_iteration",
            separation_rounds: 1,
            refine_rounds: 0,
        })
    }

    /// With a diffuse lobe: ρd separated from the extraction ([`separate`]), the NDF refined
    /// on the coarse rows, and the best analytic fit's NDF tabulated as a second start where
    /// that fit is still better.
    pub(super) fn diffuse_tabulated(
        &self,
        ex: Extraction,
        best_analytic: Option<(NdfKind, &ParamRecord)>,
    ) -> Result<TabulatedFit, FitError> {
        let cfg = self.cfg;
        let sep = separate(self.src, &self.grids.search, ex, |b| {
            self.eval.extract(b, &cfg.extract, false)
        })?;
        let ex = sep.extraction;
        let (mut best, mut error, mut refine_rounds) = self.candidate(&ex.ndf)?;
        let mut origin = "power_iteration";
        if let Some((kind, p)) = best_analytic.filter(|(_, p)| cfg.refine && p.error < error) {
            let t = ex.ndf.tables();
            if let Some(ndf) = tabulate(AnalyticNdf::isotropic(kind, p.alpha_x), t.nu, t.ng) {
                let (c, e, rounds) = self.candidate(&ndf)?;
                refine_rounds += rounds;
                if e < error {
                    (best, error, origin) = (c, e, kind.name());
                }
            }
        }
        let (ndf, fresnel, diffuse) = best;
        Ok(TabulatedFit {
            extraction: ex,
            ndf,
            fresnel,
            diffuse,
            error: Some(error),
            origin,
            separation_rounds: sep.rounds,
            refine_rounds,
        })
    }

    /// A tabulated NDF refined on the coarse rows from F and ρd solved there
    /// ([`Refinement::start`], which shares the NDF's G2 / (4 cos θo) and plain sums with the
    /// rounds), or unrefined and solved as any model ([`Fit::solve_reported`]); its error on
    /// the full grid, and the refinement's rounds.
    fn candidate(&self, ndf: &TabulatedNdf) -> Result<(Candidate, f64, usize), FitError> {
        let rows = self
            .grids
            .coarse
            .as_ref()
            .filter(|_| self.cfg.refine)
            .map(CoarseGrid::rows);
        let Some(r) = rows.and_then(|rows| Refinement::new(ndf, rows)) else {
            let (f, kd, error) = self.solve_reported(&GridModel::new(model_of(ndf)))?;
            return Ok(((ndf.clone(), f, kd), error, 0));
        };
        let start = r.start();
        let (c, rounds) = match r.run(&start) {
            Some(r) => ((r.ndf, r.fresnel, r.albedo), r.rounds),
            None => ((ndf.clone(), start.0, start.1), 0),
        };
        let m = GridModel::new(model_of(&c.0)).with_fresnel(&c.1, c.2);
        let error = self.full_error(&m)?;
        Ok((c, error, rounds))
    }
}
