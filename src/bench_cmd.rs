//! `facet bench`: every speed figure of Facet in one process, on the adapter chosen as
//! elsewhere (FACET_BACKEND, FACET_ADAPTER): the fitter (CPU and GPU backends), ray tracing,
//! the integrator with and without glints and its stages, the DPF build, the viewer's preview
//! path, and what a shard process costs besides its work. Prints a table and writes JSON
//! (`--json FILE`). Timings are medians of repeated runs after a warm-up, measured side by side
//! in this one process (the shard section times processes of this binary that it starts). The
//! sections are facet-bench's; this file is their arguments and order.

use crate::fit_cmd::DEFAULT_MATERIAL;
use anyhow::{Context, Result};
use clap::{Parser, ValueEnum};
use facet_bench::section::{
    coat, dpf, fit, integrator, lights, measured, noise, shard, trace, viewer,
};
use facet_bench::{Assets, Sizes, record};
use facet_gpu::Gpu;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Parser, Clone, Debug)]
pub struct BenchArgs {
    /// Also write the results as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// How much to measure (quick: within 5 minutes on lavapipe; default: the full sizes, for a
    /// GPU; full: also 10^7 triangles; smoke: tiny sizes, what the test suite runs).
    #[arg(long, value_enum, default_value_t = Mode::Default)]
    pub mode: Mode,
    /// Same as --mode quick.
    #[arg(long, conflicts_with = "mode")]
    pub quick: bool,
    /// Same as --mode full.
    #[arg(long, conflicts_with_all = ["mode", "quick"])]
    pub full: bool,
    /// Same as --mode smoke.
    #[arg(long, conflicts_with_all = ["mode", "quick", "full"])]
    pub smoke: bool,
    /// Only these sections (comma-separated; default: all).
    #[arg(long, value_enum, value_delimiter = ',')]
    pub only: Vec<Section>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Section {
    Fit,
    Trace,
    Integrator,
    Viewer,
    Noise,
    Dpf,
    /// What a shard process costs besides its work (`facet render --samples`, `facet fit --shard`).
    Shard,
    /// Light selection (bvh, robust, power) on the many-light rooms, the gold scene and the
    /// demo; the light BVH's build.
    Lights,
    /// A measured material (MERL table, RGL file) against its tabulated fit at equal spp.
    Measured,
    /// A fit with and without a clear coat (smooth, glints, a diffuse plastic) at equal spp.
    Coat,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    Smoke,
    Quick,
    Default,
    Full,
}

impl Mode {
    /// The mode's sizes.
    const fn sizes(self) -> Sizes {
        match self {
            Mode::Smoke => Sizes::SMOKE,
            Mode::Quick => Sizes::QUICK,
            Mode::Default => Sizes::DEFAULT,
            Mode::Full => Sizes::FULL,
        }
    }
}

pub fn run(args: &BenchArgs) -> Result<ExitCode> {
    let mode = match (args.quick, args.full, args.smoke) {
        (true, _, _) => Mode::Quick,
        (_, true, _) => Mode::Full,
        (_, _, true) => Mode::Smoke,
        _ => args.mode,
    };
    if let Some(path) = &args.json
        && let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
    {
        crate::output::folder(dir, "--json")?;
    }
    let sizes = mode.sizes();
    let t0 = Instant::now();
    let gpu = match Gpu::new() {
        Ok(g) => Some(g),
        Err(e) => {
            eprintln!("notice: no GPU adapter ({e}): only the CPU fits are measured");
            None
        }
    };
    let mode_name = format!("{mode:?}").to_lowercase();
    let mut report = record::header(&mode_name, env!("FACET_COMMIT"), gpu.as_ref());
    sections(args, gpu.as_ref(), &sizes, &mut report)?;
    report["total_s"] = json!(t0.elapsed().as_secs_f64());
    println!("bench total {:.1} s", t0.elapsed().as_secs_f64());
    if let Some(path) = &args.json {
        std::fs::write(path, serde_json::to_string_pretty(&report)? + "\n")
            .with_context(|| format!("{}: writing the bench JSON", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The sections `args` asks for, in order, each adding its key to `report` (only the CPU fits
/// without a `gpu`).
fn sections(args: &BenchArgs, gpu: Option<&Gpu>, sizes: &Sizes, report: &mut Value) -> Result<()> {
    let assets = Assets::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets"));
    let on = |s: Section| args.only.is_empty() || args.only.contains(&s);
    if on(Section::Fit) {
        report["fit"] = fit::fit(gpu, sizes, DEFAULT_MATERIAL)?;
    }
    if let Some(g) = gpu {
        if on(Section::Trace) {
            report["trace"] = trace::trace(g, sizes)?;
        }
        if on(Section::Integrator) {
            let (rows, stages, glint) = integrator::integrator(g, sizes, &assets)?;
            report["integrator"] = rows;
            report["stages"] = stages;
            report["glint"] = glint;
        }
        if on(Section::Viewer) {
            report["viewer"] = viewer::viewer(g, sizes, &assets)?;
        }
        if on(Section::Noise) {
            report["noise"] = noise::noise(g, sizes, &assets)?;
        }
        if on(Section::Dpf) {
            report["dpf"] = dpf::dpf_pyramid(g, sizes)?;
        }
        if on(Section::Lights) {
            report["lights"] = lights::lights(g, sizes, &assets)?;
        }
        if on(Section::Measured) {
            report["measured"] = measured::measured(g, sizes.noise.0, sizes.noise.1)?;
        }
        if on(Section::Coat) {
            report["coat"] = coat::coat(g, sizes.noise.0, sizes.noise.1)?;
        }
        if on(Section::Shard) {
            let exe = std::env::current_exe().context("the facet binary")?;
            let (size, spp) = sizes.shard;
            report["shard"] = shard::shards(&exe, &assets, sizes.runs, size, spp)?;
        }
    }
    Ok(())
}
