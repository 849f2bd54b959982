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
    GridSamples, fresnel_and_error, fresnel_average, fresnel_diffuse_and_error, microfacet_error,
    microfacet_errors,
};
use crate::material::{FitRecord, FittedMaterial, ParamRecord, Params, TabulatedRecord, Timings};
use crate::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use crate::params::{fit_least_squares, fit_moments, least_squares_candidates, refine_by_bracket};
use crate::refine::{Refinement, model_of, tabulate};
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
    /// of an anisotropic one); an isotropic fit then brackets α
    /// ([`crate::params::refine_by_bracket`]) on every fourth φd bin of the final steps' rows
    /// ([`GridSamples::coarse`]), solves F (and ρd) for the α found on those rows: the full grid,
    /// or with a diffuse lobe a quarter of it ([`GridSamples::diagonal`]); the reported errors
    /// use every sample.
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
// The analytic fits' α bracket runs on the final steps' rows with every fourth φd bin
// (`GridSamples::coarse`), with a diffuse lobe without reweighted steps; the α found is then
// solved, with `FINAL_IRLS` steps, on the final steps' rows. (On the 100 proxies plain steps
// gave the same medians as reweighted ones at 0.9× the time. The coarse rows gave the same
// medians and 90th percentiles in both pipelines; 399 of the 400 analytic fits within 0.2 %,
// polyethylene's GGX 3 % worse, its plain error being flat and bumpy in α. Every fourth row
// instead, a diagonal of stride 16, made sharp lobes' fits up to 2.9 times worse.)
/// The rows of the final steps with a diffuse lobe: about one in 4 ([`GridSamples::diagonal`],
/// which keeps every θh and θd bin). F and ρd of every reported model are solved on them; its
/// reported error is then measured on the full grid.
const FINAL_STRIDE: usize = 4;

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
    // The diffuse lobe is solved on the isotropic grid, on the CPU.
    let diffuse = cfg.diffuse && !cfg.anisotropic && set.iso.is_some();
    // The GPU averages Fresnel over isotropic sample sets, uploaded once for all models.
    #[cfg(feature = "gpu")]
    let uploaded = match gpu {
        Some(g) if set.rotations.len() == 1 && !diffuse => Some((
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
    // F (and with a diffuse lobe ρd) for a model's own D and G, and its error on `on` (the
    // full grid, or with a diffuse lobe the final steps' subsample).
    let solve_on =
        |m: &MicrofacetBrdf, on: &GridSamples| -> Result<(Vec<Rgb>, Rgb, f64), FitError> {
            if diffuse && let Some(r) = fresnel_diffuse_and_error(m, on, FINAL_IRLS) {
                return Ok(r);
            }
            if gpu.is_some() {
                let f = average(m)?;
                let with = MicrofacetBrdf {
                    fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
                    ..m.clone()
                };
                return Ok((f, [0.0; 3], microfacet_error(&with, &set)));
            }
            let (f, e) = fresnel_and_error(m, on);
            Ok((f, [0.0; 3], e))
        };
    let solve = |m: &MicrofacetBrdf| solve_on(m, &set);
    // The final steps: with a diffuse lobe (each step four passes) on a quarter of the rows,
    // and the reported error of the model found (its F and ρd from them) on the full grid.
    let final_steps = if diffuse {
        set.diagonal(FINAL_STRIDE)
    } else {
        set.subsample(1)
    };
    // The full grid's error of a model whose F and ρd were solved on the final steps' rows,
    // where its mean error `e_final` is known: those rows' share and one pass over the others.
    let other_rows = diffuse
        .then(|| set.diagonal_complement(FINAL_STRIDE))
        .flatten();
    let full_error = |m: &MicrofacetBrdf, f: &[Rgb], albedo: Rgb, e_final: f64| {
        let with = MicrofacetBrdf {
            fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.to_vec())),
            diffuse: albedo,
            ..m.clone()
        };
        match &other_rows {
            Some(others) => {
                let n = |s: &GridSamples| s.len() as f64;
                let e_others = if others.is_empty() {
                    0.0
                } else {
                    microfacet_error(&with, others)
                };
                (e_final * n(&final_steps) + e_others * n(others)) / n(&set)
            }
            None => microfacet_error(&with, &set),
        }
    };
    // F and ρd solved on the final steps' rows, the error measured on the full grid.
    let solve_reported = |m: &MicrofacetBrdf| -> Result<(Vec<Rgb>, Rgb, f64), FitError> {
        if !diffuse {
            return solve(m);
        }
        let (f, kd, e_final) = solve_on(m, &final_steps)?;
        let e = full_error(m, &f, kd, e_final);
        Ok((f, kd, e))
    };
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
    // on the five files of `examples/fit_timing.rs` came within 0.7 % of the full grid's.
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
    let analytic = cfg.models.ggx || cfg.models.beckmann;
    let bracket = analytic.then(|| final_steps.coarse()).flatten();
    let fit_kind = |kind: NdfKind| -> Result<ParamRecord, FitError> {
        let moments = fit_moments(kind, &ex.ndf);
        let model = |ndf: AnalyticNdf| MicrofacetBrdf::ideal("lsq", Ndf::Analytic(ndf));
        // Isotropic: the α bracket on the coarse rows, F and ρd on the final steps' rows, the
        // error on the full grid (coarse to fine).
        let (lsq, (lsq_fresnel, lsq_diffuse, error)) = if cfg.anisotropic {
            let lsq = fit_least_squares(moments, true, diffuse, &search);
            (lsq, solve(&model(lsq))?)
        } else {
            // The search's candidates compete on the bracket's rows.
            let starts: Vec<f64> = least_squares_candidates(moments, diffuse, &search)
                .iter()
                .map(|n| n.alpha_x.ln())
                .collect();
            // The bracket's F (and ρd) are averaged (plain weighted least squares) on the
            // coarse rows; the α found is solved on the final steps' rows (with a diffuse
            // lobe, with reweighted steps).
            let (t, e, solved) = refine_by_bracket(&starts, |t| {
                let m = model(AnalyticNdf::isotropic(kind, t.exp()));
                match bracket.as_ref().and_then(|b| b.error(&m, diffuse)) {
                    Some(e) => Ok::<_, FitError>((e, None)),
                    None => solve_on(&m, &final_steps).map(|(f, kd, e)| (e, Some((f, kd)))),
                }
            })?;
            let ndf = AnalyticNdf::isotropic(kind, t.exp());
            match solved {
                Some((f, kd)) => (ndf, (f, kd, e)),
                None => (ndf, solve_reported(&model(ndf))?),
            }
        };
        // The paper's estimate: α by moments with the Fresnel of the extraction; with a
        // diffuse lobe, with F and ρd solved for it.
        let moments_error = match &single {
            Some((f, _)) => microfacet_error(
                &MicrofacetBrdf {
                    fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
                    ..model(moments)
                },
                &set,
            ),
            None => solve_reported(&model(moments))?.2,
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
    // The best analytic fit: the separation's seed and the refinement's other start.
    let best_analytic = [(NdfKind::Ggx, &ggx), (NdfKind::Beckmann, &beckmann)]
        .into_iter()
        .filter_map(|(k, p)| p.as_ref().map(|p| (k, p)))
        .min_by(|a, b| a.1.error.total_cmp(&b.1.error));
    let mut separation_rounds = 1;
    let mut refine_rounds = 0;
    let (ex, tab) = match single {
        Some((f, e)) => {
            let error = e.or_else(|| {
                cfg.models.tabulated.then(|| {
                    let with = MicrofacetBrdf {
                        fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
                        ..tabulated_model(&ex)
                    };
                    microfacet_error(&with, &set)
                })
            });
            let ndf = ex.ndf.clone();
            (ex, (ndf, f, [0.0; 3], error, "power_iteration"))
        }
        None => {
            let seed = best_analytic.map_or([0.0; 3], |(_, p)| p.diffuse);
            let sep = separate(src, &search, seed, ex, |b| {
                extract_with(b, &cfg.extract, false, solver)
            })?;
            separation_rounds = sep.rounds;
            let ex = sep.extraction;
            // The candidates compete on the final steps' rows; the one kept is measured on the
            // full grid. A refinement solves its start's F and ρd itself, sharing that NDF's
            // G2 / (4 cos θo) and plain sums with its rounds.
            let refinement = cfg
                .refine
                .then(|| Refinement::new(&ex.ndf, &final_steps))
                .flatten();
            let (f, kd, e) = match &refinement {
                Some(r) => r.start(),
                None => solve_on(&tabulated_model(&ex), &final_steps)?,
            };
            let mut best = (ex.ndf.clone(), f, kd, e, "power_iteration");
            let mut best_error = None;
            if cfg.refine {
                let start = (best.1.clone(), best.2, best.3);
                if let Some(r) = refinement.and_then(|r| r.run(&start)) {
                    refine_rounds = r.rounds;
                    best = (r.ndf, r.fresnel, r.albedo, r.error, "power_iteration");
                }
                // Where an analytic fit is still better, its NDF tabulated is the start.
                let error = full_error(&model_of(&best.0), &best.1, best.2, best.3);
                best_error = Some(error);
                if let Some((kind, p)) = best_analytic.filter(|(_, p)| p.error < error) {
                    let analytic = AnalyticNdf::isotropic(kind, p.alpha_x);
                    let t = ex.ndf.tables();
                    if let Some(ndf) = tabulate(analytic, t.nu, t.ng) {
                        let refinement = Refinement::new(&ndf, &final_steps);
                        let (f, kd, e) = match &refinement {
                            Some(r) => r.start(),
                            None => solve_on(&model_of(&ndf), &final_steps)?,
                        };
                        let refined = refinement.and_then(|r| r.run(&(f.clone(), kd, e)));
                        let mut start = (ndf.clone(), f, kd, e, kind.name());
                        if let Some(r) = refined {
                            refine_rounds += r.rounds;
                            start = (r.ndf, r.fresnel, r.albedo, r.error, kind.name());
                        }
                        let e = full_error(&model_of(&start.0), &start.1, start.2, start.3);
                        if e < error {
                            (best, best_error) = (start, Some(e));
                        }
                    }
                }
            }
            let error = best_error
                .unwrap_or_else(|| full_error(&model_of(&best.0), &best.1, best.2, best.3));
            (ex, (best.0, best.1, best.2, Some(error), best.4))
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
