//! The whole fit of one source: extraction, G1, Fresnel, parameter fits and errors.
//!
//! [`fit_material`] runs the steps in order, each a named function: the power iteration on the
//! backscattering slice, the grids every later step reads (`grids.rs`), the single lobe's
//! Fresnel average, the analytic fits (`analytic.rs`), the tabulated model with the diffuse
//! lobe separated and the NDF refined (`tabulated.rs`), the physical Fresnel curves
//! ([`fresnel_fit`]) and the record. Every step asks the same few questions of a model — F
//! and ρd solved for its D and G, its error on a grid — which `solve.rs` answers, on the
//! backend of the fit (`evaluator.rs`: the CPU, or a GPU with the source's samples uploaded).

mod analytic;
pub mod coat;
pub mod diffuse;
mod evaluator;
pub mod fresnel_fit;
mod grids;
pub(crate) mod optim;
pub mod params;
pub(crate) mod refine;
mod solve;
mod tabulated;

use crate::error::FitError;
use crate::extract::ExtractConfig;
#[cfg(feature = "gpu")]
pub use crate::fitting::evaluator::Backend;
use crate::fitting::evaluator::Evaluator;
use crate::fitting::grids::Grids;
use crate::fitting::refine::model_of;
use crate::fitting::tabulated::TabulatedFit;
use crate::metric::Metric;
use crate::metric::grid::{GridSamples, microfacet_error};
use crate::metric::look::SphereScene;
use crate::model::brdf::Brdf;
use crate::model::fresnel::FresnelTable;
use crate::model::fresnel_curves::FresnelChoice;
use crate::model::material::{
    FitRecord, FittedMaterial, LookRecord, MetricErrors, ParamRecord, TabulatedRecord, Timings,
};
use crate::model::microfacet::MicrofacetBrdf;
use crate::model::microfacet::NdfKind;
use crate::model::rgb::Rgb;
use std::sync::Arc;
use std::time::Instant;

/// Which models to fit and report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Models {
    /// Report the tabulated model's error.
    pub tabulated: bool,
    /// Fit GGX.
    pub ggx: bool,
    /// Fit Beckmann.
    pub beckmann: bool,
}

impl Models {
    /// Extraction, G1 and Fresnel only: the scope of the paper's code.
    pub const NONE: Models = Models {
        tabulated: false,
        ggx: false,
        beckmann: false,
    };
    /// The tabulated model, GGX and Beckmann.
    pub const ALL: Models = Models {
        tabulated: true,
        ggx: true,
        beckmann: true,
    };
}

/// Fit settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitConfig {
    /// The power iteration's settings.
    pub extract: ExtractConfig,
    /// Extract on a (θ, φ) grid and fit αx, αy and rotation.
    pub anisotropic: bool,
    /// Which models to fit and report.
    pub models: Models,
    /// The least-squares searches run on a subsampled grid
    /// ([`GridSamples::subsample`](crate::metric::grid::GridSamples::subsample): every
    /// `search_stride`-th (θh, θd) row of an isotropic source, an isotropic fit's α search on
    /// every fourth φd bin of those rows; every `search_stride`-th sample of an anisotropic
    /// one); an isotropic fit then brackets α ([`crate::fitting::params::refine_by_bracket`]) on
    /// every fourth φd bin of the final steps' rows (the full grid, or with a diffuse lobe a
    /// quarter of it) and solves F for the α found: averaged over the full grid, or with a
    /// diffuse lobe solved with ρd on the bracket's rows. The reported errors use every sample.
    pub search_stride: usize,
    /// Fit a Lambertian lobe ρd with every model and keep F in [0, 1] ([`crate::fitting::diffuse`]);
    /// false: the paper's single specular lobe with F averaged. Isotropic fits only: an
    /// anisotropic fit always takes the single lobe.
    pub diffuse: bool,
    /// Refine the tabulated NDF in the metric's space after the extraction (`refine.rs`),
    /// and tabulate the best analytic fit's NDF when it fits better (diffuse fits only).
    pub refine: bool,
    /// The Fresnel each model renders with: its table, or the conductor, dielectric or Schlick
    /// curve fitted to it ([`crate::fitting::fresnel_fit`]; diffuse fits only, where F lies in [0, 1]).
    pub fresnel: FresnelChoice,
    /// When to search a clear coat over a base ([`coat`]), kept where the coated model fits
    /// better (diffuse fits only).
    pub coat: CoatSearch,
    /// The objective every step minimises ([`Metric`]).
    pub metric: Metric,
}

/// When a fit searches a clear coat over a base ([`coat`]); wherever it is searched, it is
/// kept where it makes the look better ([`coat::CoatCandidate::keeps`]). A search costs about
/// 40 cheap fits of the base (2–4 s on 2 cores), so by default it runs only where the
/// single layer looks off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoatSearch {
    /// Never: the single layer alone (`--coat off`).
    Off,
    /// Where the single layer's look ([`LookRecord`]) is above [`coat::TRY_ABOVE`] ΔE2000
    /// (`--coat auto`, the default).
    Auto,
    /// On every fit with a diffuse lobe (`--coat always`).
    Always,
}

impl FitConfig {
    /// Isotropic extraction ([`ExtractConfig::isotropic`]), every model.
    pub const fn isotropic() -> Self {
        FitConfig {
            extract: ExtractConfig::isotropic(),
            anisotropic: false,
            models: Models::ALL,
            search_stride: 48,
            diffuse: true,
            refine: true,
            fresnel: FresnelChoice::Table,
            coat: CoatSearch::Auto,
            metric: Metric::Perceptual,
        }
    }

    /// [`FitConfig::isotropic`] without the coat: the single layer alone (`--no-coat`), as the
    /// fit that samples a measured material takes it.
    pub const SINGLE_LAYER: FitConfig = FitConfig {
        coat: CoatSearch::Off,
        ..Self::isotropic()
    };

    /// The paper's pipeline: isotropic, one specular lobe, F averaged, no refinement, the
    /// paper's metric.
    pub const fn single_lobe() -> Self {
        FitConfig {
            diffuse: false,
            refine: false,
            coat: CoatSearch::Off,
            metric: Metric::Log,
            ..Self::isotropic()
        }
    }

    /// Anisotropic extraction ([`ExtractConfig::anisotropic`]), every model, the paper's single
    /// lobe in the paper's metric (the perceptual one was measured on isotropic data only).
    pub const fn anisotropic() -> Self {
        FitConfig {
            extract: ExtractConfig::anisotropic(),
            anisotropic: true,
            models: Models::ALL,
            search_stride: 64,
            diffuse: false,
            refine: false,
            fresnel: FresnelChoice::Table,
            coat: CoatSearch::Off,
            metric: Metric::Log,
        }
    }
}

impl Default for FitConfig {
    fn default() -> Self {
        Self::isotropic()
    }
}

/// Reweighted steps of the F / ρd solves of the final steps (the searches take none).
const FINAL_IRLS: usize = 2;
// The analytic fits' α search runs on every fourth φd bin of the search's rows, the bracket on
// every fourth φd bin of the final steps' rows (`GridSamples::coarse`), with a diffuse lobe
// without reweighted steps; the α found is then solved with `FINAL_IRLS` steps. (On the 100
// proxies plain steps gave the same medians as reweighted ones at 0.9× the time. The coarse
// bracket gave the same medians and 90th percentiles in both pipelines; 399 of the 400
// analytic fits within 0.2 %, polyethylene's GGX 3 % worse, its plain error being flat and
// bumpy in α. Every fourth row instead, a diagonal of stride 16, made sharp lobes' fits up to
// 2.9 times worse. The coarse search: the diffuse pipeline's 300 fits unchanged to the digits
// printed, the single lobe's medians too, 4 Beckmann fits better (at most 3.4 %) and 4 worse
// (at most 4.2 %).)
/// The rows of the final steps with a diffuse lobe: about one in 4 ([`GridSamples::diagonal`],
/// which keeps every θh and θd bin). F and ρd of every reported model are solved on their every
/// fourth φd bin, a sixteenth of the grid, and its reported error is measured on the full grid;
/// the physical Fresnel curves' errors are measured on these rows. (On the 100 proxies, the
/// solves on the sixteenth against the quarter: 14 of the 200 analytic fits' errors moved, by
/// at most 0.15 %.)
const FINAL_STRIDE: usize = 4;

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Fits one source on the CPU. `source` describes where it came from (recorded in the JSON).
pub fn fit_material(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
) -> Result<FittedMaterial, FitError> {
    fit_with(src, source, cfg, Evaluator::Cpu)
}

/// Fits one source on a backend. A GPU failure falls back to the CPU, and the record says so
/// (`fallback`, and in words `backend`): the answer is never silently different. (With the
/// `gpu` feature only.)
#[cfg(feature = "gpu")]
pub fn fit_material_on(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
    backend: Backend,
) -> Result<FittedMaterial, FitError> {
    match fit_with(src, source, cfg, Evaluator::new(backend)) {
        Err(e @ FitError::Gpu { .. }) => {
            let mut m = fit_with(src, source, cfg, Evaluator::Cpu)?;
            m.record.backend = format!("cpu (fallback after a GPU failure: {e})");
            m.record.fallback = Some(e.to_string());
            Ok(m)
        }
        other => other,
    }
}

/// One fit in progress: the source, its settings, where the passes over the whole grid run,
/// and the grids every step reads. The steps are its methods (`solve.rs`, `analytic.rs`,
/// `tabulated.rs`).
struct Fit<'a> {
    src: &'a dyn Brdf,
    cfg: &'a FitConfig,
    eval: Evaluator<'a>,
    grids: Grids<'a>,
    /// Every model carries a diffuse lobe (isotropic sources only, solved on the CPU).
    diffuse: bool,
}

/// The paper's single lobe: F averaged for the extraction's D and G, and the tabulated model's
/// error when it came with the average.
type SingleLobe = (Vec<Rgb>, Option<f64>);

/// The pipeline: the single layer, its errors in the other metric and its look, then the
/// coat where the settings ask for one.
fn fit_with(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
    eval: Evaluator,
) -> Result<FittedMaterial, FitError> {
    let start = Instant::now();
    let (fit, mut material) = Fit::single_layer(src, source, cfg, eval, start)?;
    let other = match &fit.grids.table {
        Some(t) => GridSamples::from_table(t, cfg.metric.other()),
        None => GridSamples::for_metric(src, cfg.metric.other()),
    };
    material.record.other_metric = Some(errors_in(&material, &other, cfg.metric.other()));
    material.record.look = fit.grids.table.as_deref().map(|t| LookRecord {
        tabulated: SphereScene::REPORT.delta_e_to_table(t, &material.tabulated),
        coated: None,
    });
    let mut material = fit.with_coat(material, start)?;
    if let (Some(c), Some(e)) = (&material.coated, &mut material.record.other_metric) {
        e.coated = Some(coat::coated_error(&c.layer, &c.base.tabulated, &other));
    }
    material.record.timings_ms.total = ms(start);
    Ok(material)
}

/// The single layer alone, on the CPU, without its errors in the other metric or its look:
/// the coat step's fits of the base.
pub(crate) fn fit_layer(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
) -> Result<FittedMaterial, FitError> {
    Fit::single_layer(src, source, cfg, Evaluator::Cpu, Instant::now()).map(|(_, m)| m)
}

/// The single layer's models' errors on `set` (in its metric): recorded beside the errors in
/// the metric the fit minimised.
fn errors_in(m: &FittedMaterial, set: &GridSamples, metric: Metric) -> MetricErrors {
    let error = |model: &MicrofacetBrdf| microfacet_error(model, set);
    MetricErrors {
        metric,
        tabulated: m.record.tabulated.error.map(|_| error(&m.tabulated)),
        ggx: m.ggx.as_ref().map(error),
        beckmann: m.beckmann.as_ref().map(error),
        coated: None,
    }
}

/// The analytic fit with the lowest error: the refinement's other start.
fn best_analytic<'p>(
    ggx: &'p Option<ParamRecord>,
    beckmann: &'p Option<ParamRecord>,
) -> Option<(NdfKind, &'p ParamRecord)> {
    [(NdfKind::Ggx, ggx), (NdfKind::Beckmann, beckmann)]
        .into_iter()
        .filter_map(|(k, p)| p.as_ref().map(|p| (k, p)))
        .min_by(|a, b| a.1.error.total_cmp(&b.1.error))
}

impl<'a> Fit<'a> {
    /// The steps of the single layer, in the order they run: the power iteration, the grids,
    /// the single lobe's Fresnel average, the analytic fits, the tabulated model and the
    /// record; the fit (its grids) returned beside it for the steps after.
    fn single_layer(
        src: &'a dyn Brdf,
        source: &str,
        cfg: &'a FitConfig,
        mut eval: Evaluator<'a>,
        start: Instant,
    ) -> Result<(Self, FittedMaterial), FitError> {
        let ex = eval.extract(src, &cfg.extract, cfg.anisotropic)?;
        let extract_ms = ms(start);

        let t = Instant::now();
        let grids = Grids::new(src, cfg)?;
        eval.upload(&grids.full, src.name())?;
        let diffuse = grids.diffuse;
        let fit = Fit {
            src,
            cfg,
            eval,
            grids,
            diffuse,
        };
        let single = (!diffuse)
            .then(|| fit.single_lobe_fresnel(&ex))
            .transpose()?;
        let mut fresnel_ms = ms(t);

        let t = Instant::now();
        let (ggx, beckmann) = fit.analytic_fits(&ex, single.as_ref())?;
        let fit_ms = ms(t);

        let t = Instant::now();
        let tab = match single {
            Some(single) => fit.single_lobe_tabulated(ex, single)?,
            None => fit.diffuse_tabulated(ex, best_analytic(&ggx, &beckmann))?,
        };
        fresnel_ms += ms(t);
        let timings = Timings {
            load: 0.0,
            extract: extract_ms,
            fresnel: fresnel_ms,
            fit: fit_ms,
            coat: 0.0,
            total: 0.0,
        };
        let material = fit.material(source, tab, ggx, beckmann, timings, start)?;
        Ok((fit, material))
    }
}

impl Fit<'_> {
    /// The coat step ([`coat`]) where the settings ask for it (`auto`: where the single
    /// layer's look is above [`coat::TRY_ABOVE`]): the material with the coat attached when it
    /// looks better ([`coat::CoatCandidate::keeps`]); the coated look recorded either way.
    fn with_coat(&self, mut m: FittedMaterial, start: Instant) -> Result<FittedMaterial, FitError> {
        let data = self.grids.table.as_deref().filter(|_| self.diffuse);
        let (Some(data), Some(look)) = (data, m.record.look) else {
            return Ok(m);
        };
        let wanted = match self.cfg.coat {
            CoatSearch::Off => false,
            CoatSearch::Auto => look.tabulated > coat::TRY_ABOVE,
            CoatSearch::Always => true,
        };
        if !wanted {
            return Ok(m);
        }
        let t = Instant::now();
        if let Some(found) = coat::fit_coat(self.src, data, self.cfg, &self.grids.full)? {
            m.record.look = Some(LookRecord {
                coated: Some(found.look),
                ..look
            });
            if found.keeps(look.tabulated) {
                let coated = found.kept(&self.grids.full);
                m.record.coat = Some(coated.record());
                m.coated = Some(Box::new(coated.models));
            }
        }
        m.record.timings_ms.coat = ms(t);
        m.record.timings_ms.total = ms(start);
        Ok(m)
    }

    /// The record of the fit and its models, the tabulated NDF as the pipeline built it.
    fn material(
        &self,
        source: &str,
        tab: TabulatedFit,
        ggx: Option<ParamRecord>,
        beckmann: Option<ParamRecord>,
        mut timings: Timings,
        start: Instant,
    ) -> Result<FittedMaterial, FitError> {
        let (cfg, ex) = (self.cfg, &tab.extraction);
        let t = Instant::now();
        let fresnel = FresnelTable::on_merl_bins(tab.fresnel);
        let fresnel_fits = self.physical(&model_of(&tab.ndf), &fresnel, tab.diffuse);
        timings.fresnel += ms(t);
        timings.total = ms(start);
        let record = FitRecord {
            name: self.src.name().to_owned(),
            source: source.to_owned(),
            backend: self.eval.name(),
            fallback: None,
            resolution: cfg.extract.resolution,
            phi_resolution: if cfg.anisotropic {
                cfg.extract.phi_resolution
            } else {
                1
            },
            anisotropic: cfg.anisotropic,
            quadrature: cfg.extract.quadrature,
            iterations: ex.iterations,
            residual: ex.residual,
            eigenvalue: ex.eigenvalue,
            tabulated: TabulatedRecord {
                error: tab.error,
                stretch: tab.ndf.stretch,
                tables: tab.ndf.tables().clone(),
                diffuse: tab.diffuse,
                origin: tab.origin.into(),
            },
            ggx,
            beckmann,
            fresnel,
            fresnel_fits,
            diffuse_lobe: self.diffuse,
            separation_rounds: tab.separation_rounds,
            refine_rounds: tab.refine_rounds,
            coat: None,
            metric: cfg.metric,
            metric_floor: 1.0 / self.grids.full.scale() as f64,
            other_metric: None,
            look: None,
            timings_ms: timings,
        };
        FittedMaterial::from_parts(record, Arc::new(tab.ndf)).map_err(|problem| {
            FitError::Extraction {
                name: self.src.name().into(),
                problem,
            }
        })
    }
}
