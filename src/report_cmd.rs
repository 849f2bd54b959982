//! `facet report`: one HTML page, for a paper's supplement, comparing measured materials with
//! their fits — per material, spheres of the measurement and of each model under a point light
//! and an environment, their ΔE2000 images and mean ΔE2000 and ΔE_ITP, NDF and Fresnel plots,
//! errors and times; a database summary (sortable table, mean ΔE per model, mean ΔE images over
//! the set); run time against error over N = 32, 64, 90, 128. The work is facet-report's; this
//! file is the arguments, their checks, the output folder and the progress bars.

use crate::fit_cmd::{CoatArg, MetricArg};
use anyhow::{Context, Result, bail};
use clap::Args;
use facet_fit::io::input::same_file;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_render::scene::EnvironmentMap;
use facet_report::{IMG, Progress, ReportConfig, ReportError, Sky};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

/// The demo's sky, embedded so that the report needs no file beside the binary.
const SKY_EXR: &[u8] = include_bytes!("../assets/demo/sky.exr");

#[derive(Args)]
pub struct ReportArgs {
    /// What `facet fit` takes (MERL .binary, RGL .bsdf, `nbrdf:NAME`, `analytic:SPEC`) or a fit
    /// .json (rendered by its models only: ΔE against its tabulated model).
    #[arg(required_unless_present = "all_proxies")]
    inputs: Vec<String>,
    /// Add every neural proxy (`nbrdf:NAME`) to the inputs: the 100 MERL proxies embedded in
    /// Facet, or those of `$FACET_NBRDF`.
    #[arg(long)]
    all_proxies: bool,
    /// Output folder: index.html and img/. Refused when it exists and is not empty, unless
    /// --force.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// Write into a non-empty --out (files of the same names are replaced).
    #[arg(long)]
    force: bool,
    /// Side of each sphere image, pixels, 1 to 16384 (128: the 100 proxies in about 10 minutes
    /// on two CPU cores with lavapipe).
    #[arg(long, default_value_t = 128, value_parser = crate::args::side)]
    resolution: u32,
    /// Samples per pixel of the environment renders, 1 to 2^20, best a power of two (scrambled
    /// Sobol points). 16: a noise floor of about 1.6 ΔE2000 and the 100 proxies within 10
    /// minutes; it halves at 4 times the samples and the cost (docs/report.md). The point-light
    /// renders take 4: only their pixel positions vary.
    #[arg(long, default_value_t = 16, value_parser = crate::args::spp)]
    spp: u32,
    /// Polar nodes N of the fits, 2 to 4096.
    #[arg(long, default_value_t = 90, value_parser = crate::args::resolution)]
    fit_resolution: usize,
    /// When the fits search a clear coat, as `facet fit --coat`: `auto` (the default) where
    /// the single layer's sphere differs from the data by more than ΔE2000 0.9 (2–4 s more
    /// for such a material on two cores), `always`, or `off`; kept where it looks better. A
    /// fit that keeps a coat gets one more sphere, its coated model, beside the single layer's
    /// three; a fit JSON that kept one shows it whatever this says.
    #[arg(long, value_enum, default_value = "auto")]
    coat: CoatArg,
    /// The objective the fits minimise, as `facet fit --metric`: `perceptual` or `log`.
    #[arg(long, value_enum, default_value = "perceptual")]
    metric: MetricArg,
    /// The same as --coat off.
    #[arg(long, conflicts_with = "coat")]
    no_coat: bool,
    /// Fit the first K inputs again at N = 32, 64, 90 and 128 for the plot of run time against
    /// error (0: no sweep). Four more fits per input, about 6 s in all on two CPU cores, so the
    /// default sweeps only the first two inputs (the 10-minute budget of the 100 proxies).
    #[arg(long, default_value_t = 2, value_name = "K")]
    sweep: usize,
    /// Equirectangular environment map (EXR, Y up) of the environment renders (default: the
    /// demo's sky, embedded in Facet).
    #[arg(long, value_name = "FILE")]
    env: Option<PathBuf>,
}

/// `--out` made, or refused when it holds anything and `--force` is not given; `img/` in it.
fn prepare_out(out: &Path, force: bool) -> Result<()> {
    if out.is_dir() && !force {
        let mut entries = std::fs::read_dir(out)
            .with_context(|| format!("--out {}: cannot read the folder", out.display()))?;
        if entries.next().is_some() {
            bail!(
                "--out {}: the folder is not empty; choose another or add --force",
                out.display()
            );
        }
    }
    crate::output::folder(out, "--out")?;
    crate::output::folder(&out.join(IMG), "--out")
}

/// The inputs: as given, then the embedded proxies with --all-proxies.
fn inputs(args: &ReportArgs) -> Result<Vec<String>> {
    let mut v = args.inputs.clone();
    if args.all_proxies {
        // Those of the file `nbrdf:` resolves in ($FACET_NBRDF, else the embedded MERL-100).
        let lib = NbrdfLibrary::open_or_embedded(None)?;
        v.extend(lib.names().map(|n| format!("nbrdf:{n}")));
    }
    Ok(v)
}

/// Refuses, before anything is written, an input file the page would replace: `index.html` of
/// `--out`, or a file in its `img/` (whose names come from the materials'), named as an input
/// or as `--env`.
fn refuse_replacing_inputs(args: &ReportArgs, inputs: &[String]) -> Result<()> {
    let files = inputs
        .iter()
        .map(PathBuf::from)
        .filter(|p| p.exists())
        .chain(args.env.clone());
    let (index, img) = (args.out.join("index.html"), args.out.join(IMG));
    for file in files {
        let in_img = file.parent().is_some_and(|p| same_file(p, &img));
        if same_file(&file, &index) || in_img {
            bail!(
                "{}: the report would replace this input (it writes {} and {}/); choose another \
                 --out",
                file.display(),
                index.display(),
                img.display()
            );
        }
    }
    Ok(())
}

/// A bar of `n` steps, with the step's words and the time left.
fn progress_bar(n: usize) -> ProgressBar {
    let bar = ProgressBar::new(n as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed} < {eta}]")
            .expect("a valid template"),
    );
    bar
}

impl ReportArgs {
    /// The library's settings.
    fn config(&self) -> ReportConfig {
        ReportConfig {
            side: self.resolution,
            env_spp: self.spp,
            fit_resolution: self.fit_resolution,
            coat: self.coat.search(self.no_coat),
            metric: self.metric.metric(),
            sweep: self.sweep,
        }
    }
}

/// The environment of `--env`, or the embedded sky; the loader's warnings printed.
fn sky(env: Option<&Path>) -> Result<Sky> {
    let (map, warnings) = match env {
        Some(path) => EnvironmentMap::load(path)?,
        None => EnvironmentMap::from_exr_bytes(Path::new("embedded sky.exr"), SKY_EXR)?,
    };
    for w in warnings {
        eprintln!("warning: {w}");
    }
    let name = env.map_or("the demo's sky".into(), |p| p.display().to_string());
    Ok(Sky {
        map: Arc::new(map),
        name,
    })
}

/// A progress bar per stage of the report (the materials, the N sweep); an input that fails
/// printed above it.
fn show_progress(bar: &mut ProgressBar) -> impl FnMut(Progress) + '_ {
    move |p| match p {
        Progress::Start { len } => *bar = progress_bar(len),
        Progress::Step(what) => bar.set_message(what.to_owned()),
        Progress::Failed(e) => bar.suspend(|| eprintln!("error: {:#}", anyhow::Error::from(e))),
        Progress::Done => bar.inc(1),
        Progress::Finish => bar.finish_and_clear(),
    }
}

pub fn run(args: &ReportArgs) -> Result<ExitCode> {
    let started = Instant::now();
    let inputs = inputs(args)?;
    refuse_replacing_inputs(args, &inputs)?;
    prepare_out(&args.out, args.force)?;
    let gpu = crate::render_cmd::open_gpu()?;
    let sky = sky(args.env.as_deref())?;
    let mut bar = ProgressBar::hidden();
    let done = facet_report::report(
        &gpu,
        &inputs,
        &args.out,
        &sky,
        &args.config(),
        started,
        &mut show_progress(&mut bar),
    );
    let outcome = match done {
        Err(e @ ReportError::NothingReported { .. }) => {
            // Nothing to show: the folders made above go again (only if empty: nothing else
            // is removed).
            let _ = std::fs::remove_dir(args.out.join(IMG));
            let _ = std::fs::remove_dir(&args.out);
            return Err(e.into());
        }
        done => done?,
    };
    println!("wrote {}", outcome.index.display());
    for line in facet_report::means_lines(&outcome.materials) {
        println!("{line}");
    }
    println!(
        "{} material(s) in {:.1} s",
        outcome.materials.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(if outcome.failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
