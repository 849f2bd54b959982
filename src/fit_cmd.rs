//! `facet fit`: one fit per input, a JSON and tables per fit, a summary table.

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use facet_fit::extract::Stopping;
use facet_fit::fitting::{Backend, FitConfig, Models, fit_material_on};
use facet_fit::gpu::GpuFitter;
use facet_fit::io::input::same_file;
use facet_fit::model::fresnel_curves::FresnelChoice;
use facet_fit::model::material::FittedMaterial;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::numerics::quadrature::Quadrature;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::{InputSpec, Residence};
use facet_gpu::Gpu;
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::HashSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Most (θ, φ) directions of an anisotropic extraction.
const MAX_ANISO_DIRECTIONS: usize = 65536;

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    All,
    Tabulated,
    Ggx,
    Beckmann,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BackendArg {
    /// Anisotropic fits: a GPU adapter when there is one, else the CPU, with a notice (a
    /// software adapter such as lavapipe is left alone: the f64 CPU path is faster).
    /// Isotropic fits: the CPU, with no adapter probed (no GPU stage pays for itself there).
    Auto,
    /// WGSL compute passes (f32); fails when there is no adapter.
    Gpu,
    /// f64 reference on the CPU, parallel over all cores.
    Cpu,
}

/// The GPU for `--backend`, or `None` for the CPU. `FACET_BACKEND` / `FACET_ADAPTER` choose it.
/// `auto` probes for an adapter only for an `anisotropic` fit: an isotropic fit's GPU stages (the
/// power iteration of a 90-node kernel, the Fresnel average) take about what the CPU takes (on an
/// H200 host: 87 against 83 ms a fit), and the probe (driver loading) cost 45–50 ms of a
/// 0.2 s `facet fit` process on a machine with only lavapipe.
fn open_gpu(arg: BackendArg, anisotropic: bool) -> Result<Option<Gpu>> {
    match arg {
        BackendArg::Cpu => Ok(None),
        BackendArg::Auto if !anisotropic => Ok(None),
        BackendArg::Gpu => Ok(Some(Gpu::new().context("--backend gpu")?)),
        // The adapter is looked at before a device is opened on it: a software rasteriser
        // (lavapipe, llvmpipe) is slower than the CPU path, and opening one costs more than a
        // fit.
        BackendArg::Auto => match Gpu::best_adapter_info().and_then(|info| {
            if info.device_type == wgpu::DeviceType::Cpu {
                Ok(Err(info))
            } else {
                Gpu::new().map(Ok)
            }
        }) {
            Ok(Err(info)) => {
                eprintln!(
                    "notice: only a software adapter ({}); fitting on the CPU (--backend gpu uses it)",
                    info.name
                );
                Ok(None)
            }
            Ok(Ok(g)) => Ok(Some(g)),
            Err(e) => {
                eprintln!("notice: {e}; fitting on the CPU");
                Ok(None)
            }
        },
    }
}

/// [`open_gpu`] on a thread while `work` runs on this one: the adapter probe (driver loading,
/// 30–50 ms with lavapipe) overlaps the first input's loading.
fn open_gpu_during<T>(
    arg: BackendArg,
    anisotropic: bool,
    work: impl FnOnce() -> T,
) -> (Result<Option<Gpu>>, T) {
    std::thread::scope(|s| {
        let probe = s.spawn(|| open_gpu(arg, anisotropic));
        let done = work();
        let gpu = probe
            .join()
            .unwrap_or_else(|_| Err(anyhow::anyhow!("the adapter probe panicked")));
        (gpu, done)
    })
}

/// A source opened, and the milliseconds it took.
type Opened = (Result<Box<dyn facet_fit::Brdf>, facet_fit::FitError>, f64);

fn open_timed(
    input: &InputSpec,
    nbrdf: Option<&Path>,
    library: &mut Option<NbrdfLibrary>,
) -> Opened {
    let t = Instant::now();
    let src = input.open(nbrdf, library, Residence::Mapped);
    (src, t.elapsed().as_secs_f64() * 1e3)
}

/// Pipelines on the GPU, or the CPU when `--backend auto` cannot build them.
fn fitter<'g>(gpu: &'g Option<Gpu>, arg: BackendArg) -> Result<Option<GpuFitter<'g>>> {
    let Some(g) = gpu else { return Ok(None) };
    match GpuFitter::new(g) {
        Ok(f) => Ok(Some(f)),
        Err(e) if arg == BackendArg::Auto => {
            eprintln!("notice: GPU pipelines failed ({e}); fitting on the CPU");
            Ok(None)
        }
        Err(e) => Err(e).context("building the GPU pipelines"),
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FresnelArg {
    Table,
    Conductor,
    Dielectric,
    Schlick,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum QuadratureArg {
    UniformTheta,
    SqrtMidpoint,
    GaussLegendreSqrt,
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct FitArgs {
    /// MERL .binary file, RGL .bsdf, `nbrdf:NAME`, `analytic:ggx?alpha=0.2&f0=0.04`, or a fit .json.
    #[arg(required = true)]
    inputs: Vec<String>,
    /// Models to fit and report (the tabulated NDF is always extracted).
    #[arg(long, value_enum, default_value = "all")]
    model: ModelArg,
    /// Extract on a (θ, φ) grid and fit αx, αy and rotation.
    #[arg(long)]
    aniso: bool,
    /// Polar quadrature nodes N, 2 to 4096 (default 90; 64 with --aniso, where N × the
    /// azimuthal nodes is at most 65536).
    #[arg(long, value_parser = crate::args::resolution)]
    resolution: Option<usize>,
    /// Azimuthal nodes with --aniso, 1 to 1024.
    #[arg(long, default_value_t = 64, value_parser = crate::args::phi_resolution)]
    phi_resolution: usize,
    /// Run exactly M power iterations, 1 to 10000 (the paper: 4), instead of iterating to
    /// convergence.
    #[arg(long, value_parser = crate::args::iterations)]
    iterations: Option<usize>,
    /// Convergence tolerance: L1 change of the normalised NDF per iteration, 1e-15 to 1.
    #[arg(long, default_value_t = 1e-9, value_parser = crate::args::tolerance)]
    tolerance: f64,
    #[arg(long, value_enum, default_value = "gauss-legendre-sqrt")]
    quadrature: QuadratureArg,
    #[arg(long, value_enum, default_value = "auto")]
    backend: BackendArg,
    /// Output folder for NAME.json and the tables.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// The paper's single specular lobe: no Lambertian term, F averaged per θd bin and not
    /// clipped to [0, 1], no refinement (default: a diffuse lobe ρd with every model, F in
    /// [0, 1], the tabulated NDF refined in the metric's space). --aniso fits a single lobe.
    #[arg(long)]
    no_diffuse: bool,
    /// Keep the extracted NDF as the power iteration gives it (with the diffuse lobe).
    #[arg(long)]
    no_refine: bool,
    /// The Fresnel every model renders with: its table F(θd), or the conductor (η, k per
    /// channel), dielectric (η) or Schlick (F0) curve fitted to it. All three are fitted and
    /// recorded with their errors either way (not with --no-diffuse or --aniso).
    #[arg(long, value_enum, default_value = "table")]
    fresnel: FresnelArg,
    /// Neural proxy file for `nbrdf:` inputs (default: `$FACET_NBRDF`, else the MERL-100
    /// proxies embedded in Facet).
    #[arg(long)]
    nbrdf: Option<PathBuf>,
}

impl FitArgs {
    fn config(&self) -> Result<FitConfig> {
        let mut cfg = if self.aniso {
            FitConfig::anisotropic()
        } else {
            FitConfig::isotropic()
        };
        if let Some(n) = self.resolution {
            cfg.extract.resolution = n;
        }
        cfg.diffuse &= !self.no_diffuse;
        cfg.refine &= !self.no_refine && cfg.diffuse;
        cfg.fresnel = match self.fresnel {
            FresnelArg::Table => FresnelChoice::Table,
            FresnelArg::Conductor => FresnelChoice::Conductor,
            FresnelArg::Dielectric => FresnelChoice::Dielectric,
            FresnelArg::Schlick => FresnelChoice::Schlick,
        };
        if self.fresnel != FresnelArg::Table && (!cfg.diffuse || self.aniso) {
            bail!(
                "--fresnel other than table needs the diffuse lobe (not --no-diffuse or --aniso)"
            );
        }
        if self.aniso {
            cfg.extract.phi_resolution = self.phi_resolution;
            // The kernel is (N·Nφ)² per iteration: 65536 directions is minutes already.
            let dirs = cfg.extract.resolution * cfg.extract.phi_resolution;
            if dirs > MAX_ANISO_DIRECTIONS {
                bail!(
                    "--resolution {} × --phi-resolution {} = {dirs} directions; --aniso takes at most {MAX_ANISO_DIRECTIONS}",
                    cfg.extract.resolution,
                    cfg.extract.phi_resolution
                );
            }
        }
        cfg.extract.stopping = match self.iterations {
            Some(m) => Stopping::Fixed(m),
            None => Stopping::Converge {
                tolerance: self.tolerance,
                max_iterations: 10_000,
            },
        };
        cfg.extract.quadrature = match self.quadrature {
            QuadratureArg::UniformTheta => Quadrature::UniformTheta,
            QuadratureArg::SqrtMidpoint => Quadrature::SqrtMidpoint,
            QuadratureArg::GaussLegendreSqrt => Quadrature::GaussLegendreSqrt,
        };
        cfg.models = match self.model {
            ModelArg::All => Models::ALL,
            ModelArg::Tabulated => Models {
                tabulated: true,
                ggx: false,
                beckmann: false,
            },
            ModelArg::Ggx => Models {
                tabulated: false,
                ggx: true,
                beckmann: false,
            },
            ModelArg::Beckmann => Models {
                tabulated: false,
                ggx: false,
                beckmann: true,
            },
        };
        Ok(cfg)
    }
}

pub fn run(args: &FitArgs) -> Result<ExitCode> {
    let cfg = args.config()?;
    let nbrdf = NbrdfLibrary::override_path(args.nbrdf.as_deref());
    let mut library = None;
    let specs: Vec<InputSpec> = args.inputs.iter().map(|i| InputSpec::parse(i)).collect();
    let (gpu, mut first) = open_gpu_during(args.backend, cfg.anisotropic, || {
        let first = specs.first()?;
        Some(open_timed(first, nbrdf.as_deref(), &mut library))
    });
    let gpu = gpu?;
    let fitter = fitter(&gpu, args.backend)?;
    let backend = fitter.as_ref().map_or(Backend::Cpu, Backend::Gpu);
    crate::output::folder(&args.out, "--out")?;
    let mut outputs = Outputs {
        dir: &args.out,
        read: specs
            .iter()
            .filter_map(|s| s.path().map(Path::to_path_buf))
            .chain(nbrdf.clone())
            .collect(),
        names: HashSet::new(),
    };
    let bar = (args.inputs.len() > 1).then(|| {
        let bar = ProgressBar::new(args.inputs.len() as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed} < {eta}]")
                .expect("valid template"),
        );
        bar
    });
    let mut rows = Vec::new();
    let mut failures = 0;
    let started = Instant::now();
    for (input, spec) in args.inputs.iter().zip(&specs) {
        if let Some(bar) = &bar {
            bar.set_message(input.clone());
        }
        let opened = first
            .take()
            .unwrap_or_else(|| open_timed(spec, nbrdf.as_deref(), &mut library));
        match fit_one(input, opened, &cfg, backend, &mut outputs) {
            Ok(fit) => rows.push(fit),
            Err(e) => {
                failures += 1;
                // Printed around the bar (a hidden bar, as when stderr is not a terminal,
                // would swallow `bar.println`).
                let msg = format!("error: {e:#}");
                match &bar {
                    Some(bar) => bar.suspend(|| eprintln!("{msg}")),
                    None => eprintln!("{msg}"),
                }
            }
        }
        if let Some(bar) = &bar {
            bar.inc(1);
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    print_summary(&rows);
    if rows.len() > 1 {
        print_medians(&rows, started.elapsed().as_secs_f64());
    }
    if !rows.is_empty() {
        println!("wrote {} fit(s) to {}", rows.len(), args.out.display());
    }
    Ok(if failures > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// Where the fits of one run go: `dir/<name>.json` and `.tables.csv`, each name once, never
/// over a file the run reads.
struct Outputs<'a> {
    dir: &'a Path,
    /// Every file this run reads.
    read: Vec<PathBuf>,
    names: HashSet<String>,
}

impl Outputs<'_> {
    /// The JSON and CSV paths for a fit named `name` (from data: made a safe file stem; a
    /// second fit of one name gets -2, -3, ...), refused when one would replace an input.
    fn claim(&mut self, name: &str) -> Result<(PathBuf, PathBuf)> {
        let base = facet_fit::io::input::safe_file_stem(name);
        let mut name = base.clone();
        for k in 2.. {
            if self.names.insert(name.clone()) {
                break;
            }
            name = format!("{base}-{k}");
        }
        let json = self.dir.join(format!("{name}.json"));
        let csv = self.dir.join(format!("{name}.tables.csv"));
        for o in [&json, &csv] {
            if let Some(i) = self.read.iter().find(|i| same_file(i, o)) {
                bail!(
                    "the output {} would replace the input {}; choose another --out",
                    o.display(),
                    i.display()
                );
            }
        }
        Ok((json, csv))
    }
}

fn fit_one(
    input: &str,
    (src, load_ms): Opened,
    cfg: &FitConfig,
    backend: Backend,
    outputs: &mut Outputs,
) -> Result<FittedMaterial> {
    let src = src?;
    let mut fit = fit_material_on(src.as_ref(), input, cfg, backend)?;
    if let Some(gpu_error) = &fit.record.fallback {
        eprintln!("notice: {input}: fitted on the CPU after a GPU failure: {gpu_error}");
    }
    // The diffuse lobe is solved on the isotropic grid: a source that is not isotropic (an
    // anisotropic analytic or RGL material fitted without --aniso) gets the single lobe.
    if cfg.diffuse && !cfg.anisotropic && !fit.record.diffuse_lobe {
        eprintln!(
            "notice: {input}: not isotropic, so fitted with a single specular lobe (no diffuse \
             term, F not clipped to [0, 1]); --aniso fits its αx, αy and rotation"
        );
    }
    fit.record.timings_ms.load = load_ms;
    fit.record.timings_ms.total += load_ms;
    let (json, csv) = outputs
        .claim(&fit.record.name)
        .with_context(|| input.to_owned())?;
    fit.save(&json)?;
    write_tables(&fit, &csv)?;
    Ok(fit)
}

/// θ (degrees), D, P = D cos⁴θ and G1 of the tabulated NDF at φ = 0, and F(θd) per channel.
fn write_tables(fit: &FittedMaterial, path: &Path) -> Result<()> {
    let facet_fit::model::microfacet::Ndf::Tabulated(ndf) = &fit.tabulated.ndf else {
        unreachable!()
    };
    let mut s = String::from("theta_deg,ndf_d,slope_pdf_p,g1,fresnel_r,fresnel_g,fresnel_b\n");
    for k in 0..=180 {
        let theta = (k as f64 * 0.5).to_radians();
        let d = ndf.base_d(theta, 0.0);
        let f = fit.record.fresnel.eval(theta);
        s += &format!(
            "{:.1},{:e},{:e},{:.6},{:.6},{:.6},{:.6}\n",
            k as f64 * 0.5,
            d,
            d * theta.cos().powi(4),
            ndf.base_g1(theta, 0.0),
            f[0],
            f[1],
            f[2]
        );
    }
    facet_fit::io::output::write_bytes_atomically(path, s)
        .with_context(|| format!("writing {}", path.display()))
}

fn print_summary(rows: &[FittedMaterial]) {
    if rows.is_empty() {
        return;
    }
    let mut out = std::io::stdout().lock();
    let _ = writeln!(
        out,
        "{:<28} {:>5} {:>9} {:>17}  {:>17} {:>8}  {:>17} {:>8}  {:>8}",
        "material",
        "iters",
        "tab err",
        "tab ρd",
        "ggx αx/αy",
        "ggx err",
        "beckmann αx/αy",
        "beck err",
        "ms"
    );
    for f in rows {
        let r = &f.record;
        let param = |p: &Option<facet_fit::model::material::ParamRecord>| match p {
            Some(p) => (
                format!("{:.4}/{:.4}", p.alpha_x, p.alpha_y),
                format!("{:.4}", p.error),
            ),
            None => ("-".into(), "-".into()),
        };
        let (ga, ge) = param(&r.ggx);
        let (ba, be) = param(&r.beckmann);
        let te = r.tabulated.error.map_or("-".into(), |e| format!("{e:.4}"));
        let kd = r.tabulated.diffuse;
        let kd = if r.diffuse_lobe {
            format!("{:.3}/{:.3}/{:.3}", kd[0], kd[1], kd[2])
        } else {
            "-".into()
        };
        let _ = writeln!(
            out,
            "{:<28} {:>5} {:>9} {:>17}  {:>17} {:>8}  {:>17} {:>8}  {:>8.1}",
            r.name, r.iterations, te, kd, ga, ge, ba, be, r.timings_ms.total
        );
    }
}

fn print_medians(rows: &[FittedMaterial], seconds: f64) {
    let median = |mut v: Vec<f64>| -> String {
        if v.is_empty() {
            return "-".into();
        }
        v.sort_by(f64::total_cmp);
        format!("{:.4}", v[v.len() / 2])
    };
    let tab = median(
        rows.iter()
            .filter_map(|f| f.record.tabulated.error)
            .collect(),
    );
    let ggx = median(
        rows.iter()
            .filter_map(|f| f.record.ggx.as_ref().map(|p| p.error))
            .collect(),
    );
    let ggx_m = median(
        rows.iter()
            .filter_map(|f| f.record.ggx.as_ref().map(|p| p.moments.error))
            .collect(),
    );
    let beck = median(
        rows.iter()
            .filter_map(|f| f.record.beckmann.as_ref().map(|p| p.error))
            .collect(),
    );
    println!(
        "median error over {} fits: tabulated {tab}, ggx {ggx} (moments {ggx_m}), beckmann {beck}; {seconds:.2} s in all",
        rows.len()
    );
}

/// The embedded default: a gold GGX conductor (α = 0.15) sampled into an in-memory MERL table
/// and fitted, so that `cargo run --release` shows the whole pipeline with no input file.
pub const DEFAULT_MATERIAL: &str = "ggx?alpha=0.15&conductor=gold";

/// Fits the embedded default material (sampled into a MERL table, then extracted and fitted),
/// writes `default-gold-ggx.json` and its tables CSV into `out`, prints the summary.
pub fn fit_default(out: &Path) -> Result<(FittedMaterial, std::path::PathBuf)> {
    println!(
        "        (sampled into a MERL table, then extracted and fitted; see `facet fit --help`)"
    );
    let (gpu, sampled) = open_gpu_during(BackendArg::Auto, false, || -> Result<_> {
        let t = Instant::now();
        let model = facet_fit::model::analytic::parse_analytic(DEFAULT_MATERIAL)?;
        let src = MerlBrdf::from_table("default-gold-ggx", MerlTable::sample(&model))
            .map_err(anyhow::Error::msg)?;
        Ok((src, t.elapsed().as_secs_f64() * 1e3))
    });
    let (src, load_ms) = sampled?;
    let gpu = gpu?;
    let fitter = fitter(&gpu, BackendArg::Auto)?;
    let backend = fitter.as_ref().map_or(Backend::Cpu, Backend::Gpu);
    let mut fit = fit_material_on(
        &src,
        &format!("embedded:analytic:{DEFAULT_MATERIAL}"),
        &FitConfig::isotropic(),
        backend,
    )?;
    fit.record.timings_ms.load = load_ms;
    crate::output::folder(out, "--out")?;
    let json = out.join("default-gold-ggx.json");
    fit.save(&json)?;
    write_tables(&fit, &out.join("default-gold-ggx.tables.csv"))?;
    print_summary(std::slice::from_ref(&fit));
    let r = &fit.record;
    let f = |deg: f64| r.fresnel.eval(f64::to_radians(deg));
    println!(
        "fresnel at θd = 0°, 60°, 85°: {:.3?} {:.3?} {:.3?}",
        f(0.0),
        f(60.0),
        f(85.0)
    );
    println!(
        "timings (ms): sample {:.1}, extract {:.1}, fresnel {:.1}, fit {:.1}; {} iterations, residual {:.1e}",
        load_ms,
        r.timings_ms.extract,
        r.timings_ms.fresnel,
        r.timings_ms.fit,
        r.iterations,
        r.residual
    );
    println!("wrote {} and default-gold-ggx.tables.csv", json.display());
    Ok((fit, json))
}
