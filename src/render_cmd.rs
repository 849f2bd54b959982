//! `facet render`: a glTF scene through the wavefront path tracer to PNG + EXR.

mod digest;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use facet_fit::io::input::{self, same_file};
use facet_render::bvh::{BvhConfig, BvhPreset};
use facet_render::output::shard::{PixelKind, ShardRecord};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Environment, EnvironmentMap, LoadOptions, Scene, load_gltf};
use facet_render::{
    ImageConfig, Integrator, LightSelection, RenderConfig, ResourceConfig, SampleConfig,
    SceneResources,
};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Args, Clone, Debug)]
#[command(allow_negative_numbers = true)]
pub struct RenderArgs {
    /// The scene: a glTF 2.0 file (.gltf or .glb).
    pub scene: PathBuf,
    /// Equirectangular environment map (EXR, Y up). Default: none, unless --env-color.
    #[arg(long)]
    pub env: Option<PathBuf>,
    /// A constant environment radiance, "r,g,b" or one value (ignored with --env).
    #[arg(long, value_name = "RGB")]
    pub env_color: Option<String>,
    /// Output image; the PNG and the EXR are both written, with this stem.
    #[arg(long, default_value = "out/render.png")]
    pub out: PathBuf,
    /// Image width, 1 to 16384 (width × height × spp at most 2^40).
    #[arg(long, default_value_t = 960, value_parser = crate::args::side)]
    pub width: u32,
    /// Image height, 1 to 16384.
    #[arg(long, default_value_t = 540, value_parser = crate::args::side)]
    pub height: u32,
    /// Samples per pixel, 1 to 2^20: the sample indices 0..SPP of every pixel.
    #[arg(long, default_value_t = 32, value_parser = crate::args::spp)]
    pub spp: u32,
    /// Only the sample indices A..B (A included, B not) of every pixel, instead of --spp: a
    /// shard of a render, to be joined with the others by `facet merge` (docs/farm.md).
    /// B at most 2^30, B − A at most 2^20.
    #[arg(long, value_name = "A..B", value_parser = crate::args::sample_range, conflicts_with = "spp")]
    pub samples: Option<std::ops::Range<u32>>,
    /// Bounces after the camera ray, 0 to 64.
    #[arg(long, default_value_t = 5, value_parser = crate::args::depth)]
    pub max_depth: u32,
    /// Seed of the per-pixel random numbers, 0 to 2^32 − 1 (the shards of one render share it).
    #[arg(long, default_value_t = 0, value_parser = crate::args::seed)]
    pub seed: u32,
    /// Stop after the pass during which this many seconds have passed (positive).
    #[arg(long, value_name = "SECONDS", value_parser = crate::args::seconds)]
    pub time_limit: Option<f64>,
    /// PNG exposure in stops, -64 to 64 (the EXR is always linear).
    #[arg(long, default_value_t = 0.0, value_parser = crate::args::stops)]
    pub exposure: f32,
    /// Camera by index or name (default: the first perspective camera).
    #[arg(long)]
    pub camera: Option<String>,
    /// Neural proxy file for `nbrdf:` measurements (default: `$FACET_NBRDF`, else the
    /// embedded MERL-100), as every command resolves `nbrdf:`.
    #[arg(long, value_name = "FILE")]
    pub nbrdf: Option<PathBuf>,
    /// Give the glTF material NAME a fit or a measurement (repeatable): NAME=FILE. A fit
    /// `.json` is rendered by its model; a measurement (a MERL `.binary`, an RGL `.bsdf`,
    /// `nbrdf:NAME`) is rendered as measured, a MERL-grid one sampled by a fit made before the
    /// render (shown with its time).
    #[arg(long = "material", value_name = "NAME=FILE")]
    pub materials: Vec<String>,
    /// Paths in flight at once, 64 to 2^24.
    #[arg(long, default_value_t = 1 << 20, value_parser = crate::args::wavefront)]
    pub wavefront: u32,
    /// BVH build preset.
    #[arg(long, value_enum, default_value_t = PresetArg::Medium)]
    pub bvh: PresetArg,
    /// Count flakes everywhere (no mean above the glint threshold): slow, for comparison.
    #[arg(long)]
    pub no_glint_filter: bool,
    /// Also write each pixel's variance (of its mean, linear RGB) as STEM.variance.exr.
    #[arg(long)]
    pub variance: bool,
    /// How next-event estimation picks a light: bvh (per shading point, by a light BVH over the
    /// point and spot lights and emissive triangles), robust (one distribution for the scene:
    /// ½ by what each light gives the camera's view, ½ uniform) or power (by emitted power).
    #[arg(long, value_enum, default_value_t = SelectionArg::Bvh)]
    pub light_selection: SelectionArg,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SelectionArg {
    Bvh,
    Robust,
    Power,
}

impl SelectionArg {
    fn selection(self) -> LightSelection {
        match self {
            SelectionArg::Bvh => LightSelection::Bvh,
            SelectionArg::Robust => LightSelection::Robust,
            SelectionArg::Power => LightSelection::Power,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PresetArg {
    Fastest,
    VeryFast,
    Fast,
    Medium,
    Slow,
    VerySlow,
}

impl PresetArg {
    fn preset(self) -> BvhPreset {
        match self {
            PresetArg::Fastest => BvhPreset::Fastest,
            PresetArg::VeryFast => BvhPreset::VeryFast,
            PresetArg::Fast => BvhPreset::Fast,
            PresetArg::Medium => BvhPreset::Medium,
            PresetArg::Slow => BvhPreset::Slow,
            PresetArg::VerySlow => BvhPreset::VerySlow,
        }
    }
}

fn parse_rgb(s: &str) -> Result<Vec3> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--env-color {s:?}: expected r,g,b or one number"))?;
    let c = match v.as_slice() {
        [x] => Vec3::splat(*x),
        [r, g, b] => Vec3::new(*r, *g, *b),
        _ => bail!("--env-color {s:?}: expected r,g,b or one number"),
    };
    if !c.is_finite() || c.min_element() < 0.0 {
        bail!("--env-color {s:?}: values must be finite and non-negative");
    }
    Ok(c)
}

/// The two outputs of `--out`: (png, exr).
pub fn outputs(out: &Path) -> (PathBuf, PathBuf) {
    (out.with_extension("png"), out.with_extension("exr"))
}

/// The variance output of `--out --variance`: STEM.variance.exr.
pub fn variance_output(out: &Path) -> PathBuf {
    out.with_extension("variance.exr")
}

/// Everything a render needs, loaded and checked before the GPU is touched.
pub struct Job {
    pub scene: facet_render::scene::Scene,
    pub environment: Option<Environment>,
    pub config: RenderConfig,
    pub resources: ResourceConfig,
    /// Write STEM.variance.exr too.
    pub variance: bool,
    /// The sample indices to render: --samples, or 0..--spp.
    pub samples: std::ops::Range<u32>,
    /// The scene's files and the settings that decide the image, digested: written in the
    /// EXRs so that `facet merge` joins only parts of one render.
    pub digest: String,
}

pub fn prepare(args: &RenderArgs) -> Result<Job> {
    let (range, spp_flag) = match &args.samples {
        Some(r) => (
            r.clone(),
            format!("--samples {}..{} ({} spp)", r.start, r.end, r.len()),
        ),
        None => (0..args.spp, format!("--spp {}", args.spp)),
    };
    let spp = range.len() as u32;
    let samples = args.width as u64 * args.height as u64 * spp as u64;
    if samples > crate::args::MAX_SAMPLES {
        bail!(
            "--width {} × --height {} × {spp_flag} = {samples} samples; a render takes at most 2^40",
            args.width,
            args.height,
        );
    }
    let mut materials = Vec::new();
    for m in &args.materials {
        let (name, file) = m
            .split_once('=')
            .with_context(|| format!("--material {m:?}: expected NAME=FILE"))?;
        materials.push((name.to_owned(), PathBuf::from(file)));
    }
    let options = LoadOptions {
        camera: args.camera.clone(),
        materials,
        nbrdf: args.nbrdf.clone(),
    };
    let mut scene = load_gltf(&args.scene, &options)?;
    // Every file the scene read (the scene, its buffers, textures, fits and measurements, the
    // proxy file `nbrdf:` resolves in) and the environment: no output may replace one of them.
    let inputs: Vec<&Path> = std::iter::once(args.scene.as_path())
        .chain(args.env.as_deref())
        .chain(scene.inputs.iter().map(|r| r.path.as_path()))
        .collect();
    let (png, exr) = outputs(&args.out);
    // The folder is made (or refused) now, not after the render.
    if let Some(dir) = png.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::output::folder(dir, "--out")?;
    }
    let variance = args.variance.then(|| variance_output(&args.out));
    for o in [Some(&png), Some(&exr), variance.as_ref()]
        .into_iter()
        .flatten()
    {
        if let Some(i) = inputs.iter().find(|i| same_file(i, o)) {
            bail!(
                "{}: the output would replace the input {}; choose another --out",
                o.display(),
                i.display()
            );
        }
    }
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    // The shards' digest is made of the bytes the loaders read, hashed as they read them.
    let mut read = scene.inputs.clone();
    let environment = match (&args.env, &args.env_color) {
        (Some(path), _) => {
            let (map, env_read) = input::recording(|| EnvironmentMap::load(path));
            let (map, warnings) = map?;
            read.extend(env_read);
            for w in warnings {
                eprintln!("warning: {w}");
            }
            Some(Environment::Map(std::sync::Arc::new(map)))
        }
        (None, Some(c)) => Some(Environment::Constant(parse_rgb(c)?)),
        (None, None) => None,
    };
    let config = RenderConfig {
        image: ImageConfig {
            width: args.width,
            height: args.height,
            wavefront: args.wavefront,
        },
        sampling: SampleConfig {
            spp,
            max_depth: args.max_depth,
            seed: args.seed,
            time_limit: args.time_limit,
            ..SampleConfig::standard()
        },
    };
    let resources = ResourceConfig {
        bvh: BvhConfig {
            preset: args.bvh.preset(),
        },
        glint_filter: !args.no_glint_filter,
        light_selection: args.light_selection.selection(),
        ..ResourceConfig::standard()
    };
    let digest = digest::digest(args, &read);
    fit_measured(&mut scene)?;
    Ok(Job {
        scene,
        environment,
        config,
        resources,
        variance: args.variance,
        samples: range,
        digest,
    })
}

/// Timings of one render, ms.
pub struct Timings {
    pub resources: f64,
    pub pipelines: f64,
    pub render: f64,
    pub stats: facet_render::RenderStats,
    pub built: facet_render::Built,
}

/// The renderer's adapter (FACET_BACKEND / FACET_ADAPTER choose it), with a hint when none.
pub fn open_gpu() -> Result<facet_gpu::Gpu> {
    facet_gpu::Gpu::new().context(
        "the renderer needs a GPU adapter (any wgpu adapter works; on Linux without a GPU, \
         `apt-get install mesa-vulkan-drivers libvulkan1` gives the lavapipe software adapter)",
    )
}

/// Renders a job on `gpu` and writes both outputs.
pub fn render_job(gpu: &facet_gpu::Gpu, job: &Job, out: &Path, exposure: f32) -> Result<Timings> {
    println!("adapter: {}", gpu.describe());
    let t = std::time::Instant::now();
    let res = SceneResources::new(gpu, &job.scene, job.environment.as_ref(), job.resources)?;
    let resources = t.elapsed().as_secs_f64() * 1e3;
    if let Some(why) = &res.built.light_tree_fallback {
        eprintln!("notice: {why}");
    }
    let t = std::time::Instant::now();
    let integrator = Integrator::new(&gpu.device, &res)?;
    let pipelines = t.elapsed().as_secs_f64() * 1e3;
    let camera = CameraFrame::new(&job.scene.camera)?;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed} (eta {eta})")
            .expect("static template"),
    );
    let c = &job.config;
    let mut wf = if job.variance {
        integrator.wavefront_with_variance(gpu, &res, c.image)?
    } else {
        integrator.wavefront(gpu, &res, c.image)?
    };
    wf.start_at(gpu, job.samples.start);
    let stats = integrator.render_more(gpu, &mut wf, &camera, &c.sampling, &mut |f| {
        bar.set_position((f * 1000.0) as u64)
    })?;
    let image = wf.image(gpu)?;
    bar.finish_and_clear();
    let record = |pixels| {
        ShardRecord::new(
            pixels,
            wf.sample_range(),
            c.sampling.seed,
            job.digest.clone(),
            digest::VERSION.into(),
        )
    };
    let (png, exr) = outputs(out);
    image.write_png(&png, exposure)?;
    image.write_shard_exr(&exr, &record(PixelKind::Mean))?;
    println!("wrote {} and {}", png.display(), exr.display());
    if let Some(var) = wf.variance(gpu)? {
        let path = variance_output(out);
        var.write_shard_exr(&path, &record(PixelKind::VarianceOfMean))?;
        let mean = var.mean();
        println!(
            "wrote {} (mean variance of a pixel {:.3e} {:.3e} {:.3e})",
            path.display(),
            mean[0],
            mean[1],
            mean[2]
        );
    }
    Ok(Timings {
        resources,
        pipelines,
        render: stats.ms,
        stats,
        built: res.built.clone(),
    })
}

pub fn print_timings(t: &Timings, triangles: usize) {
    let b = &t.built;
    let tree = if b.light_tree_nodes > 0 {
        format!(
            " (light BVH {} nodes in {:.0} ms, asked {:.0} % of the time)",
            b.light_tree_nodes,
            b.light_tree_ms,
            100.0 * b.light_tree_share
        )
    } else {
        String::new()
    };
    println!(
        "scene: {} triangles, BVH {} nodes in {:.0} ms; classes {:?}; glint pyramids {:?} in {:.0} ms; {} lights{tree}",
        triangles,
        b.bvh_nodes,
        b.bvh_build_ms,
        b.classes,
        b.glint_pyramids,
        b.glint_build_ms,
        b.lights
    );
    println!(
        "timings (ms): resources {:.0}, pipelines {:.0}, render {:.0} ({} spp, {} iterations, {:.2} Msamples/s)",
        t.resources,
        t.pipelines,
        t.render,
        t.stats.spp,
        t.stats.iterations,
        t.stats.samples as f64 / (t.render * 1e3)
    );
}

pub fn run(args: &RenderArgs) -> Result<ExitCode> {
    let job = prepare(args)?;
    let gpu = open_gpu()?;
    let timings = render_job(&gpu, &job, &args.out, args.exposure)?;
    print_timings(&timings, job.scene.indices.len());
    Ok(ExitCode::SUCCESS)
}

/// Fits the sampling NDF of each MERL-grid measurement the scene names without a fit, once per
/// source, as a step of its own shown with its time (loading never fits). The fit only samples
/// the measurement: a single layer, no coat searched.
fn fit_measured(scene: &mut Scene) -> Result<()> {
    scene.fit_measured(|source, brdf| {
        let t = Instant::now();
        let fit = facet_fit::fit_material(brdf, source, &facet_fit::FitConfig::SINGLE_LAYER);
        println!(
            "fitted the sampling NDF of {} (no fit named beside it) in {:.2} s",
            source.escape_debug(),
            t.elapsed().as_secs_f64()
        );
        fit
    })?;
    Ok(())
}
