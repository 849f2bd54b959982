//! `facet demo` (what `cargo run --release` runs): fit the embedded default material, render
//! the committed demo scene with it — tabulated and GGX side by side, a glint sphere, a diffuse
//! floor, a sky — and write `out/`.

use crate::fit_cmd;
use crate::render_cmd::{self, RenderArgs};
use anyhow::Result;
use clap::Parser;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser, Clone, Debug)]
#[command(allow_negative_numbers = true)]
pub struct DemoArgs {
    /// Output folder.
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Image width, 1 to 16384.
    #[arg(long, default_value_t = 480, value_parser = crate::args::side)]
    pub width: u32,
    /// Image height, 1 to 16384.
    #[arg(long, default_value_t = 270, value_parser = crate::args::side)]
    pub height: u32,
    /// Samples per pixel, 1 to 2^20.
    #[arg(long, default_value_t = 16, value_parser = crate::args::spp)]
    pub spp: u32,
}

impl DemoArgs {
    /// The defaults above, as `facet demo` with no options gets them.
    pub fn defaults() -> Self {
        DemoArgs::parse_from(["demo"])
    }
}

/// The committed demo scene and sky.
pub fn demo_assets() -> (PathBuf, PathBuf) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/demo");
    (dir.join("demo.gltf"), dir.join("sky.exr"))
}

pub fn run(args: &DemoArgs) -> Result<ExitCode> {
    let t = std::time::Instant::now();
    println!(
        "facet demo: fitting the embedded default material analytic:{}",
        fit_cmd::DEFAULT_MATERIAL
    );
    let (_, fit_json) = fit_cmd::fit_default(&args.out)?;
    let fit_ms = t.elapsed().as_secs_f64() * 1e3;
    let (scene, sky) = demo_assets();
    let fit = fit_json.display().to_string();
    let render = RenderArgs {
        scene,
        env: Some(sky),
        env_color: None,
        out: args.out.join("demo.png"),
        width: args.width,
        height: args.height,
        spp: args.spp,
        samples: None,
        max_depth: 5,
        seed: 0,
        time_limit: None,
        exposure: 0.0,
        camera: None,
        materials: ["tabulated", "ggx", "glint"]
            .iter()
            .map(|m| format!("{m}={fit}"))
            .collect(),
        nbrdf: None,
        wavefront: 1 << 20,
        bvh: render_cmd::PresetArg::Medium,
        no_glint_filter: false,
        variance: false,
        light_selection: render_cmd::SelectionArg::Bvh,
    };
    println!(
        "rendering {} (tabulated | GGX | glints), {}×{} at {} spp",
        render.scene.display(),
        args.width,
        args.height,
        args.spp
    );
    let job = render_cmd::prepare(&render)?;
    // Without any adapter the fit above still stands; say how to get one rather than fail.
    let gpu = match render_cmd::open_gpu() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("notice: {e:#}\nnotice: the fit is written; the render was skipped");
            return Ok(ExitCode::SUCCESS);
        }
    };
    let timings = render_cmd::render_job(&gpu, &job, &render.out, render.exposure)?;
    render_cmd::print_timings(&timings, job.scene.indices.len());
    println!(
        "demo total {:.1} s (fit {:.0} ms)",
        t.elapsed().as_secs_f64(),
        fit_ms
    );
    Ok(ExitCode::SUCCESS)
}
