//! `facet fit`: one fit per input, a JSON and tables per fit, a summary table; a sweep split
//! into shards ([`shard`]) and its table put back together ([`summary`]).

mod shard;
mod summary;

use self::shard::{Entry, Manifest, Shard, fit_stem, settings};
use self::summary::{
    FitRow, SUMMARY_CSV, print_medians, print_summary, refuse_over_input, write_summary_csv,
};
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use facet_fit::Brdf;
use facet_fit::extract::Stopping;
use facet_fit::fitting::{Backend, CoatSearch, FitConfig, Models, fit_material_on};
use facet_fit::gpu::GpuFitter;
use facet_fit::metric::Metric;
use facet_fit::model::analytic::parse_analytic;
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
type Opened = (
    Result<Box<dyn facet_fit::Brdf + Send>, facet_fit::FitError>,
    f64,
);

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
pub enum MetricArg {
    Perceptual,
    Log,
}

impl MetricArg {
    /// The metric `--metric` names.
    pub fn metric(self) -> Metric {
        match self {
            MetricArg::Perceptual => Metric::Perceptual,
            MetricArg::Log => Metric::Log,
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CoatArg {
    Auto,
    Always,
    Off,
}

impl CoatArg {
    /// The search `--coat` and `--no-coat` ask for.
    pub fn search(self, no_coat: bool) -> CoatSearch {
        match (no_coat, self) {
            (true, _) | (_, CoatArg::Off) => CoatSearch::Off,
            (_, CoatArg::Auto) => CoatSearch::Auto,
            (_, CoatArg::Always) => CoatSearch::Always,
        }
    }
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
    #[arg(required_unless_present = "summary")]
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
    /// Output folder for NAME.json and the tables, summary.csv (the printed table, when there are
    /// several inputs) and a shard's manifest.
    #[arg(long, default_value = "out")]
    out: PathBuf,
    /// Fit only shard I of N of the inputs (I from 0 to N − 1): those at k = I, I + N, I + 2N, …
    /// in command-line order, from 0. Every shard gets the same inputs and options; each writes
    /// its fits, named as one run over all the inputs names them, and
    /// `shard-I-of-N.facet-shard.json`, which --summary reads (no summary.csv: shards may share
    /// --out).
    #[arg(long, value_name = "I/N", value_parser = shard::parse_shard)]
    shard: Option<Shard>,
    /// Fit nothing: read the fits and shard manifests in the folders DIR… (the --out of one run or
    /// of every shard of a sweep), print the table one run over all the inputs prints, in its
    /// order, and write it to --out as summary.csv. Refused, with nothing written, unless the
    /// manifests make one whole sweep: every shard once, the same N, number of inputs, settings
    /// and Facet version.
    #[arg(
        long,
        value_name = "DIR",
        num_args = 1..,
        conflicts_with_all = [
            "inputs", "shard", "model", "aniso", "resolution", "phi_resolution", "iterations",
            "tolerance", "quadrature", "backend", "no_diffuse", "no_refine", "fresnel", "nbrdf",
            "coat", "no_coat", "metric",
        ]
    )]
    summary: Vec<PathBuf>,
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
    /// When to search a clear coat over a base (η 1.5; its α, its weight and the base under it
    /// fitted; 2–4 s), kept where the coated sphere looks closer to the data (ΔE2000 under
    /// the report's point light, at least 0.1 lower): `auto` (the default) where the single
    /// layer's sphere differs from the data by more than ΔE 0.9, `always`, or `off`. The
    /// single layer's models are written either way; a coat kept is the fit JSON's `coat`,
    /// both looks its `look`.
    #[arg(long, value_enum, default_value = "auto")]
    coat: CoatArg,
    /// The objective every step of the fit minimises: `perceptual`, |ln(1 + x_model/ε) −
    /// ln(1 + x_data/ε)| with ε 0.3 times the material's median x (a relative error down to
    /// well below its typical brightness, as the eye sees it; the default), or `log`, the
    /// paper's (ε = 1; the default of --no-diffuse and --aniso, the paper's pipelines). The JSON
    /// names it and holds every model's error in both.
    #[arg(long, value_enum)]
    metric: Option<MetricArg>,
    /// The same as --coat off: the single layer alone.
    #[arg(long, conflicts_with = "coat")]
    no_coat: bool,
    /// Neural proxy file for `nbrdf:` inputs (default: `$FACET_NBRDF`, else the MERL-100
    /// proxies embedded in Facet).
    #[arg(long)]
    nbrdf: Option<PathBuf>,
}

impl FitArgs {
    /// `--backend` as it is written on the command line.
    fn backend_name(&self) -> String {
        self.backend
            .to_possible_value()
            .map_or(String::new(), |v| v.get_name().to_owned())
    }

    fn config(&self) -> Result<FitConfig> {
        let mut cfg = if self.aniso {
            FitConfig::anisotropic()
        } else {
            FitConfig::isotropic()
        };
        if let Some(n) = self.resolution {
            cfg.extract.resolution = n;
        }
        cfg.metric = match self.metric {
            Some(m) => m.metric(),
            None if self.no_diffuse || self.aniso => Metric::Log,
            None => Metric::Perceptual,
        };
        cfg.diffuse &= !self.no_diffuse;
        cfg.refine &= !self.no_refine && cfg.diffuse;
        if cfg.diffuse && !self.aniso {
            cfg.coat = self.coat.search(self.no_coat);
        }
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

/// `facet fit`: each input (or each of `--shard`'s) fitted and written, the table printed;
/// `summary.csv` across several inputs, a shard's manifest; `--summary` goes to
/// [`summary::run`].
pub fn run(args: &FitArgs) -> Result<ExitCode> {
    if !args.summary.is_empty() {
        return summary::run(&args.summary, &args.out);
    }
    let cfg = args.config()?;
    let nbrdf = NbrdfLibrary::override_path(args.nbrdf.as_deref());
    let mut library = None;
    let specs: Vec<InputSpec> = args.inputs.iter().map(|i| InputSpec::parse(i)).collect();
    let mine: Vec<usize> = (0..specs.len())
        .filter(|&k| args.shard.is_none_or(|s| s.holds(k)))
        .collect();
    let (gpu, (names, first)) = open_gpu_during(args.backend, cfg.anisotropic, || {
        let names: Vec<Option<String>> = specs.iter().map(planned_name).collect();
        let first = mine
            .first()
            .map(|&k| open_timed(&specs[k], nbrdf.as_deref(), &mut library));
        (names, first)
    });
    let gpu = gpu?;
    let fitter = fitter(&gpu, args.backend)?;
    let backend = fitter.as_ref().map_or(Backend::Cpu, Backend::Gpu);
    let mut outputs = Outputs {
        dir: &args.out,
        read: specs
            .iter()
            .filter_map(|s| s.path().map(Path::to_path_buf))
            .chain(nbrdf.clone())
            .collect(),
        names: HashSet::new(),
    };
    // The sweep's own file, refused before any fit when it would replace an input.
    let sweep_file = match args.shard {
        Some(shard) => Some(args.out.join(shard.manifest_name())),
        None => (args.inputs.len() > 1).then(|| args.out.join(SUMMARY_CSV)),
    };
    if let Some(file) = &sweep_file {
        refuse_over_input(file, &outputs.read)?;
    }
    crate::output::folder(&args.out, "--out")?;
    // Every input claims its file name in command-line order, fitted here or not, so that each
    // shard names its fits as one run over all the inputs does.
    let mut planned: Vec<_> = names
        .iter()
        .map(|n| n.as_deref().map(|n| outputs.claim(n)))
        .collect();
    let jobs = mine
        .iter()
        .map(|&k| Job {
            index: k,
            input: &args.inputs[k],
            spec: &specs[k],
            planned: planned[k].take(),
        })
        .collect();
    let mut first = first;
    let started = Instant::now();
    let (rows, entries) = fit_inputs(jobs, &cfg, backend, &mut outputs, |spec| {
        first
            .take()
            .unwrap_or_else(|| open_timed(spec, nbrdf.as_deref(), &mut library))
    });
    let failed = entries.iter().any(|e| e.outcome.is_err());
    print_summary(&rows);
    if rows.len() > 1 {
        print_medians(&rows, started.elapsed().as_secs_f64());
    }
    if !rows.is_empty() {
        println!("wrote {} fit(s) to {}", rows.len(), args.out.display());
    }
    if let Some(shard) = args.shard {
        let manifest = Manifest {
            shard,
            total_inputs: args.inputs.len(),
            facet_version: env!("CARGO_PKG_VERSION").into(),
            settings: settings(&cfg, &args.backend_name(), nbrdf.as_deref()),
            entries,
        };
        let path = args.out.join(shard.manifest_name());
        facet_fit::io::output::write_bytes_atomically(&path, manifest.to_json())
            .with_context(|| format!("writing {}", path.display()))?;
        println!("wrote {}", path.display());
    } else if sweep_file.is_some() {
        println!("wrote {}", write_summary_csv(&args.out, &rows)?.display());
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// The name the fit of `spec` will have (its source's name), found without fitting it and,
/// but for a fit `.json` or an analytic spec, without opening it; `None` when a fit `.json` or
/// spec cannot be read to tell (it then fails to open, and claims no name).
fn planned_name(spec: &InputSpec) -> Option<String> {
    let stem = |path: &Path| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    match spec {
        InputSpec::Nbrdf(name) => Some(name.clone()),
        InputSpec::Analytic(s) => parse_analytic(s).ok().map(|m| Brdf::name(&m).to_owned()),
        InputSpec::Fit(path) => FittedMaterial::load(path).ok().map(|f| f.record.name),
        // MERL and RGL sources are named after the file's stem.
        InputSpec::Rgl(path) | InputSpec::Merl(path) => Some(stem(path)),
    }
}

/// One input to fit.
struct Job<'a> {
    /// Its index on the command line.
    index: usize,
    /// As given.
    input: &'a str,
    spec: &'a InputSpec,
    /// Its JSON and tables paths, claimed from its name before any fit; `None` when the name
    /// was not known then.
    planned: Option<Result<(PathBuf, PathBuf)>>,
}

/// Fits `jobs` in order, each source opened by `open`, with a progress bar across several:
/// the rows of the fits and every input's outcome. A failed input is reported and the rest
/// still run.
fn fit_inputs(
    jobs: Vec<Job>,
    cfg: &FitConfig,
    backend: Backend,
    outputs: &mut Outputs,
    mut open: impl FnMut(&InputSpec) -> Opened,
) -> (Vec<FitRow>, Vec<Entry>) {
    let bar = (jobs.len() > 1).then(|| {
        let bar = ProgressBar::new(jobs.len() as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed} < {eta}]")
                .expect("valid template"),
        );
        bar
    });
    let (mut rows, mut entries) = (Vec::new(), Vec::new());
    for job in jobs {
        if let Some(bar) = &bar {
            bar.set_message(job.input.to_owned());
        }
        let opened = open(job.spec);
        let outcome = match fit_one(job.input, opened, job.planned, cfg, backend, outputs) {
            Ok(row) => {
                let json = row.json.clone();
                rows.push(row);
                Ok(json)
            }
            Err(e) => {
                // Printed around the bar (a hidden bar, as when stderr is not a terminal,
                // would swallow `bar.println`).
                let msg = format!("{e:#}");
                match &bar {
                    Some(bar) => bar.suspend(|| eprintln!("error: {msg}")),
                    None => eprintln!("error: {msg}"),
                }
                Err(msg)
            }
        };
        entries.push(Entry {
            index: job.index,
            input: job.input.to_owned(),
            outcome,
        });
        if let Some(bar) = &bar {
            bar.inc(1);
        }
    }
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    (rows, entries)
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
    /// The JSON and CSV paths for a fit named `name` (from data: made a safe file stem that no
    /// shard manifest's name ends like; a second fit of one name gets -2, -3, ...), refused when
    /// one would replace an input.
    fn claim(&mut self, name: &str) -> Result<(PathBuf, PathBuf)> {
        let base = fit_stem(facet_fit::io::input::safe_file_stem(name));
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
            refuse_over_input(o, &self.read)?;
        }
        Ok((json, csv))
    }
}

/// Fits one opened input and writes its JSON and tables to the paths `planned` for it (or, when
/// its name was not known before, claimed now).
fn fit_one(
    input: &str,
    (src, load_ms): Opened,
    planned: Option<Result<(PathBuf, PathBuf)>>,
    cfg: &FitConfig,
    backend: Backend,
    outputs: &mut Outputs,
) -> Result<FitRow> {
    let src = src?;
    let (json, csv) = planned
        .unwrap_or_else(|| outputs.claim(src.name()))
        .with_context(|| input.to_owned())?;
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
    fit.save(&json)?;
    write_tables(&fit, &csv)?;
    let json = json
        .file_name()
        .expect("a claimed path has a file name")
        .to_string_lossy()
        .into_owned();
    Ok(FitRow {
        json,
        record: fit.record,
    })
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
    print_summary(&[FitRow {
        json: "default-gold-ggx.json".into(),
        record: fit.record.clone(),
    }]);
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
