//! `facet report`: one HTML page, for a paper's supplement, comparing measured materials with
//! their fits — per material, spheres of the measurement and of each model under a point light
//! and an environment, their ΔE2000 images and mean ΔE2000 and ΔE_ITP, NDF and Fresnel plots,
//! errors and times; a database summary (sortable table, mean ΔE per model, mean ΔE images over
//! the set); run time against error over N = 32, 64, 90, 128 ([`sweep`]).

mod delta_e;
mod false_colour;
mod html;
mod material;
mod plots;
mod scenes;
mod subject;
mod sweep;

use self::material::{MaterialReport, report_material};
use self::scenes::{Lighting, SphereRenderer};
use crate::fit_cmd::{CoatArg, MetricArg};
use anyhow::{Context, Result, bail};
use clap::Args;
use facet_fit::FitConfig;
use facet_fit::fitting::CoatSearch;
use facet_fit::io::input::same_file;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

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

/// Subfolder of the report's images.
pub const IMG: &str = "img";

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

/// A file stem for `name`, unique among `taken` (-2, -3, ... on a repeat).
fn unique_stem(name: &str, taken: &mut HashSet<String>) -> String {
    let base = facet_fit::io::input::safe_file_stem(name);
    let mut stem = base.clone();
    for k in 2.. {
        if taken.insert(stem.clone()) {
            break;
        }
        stem = format!("{base}-{k}");
    }
    stem
}

fn progress_bar(n: usize) -> ProgressBar {
    let bar = ProgressBar::new(n as u64);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed} < {eta}]")
            .expect("a valid template"),
    );
    bar
}

pub fn run(args: &ReportArgs) -> Result<ExitCode> {
    let started = Instant::now();
    let inputs = inputs(args)?;
    refuse_replacing_inputs(args, &inputs)?;
    prepare_out(&args.out, args.force)?;
    let gpu = crate::render_cmd::open_gpu()?;
    let mut renderer = SphereRenderer::new(&gpu, args.resolution, args.spp, args.env.as_deref())?;
    let mut cfg = FitConfig {
        coat: args.coat.search(args.no_coat),
        metric: args.metric.metric(),
        ..FitConfig::isotropic()
    };
    cfg.extract.resolution = args.fit_resolution;
    let mut library = None;
    let bar = progress_bar(inputs.len());
    let (mut reports, mut stems, mut failed) = (Vec::new(), HashSet::new(), 0);
    for input in &inputs {
        bar.set_message(input.clone());
        let done = subject::open(input, &cfg, &mut library).and_then(|s| {
            let stem = unique_stem(&s.fit.record.name, &mut stems);
            report_material(&mut renderer, &s, &stem, &args.out)
        });
        match done {
            Ok(r) => reports.push(r),
            // The readers' and the steps' errors name the input; the others still go on.
            Err(e) => {
                failed += 1;
                bar.suspend(|| eprintln!("error: {e:#}"));
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if reports.is_empty() {
        // Nothing to show: the folders made above go again (only if empty: nothing else is
        // removed).
        let _ = std::fs::remove_dir(args.out.join(IMG));
        let _ = std::fs::remove_dir(&args.out);
        bail!("no input could be reported ({failed} failed)");
    }
    // The sweep fits again only inputs that were reported.
    let reported: Vec<String> = reports.iter().map(|r| r.input.clone()).collect();
    // The sweep times the single layer's fit against N: no coat is searched.
    let single = FitConfig {
        coat: CoatSearch::Off,
        ..cfg
    };
    let sweep = run_sweep(&reported, args.sweep, &single, &mut library)?;
    write_page(args, &gpu, &reports, &sweep, started)?;
    print_means(&reports, started);
    Ok(if failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}

/// The N sweep of the first `k` inputs, with its own progress bar.
fn run_sweep(
    inputs: &[String],
    k: usize,
    cfg: &FitConfig,
    library: &mut Option<NbrdfLibrary>,
) -> Result<Vec<sweep::SweepPoint>> {
    let chosen = &inputs[..k.min(inputs.len())];
    let bar = progress_bar(chosen.len());
    let mut points = Vec::new();
    for input in chosen {
        bar.set_message(format!("N sweep: {input}"));
        points.extend(sweep::sweep_input(input, cfg, library)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(points)
}

/// The database's mean ΔE images, the scale, the sweep plot and index.html.
fn write_page(
    args: &ReportArgs,
    gpu: &facet_gpu::Gpu,
    reports: &[MaterialReport],
    sweep: &[sweep::SweepPoint],
    started: Instant,
) -> Result<()> {
    let out = &args.out;
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        for k in 0..scenes::N_MODELS {
            let images: Vec<_> = reports.iter().filter_map(|r| r.de[l][k].as_ref()).collect();
            if let Some(mean) = delta_e::DeltaE::mean_of(&images) {
                false_colour::write_png(&mean, &out.join(html::mean_de_file(*lighting, k)))?;
            }
        }
    }
    plots::write_scale(&out.join(plots::SCALE_FILE))?;
    if !sweep.is_empty() {
        plots::write_sweep_plot(sweep, &out.join(plots::SWEEP_FILE))?;
    }
    let info = html::PageInfo {
        adapter: gpu.describe(),
        side: args.resolution,
        env_spp: args.spp,
        resolution: args.fit_resolution,
        coat: match args.coat.search(args.no_coat) {
            CoatSearch::Auto => {
                "a clear coat searched where the single layer's point-light sphere is above \
                 ΔE2000 0.9, kept where it looks better"
            }
            CoatSearch::Always => {
                "a clear coat searched for every material, kept where it looks better"
            }
            CoatSearch::Off => "no coat searched",
        },
        env: args
            .env
            .as_ref()
            .map_or("the demo's sky".into(), |p| p.display().to_string()),
        seconds: started.elapsed().as_secs_f64(),
        version: env!("CARGO_PKG_VERSION"),
    };
    let page = html::page(&info, reports, sweep);
    let index = out.join("index.html");
    std::fs::write(&index, page).with_context(|| format!("writing {}", index.display()))?;
    println!("wrote {}", index.display());
    Ok(())
}

/// The mean ΔE2000 and ΔE_ITP per model over the set, the noise floor's mean and median, and
/// the wall time.
fn print_means(reports: &[MaterialReport], started: Instant) {
    let means = html::set_means(reports);
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        for (d, name) in ["ΔE", "ΔE_ITP"].iter().enumerate() {
            let v: Vec<String> = scenes::Variant::MODELS
                .iter()
                .zip(means[l])
                .map(|(m, v)| {
                    let v = v.map(|v| v.both()[d]);
                    format!(
                        "{} {}",
                        m.key(),
                        v.map_or("–".into(), |v| format!("{v:.3}"))
                    )
                })
                .collect();
            println!("mean {name} ({}): {}", lighting.key(), v.join(", "));
        }
    }
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        let floors = html::floor_stats(reports)[l];
        println!(
            "noise floor ({}): ΔE mean {:.3} median {:.3}, ΔE_ITP mean {:.3} median {:.3}",
            lighting.key(),
            floors[0].0,
            floors[0].1,
            floors[1].0,
            floors[1].1
        );
    }
    println!(
        "{} material(s) in {:.1} s",
        reports.len(),
        started.elapsed().as_secs_f64()
    );
}
