//! The whole fit of one source: extraction, G1, Fresnel, parameter fits and errors.

use crate::brdf::Brdf;
use crate::error::FitError;
use crate::extract::{CpuSolver, ExtractConfig, Solver, extract_with};
use crate::fresnel::{Fresnel, FresnelTable};
#[cfg(feature = "gpu")]
use crate::gpu::{GpuFitter, gpu_error};
#[cfg(feature = "gpu")]
use crate::grid::IsoTables;
use crate::grid::{GridSamples, fresnel_and_error, fresnel_average, microfacet_error};
use crate::material::{FitRecord, FittedMaterial, ParamRecord, Params, TabulatedRecord, Timings};
use crate::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use crate::params::{fit_least_squares, fit_moments, refine_on_full_grid};
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
    /// The least-squares searches run on a subsampled grid ([`GridSamples::subsample`]: every
    /// `search_stride`-th (θh, θd) row of an isotropic source, every `search_stride`-th sample
    /// of an anisotropic one); an isotropic fit then takes its final steps on the full grid
    /// ([`crate::params::refine_on_full_grid`]), and the reported errors use every sample.
    pub search_stride: usize,
}

impl FitConfig {
    /// Isotropic extraction ([`ExtractConfig::isotropic`]), every model.
    pub const fn isotropic() -> Self {
        FitConfig {
            extract: ExtractConfig::isotropic(),
            anisotropic: false,
            models: Models::ALL,
            search_stride: 48,
        }
    }

    /// Anisotropic extraction ([`ExtractConfig::anisotropic`]), every model.
    pub const fn anisotropic() -> Self {
        FitConfig {
            extract: ExtractConfig::anisotropic(),
            anisotropic: true,
            models: Models::ALL,
            search_stride: 64,
        }
    }
}

impl Default for FitConfig {
    fn default() -> Self {
        Self::isotropic()
    }
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Without the `gpu` feature there is no GPU fitter: an uninhabited stand-in keeps one body of
/// `fit_with` for both builds.
#[cfg(not(feature = "gpu"))]
enum GpuFitter {}

/// Where the extraction and the Fresnel averages run. The parameter searches and the error
/// metric always run on the CPU. (With the `gpu` feature only.)
#[cfg(feature = "gpu")]
#[derive(Clone, Copy)]
pub enum Backend<'a, 'g> {
    /// The f64 reference path.
    Cpu,
    /// WGSL compute passes on the fitter's adapter (f32).
    Gpu(&'a GpuFitter<'g>),
}

/// Fits one source on the CPU. `source` describes where it came from (recorded in the JSON).
pub fn fit_material(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
) -> Result<FittedMaterial, FitError> {
    fit_with(src, source, cfg, None)
}

/// Fits one source on a backend. A GPU failure falls back to the CPU, and the record's
/// `backend` says so: the answer is never silently different. (With the `gpu` feature only.)
#[cfg(feature = "gpu")]
pub fn fit_material_on(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
    backend: Backend,
) -> Result<FittedMaterial, FitError> {
    match backend {
        Backend::Cpu => fit_with(src, source, cfg, None),
        Backend::Gpu(g) => match fit_with(src, source, cfg, Some(g)) {
            Err(e @ FitError::Gpu { .. }) => {
                let mut m = fit_with(src, source, cfg, None)?;
                m.record.backend = format!("cpu (fallback after a GPU failure: {e})");
                Ok(m)
            }
            other => other,
        },
    }
}

fn fit_with(
    src: &dyn Brdf,
    source: &str,
    cfg: &FitConfig,
    gpu: Option<&GpuFitter>,
) -> Result<FittedMaterial, FitError> {
    let start = Instant::now();
    let t = Instant::now();
    let solver: &dyn Solver = match gpu {
        #[cfg(feature = "gpu")]
        Some(g) => g,
        #[cfg(not(feature = "gpu"))]
        Some(g) => match *g {},
        None => &CpuSolver,
    };
    let ex = extract_with(src, &cfg.extract, cfg.anisotropic, solver)?;
    let extract_ms = ms(t);

    let t = Instant::now();
    let set = GridSamples::new(src);
    if set.is_empty() {
        return Err(FitError::Extraction {
            name: src.name().into(),
            problem: "no valid sample on the MERL grid".into(),
        });
    }
    if let Some(s) = set.out_of_range() {
        let (i, j, max) = (s.i, s.j, crate::grid::MAX_X);
        return Err(FitError::Extraction {
            name: src.name().into(),
            problem: format!(
                "f_r cos θi = {:?} at θh bin {i}, θd bin {j} is outside ±{max:e}",
                s.x
            ),
        });
    }
    // The GPU averages Fresnel over isotropic sample sets, uploaded once for all models.
    #[cfg(feature = "gpu")]
    let uploaded = match gpu {
        Some(g) if set.rotations.len() == 1 => Some((
            g,
            g.fresnel
                .upload(g.gpu, &set)
                .map_err(|e| gpu_error(src.name(), e))?,
        )),
        _ => None,
    };
    let average = |model: &MicrofacetBrdf| -> Result<Vec<crate::brdf::Rgb>, FitError> {
        #[cfg(feature = "gpu")]
        if let (Some((g, samples)), Some(tables)) = (&uploaded, IsoTables::new(model)) {
            return g
                .fresnel
                .average(g.gpu, samples, &set, &tables)
                .map_err(|e| gpu_error(src.name(), e));
        }
        Ok(fresnel_average(model, &set))
    };
    let mut tabulated = MicrofacetBrdf {
        name: format!("{}-tabulated", src.name()),
        ndf: Ndf::Tabulated(Arc::new(ex.ndf.clone())),
        fresnel: Fresnel::Schlick { f0: [1.0; 3] },
        diffuse: [0.0; 3],
    };
    // On the CPU the tabulated model's error shares G2 with its Fresnel average.
    let (rgb, fused_error) = if gpu.is_none() && cfg.models.tabulated {
        let (f, e) = fresnel_and_error(&tabulated, &set);
        (f, Some(e))
    } else {
        (average(&tabulated)?, None)
    };
    let fresnel = FresnelTable::on_merl_bins(rgb);
    tabulated.fresnel = Fresnel::Table(fresnel.clone());
    let fresnel_ms = ms(t);

    let t = Instant::now();
    let tab_error = fused_error.or_else(|| {
        cfg.models
            .tabulated
            .then(|| microfacet_error(&tabulated, &set))
    });
    let search = set.subsample(cfg.search_stride);
    let fit_kind = |kind: NdfKind| -> Result<ParamRecord, FitError> {
        let moments = fit_moments(kind, &ex.ndf);
        let lsq = fit_least_squares(moments, cfg.anisotropic, &search);
        // The paper's estimate: α by moments with the Fresnel of the extraction.
        let moment_model = MicrofacetBrdf {
            name: "moments".into(),
            ndf: Ndf::Analytic(moments),
            fresnel: Fresnel::Table(fresnel.clone()),
            diffuse: [0.0; 3],
        };
        // The least-squares model with a Fresnel table averaged for its own D and G.
        let lsq_model = |ndf: AnalyticNdf| -> Result<(f64, MicrofacetBrdf), FitError> {
            let mut m = MicrofacetBrdf {
                name: "lsq".into(),
                ndf: Ndf::Analytic(ndf),
                fresnel: Fresnel::Schlick { f0: [1.0; 3] },
                diffuse: [0.0; 3],
            };
            let (f, e) = if gpu.is_some() {
                let f = average(&m)?;
                m.fresnel = Fresnel::Table(FresnelTable::on_merl_bins(f));
                (None, microfacet_error(&m, &set))
            } else {
                let (f, e) = fresnel_and_error(&m, &set);
                (Some(f), e)
            };
            if let Some(f) = f {
                m.fresnel = Fresnel::Table(FresnelTable::on_merl_bins(f));
            }
            Ok((e, m))
        };
        // Isotropic: the final steps on the full grid (coarse to fine).
        let (lsq, error, lsq_model) = if cfg.anisotropic {
            let (e, m) = lsq_model(lsq)?;
            (lsq, e, m)
        } else {
            let (t, e, m) = refine_on_full_grid(lsq.alpha_x.ln(), |t| {
                lsq_model(AnalyticNdf::isotropic(kind, t.exp()))
            })?;
            (AnalyticNdf::isotropic(kind, t.exp()), e, m)
        };
        let Fresnel::Table(lsq_fresnel) = lsq_model.fresnel else {
            unreachable!("the least-squares model has a Fresnel table")
        };
        let params = |n: &AnalyticNdf, e| Params {
            alpha_x: n.alpha_x,
            alpha_y: n.alpha_y,
            rotation: n.rotation,
            error: e,
        };
        let moments = params(&moments, microfacet_error(&moment_model, &set));
        Ok(ParamRecord {
            alpha_x: lsq.alpha_x,
            alpha_y: lsq.alpha_y,
            rotation: lsq.rotation,
            error,
            method: "least_squares".into(),
            moments,
            fresnel: lsq_fresnel,
        })
    };
    let ggx = cfg.models.ggx.then(|| fit_kind(NdfKind::Ggx)).transpose()?;
    let beckmann = cfg
        .models
        .beckmann
        .then(|| fit_kind(NdfKind::Beckmann))
        .transpose()?;
    let fit_ms = ms(t);

    let record = FitRecord {
        name: src.name().to_owned(),
        source: source.to_owned(),
        backend: solver.name(),
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
            error: tab_error,
            stretch: ex.ndf.stretch,
            tables: ex.ndf.tables().clone(),
        },
        ggx,
        beckmann,
        fresnel,
        timings_ms: Timings {
            load: 0.0,
            extract: extract_ms,
            fresnel: fresnel_ms,
            fit: fit_ms,
            total: ms(start),
        },
    };
    let mut material =
        FittedMaterial::from_record(record).map_err(|problem| FitError::Extraction {
            name: src.name().into(),
            problem,
        })?;
    material.tabulated = tabulated; // the same model, without rebuilding the sampler
    Ok(material)
}
