//! The whole fit of one source: extraction, G1, Fresnel, parameter fits and errors.

use crate::brdf::Brdf;
use crate::brdf::Rgb;
use crate::diffuse::{separate, tabulated_model};
use crate::error::FitError;
use crate::extract::{CpuSolver, ExtractConfig, Solver, extract_with};
use crate::fresnel::{Fresnel, FresnelTable};
use crate::fresnel_fit::{FresnelChoice, FresnelFits};
#[cfg(feature = "gpu")]
use crate::gpu::{GpuFitter, gpu_error};
#[cfg(feature = "gpu")]
use crate::grid::IsoTables;
use crate::grid::{
    CoarseGrid, GridSamples, fresnel_and_error, fresnel_average, fresnel_diffuse_and_error,
    microfacet_error, microfacet_errors,
};
use crate::material::{FitRecord, FittedMaterial, ParamRecord, Params, TabulatedRecord, Timings};
use crate::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use crate::params::{
    candidates_of, fit_least_squares, fit_moments, least_squares_candidates, refine_by_bracket,
};
use crate::refine::{Refinement, model_of, tabulate};
use crate::tabulated::TabulatedNdf;
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
    /// `search_stride`-th (θh, θd) row of an isotropic source, an isotropic fit's α search on
    /// every fourth φd bin of those rows ([`GridSamples::coarse`]); every `search_stride`-th
    /// sample of an anisotropic one); an isotropic fit then brackets α
    /// ([`crate::params::refine_by_bracket`]) on every fourth φd bin of the final steps' rows
    /// (the full grid, or with a diffuse lobe a quarter of it, [`GridSamples::diagonal`]) and
    /// solves F for the α found: averaged over the full grid, or with a diffuse lobe solved with
    /// ρd on the bracket's rows. The reported errors use every sample.
    pub search_stride: usize,
    /// Fit a Lambertian lobe ρd with every model and keep F in [0, 1] ([`crate::diffuse`]);
    /// false: the paper's single specular lobe with F averaged. Isotropic fits only: an
    /// anisotropic fit always takes the single lobe.
    pub diffuse: bool,
    /// Refine the tabulated NDF in the metric's space after the extraction (`refine.rs`),
    /// and tabulate the best analytic fit's NDF when it fits better (diffuse fits only).
    pub refine: bool,
    /// The Fresnel each model renders with: its table, or the conductor, dielectric or Schlick
    /// curve fitted to it ([`crate::fresnel_fit`]; diffuse fits only, where F lies in [0, 1]).
    pub fresnel: FresnelChoice,
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
        }
    }

    /// The paper's pipeline: isotropic, one specular lobe, F averaged, no refinement.
    pub const fn single_lobe() -> Self {
        FitConfig {
            diffuse: false,
            refine: false,
            ..Self::isotropic()
        }
    }

    /// Anisotropic extraction ([`ExtractConfig::anisotropic`]), every model.
    pub const fn anisotropic() -> Self {
        FitConfig {
            extract: ExtractConfig::anisotropic(),
            anisotropic: true,
            models: Models::ALL,
            search_stride: 64,
            diffuse: false,
            refine: false,
            fresnel: FresnelChoice::Table,
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

/// A tabulated candidate: its NDF, F per θd bin and ρd.
type Candidate = (TabulatedNdf, Vec<Rgb>, Rgb);

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Without the `gpu` feature there is no GPU fitter: an uninhabited stand-in keeps one body of
/// `fit_with` for both builds.
#[cfg(not(feature = "gpu"))]
enum GpuFitter {}

/// Where the extraction and the passes over the whole grid (the Fresnel average, the error
/// metric of every reported error) run. The parameter searches, the F and ρd solves and the
/// refinement, on subsets of the grid, always run on the CPU. (With the `gpu` feature only.)
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
    if set.len() < crate::merl::MIN_VALID_SAMPLES {
        return Err(FitError::Extraction {
            name: src.name().into(),
            problem: format!(
                "{} valid samples on the MERL grid; a fit needs at least {}",
                set.len(),
                crate::merl::MIN_VALID_SAMPLES
            ),
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
    // The diffuse lobe is solved on the isotropic grid, on the CPU.
    let diffuse = cfg.diffuse && !cfg.anisotropic && set.iso.is_some();
    // The GPU runs the passes over the whole grid of an isotropic source, its samples uploaded
    // once for all models: the Fresnel average and the error metric.
    #[cfg(feature = "gpu")]
    let uploaded = match gpu {
        Some(g) if set.rotations.len() == 1 => {
            Some((g, g.upload(&set).map_err(|e| gpu_error(src.name(), e))?))
        }
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
    // A model's error on the full grid (on the GPU where the samples are uploaded).
    let full_error = |m: &MicrofacetBrdf| -> Result<f64, FitError> {
        #[cfg(feature = "gpu")]
        if let (Some((g, samples)), Some(tables)) = (&uploaded, IsoTables::new(m)) {
            return g
                .error
                .mean(g.gpu, samples, &tables)
                .map_err(|e| gpu_error(src.name(), e));
        }
        Ok(microfacet_error(m, &set))
    };
    // F (and with a diffuse lobe ρd) for a model's own D and G, and its error, on the full
    // grid.
    let solve = |m: &MicrofacetBrdf| -> Result<(Vec<Rgb>, Rgb, f64), FitError> {
        if diffuse && let Some(r) = fresnel_diffuse_and_error(m, &set, FINAL_IRLS) {
            return Ok(r);
        }
        if gpu.is_some() {
            let f = average(m)?;
            let with = MicrofacetBrdf {
                fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
                ..m.clone()
            };
            return Ok((f, [0.0; 3], full_error(&with)?));
        }
        let (f, e) = fresnel_and_error(m, &set);
        Ok((f, [0.0; 3], e))
    };
    // The final steps' rows: with a diffuse lobe a quarter of the rows, the full grid without.
    // (A sparse source may hold no sample on the quarter: then the full grid.)
    let final_steps = match diffuse.then(|| set.diagonal(FINAL_STRIDE)) {
        Some(rows) if !rows.is_empty() => rows,
        _ => set.subsample(1),
    };
    // A model with its F table and ρd solved.
    let solved = |m: &MicrofacetBrdf, f: &[Rgb], albedo: Rgb| MicrofacetBrdf {
        fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.to_vec())),
        diffuse: albedo,
        ..m.clone()
    };
    let analytic = cfg.models.ggx || cfg.models.beckmann;
    // Every fourth φd bin of the final steps' rows ([`GridSamples::coarse`]): the analytic
    // fits' α bracket runs on them, and with a diffuse lobe every model's F / ρd solve and the
    // tabulated NDF's refinement.
    let coarse = (analytic || diffuse)
        .then(|| final_steps.coarse())
        .flatten();
    // A model's F and ρd, and its error on `rows` (the full grid where `None`): with a diffuse
    // lobe F and ρd solved on the coarse rows (`FINAL_IRLS` reweighted steps), without one
    // averaged over the grid (and the error on the grid).
    let solve_for = |m: &MicrofacetBrdf,
                     rows: Option<&GridSamples>|
     -> Result<(Vec<Rgb>, Rgb, f64), FitError> {
        let on_coarse = coarse
            .as_ref()
            .filter(|_| diffuse)
            .and_then(|c| c.fresnel_diffuse_and_error(m, FINAL_IRLS));
        let Some((f, kd, _)) = on_coarse else {
            return solve(m);
        };
        let with = solved(m, &f, kd);
        let e = match rows {
            Some(rows) => microfacet_error(&with, rows),
            None => full_error(&with)?,
        };
        Ok((f, kd, e))
    };
    // ... with its error on the full grid.
    let solve_reported = |m: &MicrofacetBrdf| solve_for(m, None);
    // The paper's tabulated model: one lobe, F averaged for the extraction's D and G.
    let single = if diffuse {
        None
    } else {
        let model = tabulated_model(&ex);
        // On the CPU the tabulated model's error shares G2 with its Fresnel average.
        Some(if gpu.is_none() && cfg.models.tabulated {
            let (f, e) = fresnel_and_error(&model, &set);
            (f, Some(e))
        } else {
            (average(&model)?, None)
        })
    };
    let mut fresnel_ms = ms(t);

    // With a diffuse lobe, the physical Fresnel curves fitted to a model's table, each with its
    // error on the final steps' rows: one pass over a quarter of the grid for the three, which
    // on the 100 MERL proxies came within 0.85 % of the full grid's (the sixteenth: 1.33 %).
    let physical = |m: &MicrofacetBrdf, table: &FresnelTable, albedo: Rgb| {
        diffuse.then(|| {
            let with = MicrofacetBrdf {
                diffuse: albedo,
                ..m.clone()
            };
            let mut fits = FresnelFits::of(table, |curves| {
                let e = microfacet_errors(&with, curves, &final_steps);
                std::array::from_fn(|n| e[n])
            });
            fits.used = cfg.fresnel;
            fits
        })
    };

    let t = Instant::now();
    let search = set.subsample(cfg.search_stride);
    // An isotropic fit's α search on every fourth φd bin of those rows.
    let coarse_search = (analytic && !cfg.anisotropic)
        .then(|| search.coarse())
        .flatten();
    let fit_kind = |kind: NdfKind| -> Result<ParamRecord, FitError> {
        let moments = fit_moments(kind, &ex.ndf);
        let model = |ndf: AnalyticNdf| MicrofacetBrdf::ideal("lsq", Ndf::Analytic(ndf));
        // Isotropic: the α search and bracket on coarse rows, F and ρd (with a diffuse lobe)
        // on the final steps' coarse rows, the error on the full grid (coarse to fine).
        let (lsq, (lsq_fresnel, lsq_diffuse, error)) = if cfg.anisotropic {
            let lsq = fit_least_squares(moments, true, diffuse, &search);
            (lsq, solve(&model(lsq))?)
        } else {
            // The search's candidates compete on the bracket's rows.
            let starts: Vec<f64> = match &coarse_search {
                // (`error` is `None` only for an anisotropic model.)
                Some(rows) => candidates_of(moments, |n| {
                    rows.error(&model(n), diffuse).unwrap_or(f64::INFINITY)
                }),
                None => least_squares_candidates(moments, diffuse, &search),
            }
            .iter()
            .map(|n| n.alpha_x.ln())
            .collect();
            // The bracket's F (and ρd) are averaged (plain weighted least squares) on the
            // coarse rows; the α found is solved again (`solve_reported`).
            let (t, e, solved) = refine_by_bracket(&starts, |t| {
                let m = model(AnalyticNdf::isotropic(kind, t.exp()));
                match coarse.as_ref().and_then(|b| b.error(&m, diffuse)) {
                    Some(e) => Ok::<_, FitError>((e, None)),
                    None => solve(&m).map(|(f, kd, e)| (e, Some((f, kd)))),
                }
            })?;
            let ndf = AnalyticNdf::isotropic(kind, t.exp());
            match solved {
                Some((f, kd)) => (ndf, (f, kd, e)),
                None => (ndf, solve_reported(&model(ndf))?),
            }
        };
        // The paper's estimate: α by moments with the Fresnel of the extraction; with a
        // diffuse lobe, with F and ρd solved for it and its error on the final steps' rows (a
        // quarter of the grid; on the 100 MERL proxies within 0.6 % of the full grid's, median
        // 0.04 %), as the physical curves' errors are: a comparison figure, which took a
        // fifth of the analytic fits' time on the full grid.
        let moments_error = match &single {
            Some((f, _)) => full_error(&MicrofacetBrdf {
                fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
                ..model(moments)
            })?,
            None => solve_for(&model(moments), Some(&final_steps))?.2,
        };
        let params = |n: &AnalyticNdf, e| Params {
            alpha_x: n.alpha_x,
            alpha_y: n.alpha_y,
            rotation: n.rotation,
            error: e,
        };
        Ok(ParamRecord {
            alpha_x: lsq.alpha_x,
            alpha_y: lsq.alpha_y,
            rotation: lsq.rotation,
            error,
            method: "least_squares".into(),
            moments: params(&moments, moments_error),
            fresnel_fits: physical(
                &model(lsq),
                &FresnelTable::on_merl_bins(lsq_fresnel.clone()),
                lsq_diffuse,
            ),
            fresnel: FresnelTable::on_merl_bins(lsq_fresnel),
            diffuse: lsq_diffuse,
        })
    };
    // The two families side by side: their searches' passes are short (a few hundred rows) and
    // their steps between passes serial, which one fit alone leaves the second core idle for.
    let (ggx, beckmann) = rayon::join(
        || cfg.models.ggx.then(|| fit_kind(NdfKind::Ggx)).transpose(),
        || {
            cfg.models
                .beckmann
                .then(|| fit_kind(NdfKind::Beckmann))
                .transpose()
        },
    );
    let (ggx, beckmann) = (ggx?, beckmann?);
    let fit_ms = ms(t);

    let t = Instant::now();
    // The best analytic fit: the refinement's other start.
    let best_analytic = [(NdfKind::Ggx, &ggx), (NdfKind::Beckmann, &beckmann)]
        .into_iter()
        .filter_map(|(k, p)| p.as_ref().map(|p| (k, p)))
        .min_by(|a, b| a.1.error.total_cmp(&b.1.error));
    let mut separation_rounds = 1;
    let mut refine_rounds = 0;
    let (ex, tab) = match single {
        Some((f, e)) => {
            let error = match e {
                Some(e) => Some(e),
                None if cfg.models.tabulated => Some(full_error(&MicrofacetBrdf {
                    fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
                    ..tabulated_model(&ex)
                })?),
                None => None,
            };
            let ndf = ex.ndf.clone();
            (ex, (ndf, f, [0.0; 3], error, "power_iteration"))
        }
        None => {
            let sep = separate(src, &search, ex, |b| {
                extract_with(b, &cfg.extract, false, solver)
            })?;
            separation_rounds = sep.rounds;
            let ex = sep.extraction;
            // A tabulated NDF refined on the coarse rows from F and ρd solved there
            // (`Refinement::start`, which shares the NDF's G2 / (4 cos θo) and plain sums with
            // the rounds), or unrefined solved as any model (`solve_reported`); its error on
            // the full grid, and the refinement's rounds.
            let rows = coarse.as_ref().filter(|_| cfg.refine).map(CoarseGrid::rows);
            let candidate = |ndf: &TabulatedNdf| -> Result<(Candidate, f64, usize), FitError> {
                let Some(r) = rows.and_then(|rows| Refinement::new(ndf, rows)) else {
                    let (f, kd, error) = solve_reported(&model_of(ndf))?;
                    return Ok(((ndf.clone(), f, kd), error, 0));
                };
                let start = r.start();
                let (c, rounds) = match r.run(&start) {
                    Some(r) => ((r.ndf, r.fresnel, r.albedo), r.rounds),
                    None => ((ndf.clone(), start.0, start.1), 0),
                };
                let error = full_error(&solved(&model_of(&c.0), &c.1, c.2))?;
                Ok((c, error, rounds))
            };
            let (mut best, mut error, rounds) = candidate(&ex.ndf)?;
            let mut origin = "power_iteration";
            refine_rounds = rounds;
            // Where an analytic fit is still better, its NDF tabulated is the other start.
            if let Some((kind, p)) = best_analytic.filter(|(_, p)| cfg.refine && p.error < error) {
                let analytic = AnalyticNdf::isotropic(kind, p.alpha_x);
                let t = ex.ndf.tables();
                if let Some(ndf) = tabulate(analytic, t.nu, t.ng) {
                    let (c, e, rounds) = candidate(&ndf)?;
                    refine_rounds += rounds;
                    if e < error {
                        (best, error, origin) = (c, e, kind.name());
                    }
                }
            }
            (ex, (best.0, best.1, best.2, Some(error), origin))
        }
    };
    let (ndf, tab_fresnel, tab_diffuse, tab_error, origin) = tab;
    let fresnel = FresnelTable::on_merl_bins(tab_fresnel);
    let fresnel_fits = physical(&model_of(&ndf), &fresnel, tab_diffuse);
    fresnel_ms += ms(t);

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
            stretch: ndf.stretch,
            tables: ndf.tables().clone(),
            diffuse: tab_diffuse,
            origin: origin.into(),
        },
        ggx,
        beckmann,
        fresnel,
        fresnel_fits,
        diffuse_lobe: diffuse,
        separation_rounds,
        refine_rounds,
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
    // The same NDF, without rebuilding its sampler.
    material.tabulated.ndf = Ndf::Tabulated(Arc::new(ndf));
    Ok(material)
}
