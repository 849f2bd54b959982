//! `facet`: measured materials to microfacet models.

mod args;
mod bench_cmd;
mod convert_cmd;
mod demo_cmd;
mod dpf_cmd;
mod export_cmd;
mod fit_cmd;
mod merge_cmd;
mod output;
mod render_cmd;
mod report_cmd;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "facet",
    version,
    about = "Measured materials to microfacet models: NDF extraction, fitting, glints, path-traced renders.\nWith no command, runs `facet demo`."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Extract the NDF of each input and fit tabulated, GGX and Beckmann models.
    Fit(fit_cmd::FitArgs),
    /// A material from one format to another: MERL .binary, RGL .bsdf, fit .json (by OUT's
    /// extension; the neural proxies and analytic models as inputs).
    Convert(convert_cmd::ConvertArgs),
    /// Write a fit's GGX (or Beckmann) model for Mitsuba 3, pbrt-v4 or glTF 2.0, with its error.
    Export(export_cmd::ExportArgs),
    /// The glint model's Directional Probability Function: one query, or the tables as EXR.
    Dpf(dpf_cmd::DpfArgs),
    /// Path-trace a glTF scene (wavefront, on the GPU) to PNG and EXR.
    Render(render_cmd::RenderArgs),
    /// Join shards of one render (`facet render --samples A..B`) into one image, weighted by
    /// their sample counts, the variance too.
    Merge(merge_cmd::MergeArgs),
    /// Fit the embedded default material and render the demo scene with it (the default).
    Demo(demo_cmd::DemoArgs),
    /// Measure the fitter, ray tracing, the integrator, glints and the preview on this adapter.
    Bench(bench_cmd::BenchArgs),
    /// One HTML page comparing measurements with their fits: spheres under a point light and an
    /// environment, ΔE2000 images, NDF and Fresnel plots, a sortable table over the set, run
    /// time against error.
    Report(report_cmd::ReportArgs),
}

fn main() -> std::process::ExitCode {
    // SAFETY: first thing in main, before any thread exists.
    unsafe { facet_gpu::ensure_runtime_dir() };
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Fit(args)) => fit_cmd::run(&args),
        Some(Command::Convert(args)) => convert_cmd::run(&args),
        Some(Command::Export(args)) => export_cmd::run(&args),
        Some(Command::Dpf(args)) => dpf_cmd::run(&args),
        Some(Command::Render(args)) => render_cmd::run(&args),
        Some(Command::Merge(args)) => merge_cmd::run(&args),
        Some(Command::Demo(args)) => demo_cmd::run(&args),
        Some(Command::Bench(args)) => bench_cmd::run(&args),
        Some(Command::Report(args)) => report_cmd::run(&args),
        None => demo_cmd::run(&demo_cmd::DemoArgs::defaults()),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
