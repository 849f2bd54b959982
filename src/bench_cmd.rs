//! `facet bench`: every speed figure of Facet in one process, on the adapter chosen as
//! elsewhere (FACET_BACKEND, FACET_ADAPTER): the fitter (CPU and GPU backends), ray tracing,
//! the integrator with and without glints and its stages, the DPF build, the viewer's preview
//! path, and what a shard process costs besides its work. Prints a table and writes JSON
//! (`--json FILE`). Timings are medians of repeated runs after a warm-up, measured side by side
//! in this one process (the shard section times processes of this binary that it starts).

use crate::demo_cmd::demo_assets;
use crate::fit_cmd::DEFAULT_MATERIAL;
use anyhow::{Context, Result, bail};
use clap::{Parser, ValueEnum};
use facet_fit::extract::ExtractConfig;
use facet_fit::fitting::{Backend, FitConfig, Models, fit_material_on};
use facet_fit::gpu::GpuFitter;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_gpu::Gpu;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Environment, EnvironmentMap, LoadOptions, Material, Scene, load_gltf};
use facet_render::{ImageConfig, Integrator, ResourceConfig, SampleConfig, SceneResources};
use glam::Vec3;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

mod coat;
mod lights;
mod measured;
mod shard;
mod trace;

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

/// The sizes of one mode.
#[derive(Clone, Copy, Debug)]
struct Sizes {
    /// Timed runs after one warm-up (1: no warm-up).
    runs: usize,
    /// The same for the anisotropic extraction, whose default size is the slowest case.
    aniso_runs: usize,
    fit_resolution: usize,
    aniso: (usize, usize),
    triangles: &'static [usize],
    rays: u32,
    render: (u32, u32, u32),
    stage_warm: u32,
    viewer: (u32, u32),
    /// Side and spp of the noise renders.
    noise: (u32, u32),
    /// The shard processes' size (None: the demo's) and samples per shard.
    shard: (Option<(u32, u32)>, &'static [u32]),
    /// Side and spp of the light-selection renders, and emissive triangles of the tree builds.
    lights: (u32, u32, &'static [usize]),
}

impl Mode {
    const fn sizes(self) -> Sizes {
        match self {
            Mode::Smoke => Sizes {
                runs: 1,
                aniso_runs: 1,
                fit_resolution: 24,
                aniso: (8, 16),
                triangles: &[1_000],
                rays: 1 << 12,
                render: (64, 36, 1),
                stage_warm: 2,
                viewer: (64, 3),
                noise: (32, 2),
                shard: (Some((64, 36)), &[1, 2]),
                lights: (32, 2, &[1_000]),
            },
            Mode::Quick => Sizes {
                runs: 5,
                aniso_runs: 3,
                fit_resolution: 90,
                aniso: (32, 64),
                triangles: &[10_000, 100_000, 1_000_000],
                rays: 1 << 17,
                render: (480, 270, 2),
                stage_warm: 4,
                viewer: (512, 5),
                noise: (128, 16),
                shard: (None, &[1, 4, 16]),
                lights: (128, 16, &[10_000, 1_000_000]),
            },
            Mode::Default => Sizes {
                runs: 5,
                aniso_runs: 3,
                fit_resolution: 90,
                aniso: (128, 256),
                triangles: &[10_000, 100_000, 1_000_000],
                rays: 1 << 21,
                render: (1920, 1080, 8),
                stage_warm: 6,
                viewer: (512, 60),
                noise: (256, 64),
                shard: (None, &[1, 16, 64, 256]),
                lights: (256, 64, &[10_000, 1_000_000]),
            },
            Mode::Full => Sizes {
                triangles: &[10_000, 100_000, 1_000_000, 10_000_000],
                ..Mode::Default.sizes()
            },
        }
    }
}

/// Median of `runs` timed calls of `f` (ms) after one untimed call when runs > 1.
fn median_ms(runs: usize, mut f: impl FnMut() -> Result<()>) -> Result<f64> {
    if runs > 1 {
        f()?;
    }
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let s = Instant::now();
            f().map(|_| s.elapsed().as_secs_f64() * 1e3)
        })
        .collect::<Result<_>>()?;
    Ok(median(&mut t))
}

/// The median of `t` (sorts it).
fn median(t: &mut [f64]) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// Now as ISO 8601 UTC (days to civil date: Hinnant's algorithm).
fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
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
    let mut report = json!({
        "facet_bench": 1,
        "mode": format!("{mode:?}").to_lowercase(),
        "commit": env!("FACET_COMMIT"),
        "date": utc_now(),
    });
    println!(
        "facet bench ({}), commit {}, {}",
        report["mode"].as_str().unwrap_or(""),
        env!("FACET_COMMIT"),
        report["date"].as_str().unwrap_or("")
    );
    if let Some(g) = &gpu {
        let info = g.adapter.get_info();
        let l = g.device.limits();
        report["adapter"] = json!({
            "name": info.name, "backend": format!("{:?}", info.backend),
            "device_type": format!("{:?}", info.device_type),
            "driver": info.driver, "driver_info": info.driver_info,
            "timestamps": g.device.features().contains(wgpu::Features::TIMESTAMP_QUERY),
        });
        report["limits_requested"] = json!({
            "max_storage_buffer_binding_size": l.max_storage_buffer_binding_size,
            "max_buffer_size": l.max_buffer_size,
            "max_compute_workgroups_per_dimension": l.max_compute_workgroups_per_dimension,
            "max_compute_invocations_per_workgroup": l.max_compute_invocations_per_workgroup,
            "max_texture_dimension_3d": l.max_texture_dimension_3d,
        });
        println!(
            "adapter: {} ({:?}, {:?}), driver {} {}",
            info.name, info.backend, info.device_type, info.driver, info.driver_info
        );
    }
    let on = |s: Section| args.only.is_empty() || args.only.contains(&s);
    if on(Section::Fit) {
        report["fit"] = fit(gpu.as_ref(), &sizes)?;
    }
    if let Some(g) = &gpu {
        if on(Section::Trace) {
            report["trace"] = trace::trace(g, &sizes)?;
        }
        if on(Section::Integrator) {
            let (integrator, stages, glint) = integrator(g, &sizes)?;
            report["integrator"] = integrator;
            report["stages"] = stages;
            report["glint"] = glint;
        }
        if on(Section::Viewer) {
            report["viewer"] = viewer(g, &sizes)?;
        }
        if on(Section::Noise) {
            report["noise"] = noise(g, &sizes)?;
        }
        if on(Section::Dpf) {
            report["dpf"] = dpf_pyramid(g, mode, &sizes)?;
        }
        if on(Section::Lights) {
            report["lights"] = lights::lights(g, &sizes)?;
        }
        if on(Section::Measured) {
            report["measured"] = measured::measured(g, sizes.noise.0, sizes.noise.1)?;
        }
        if on(Section::Coat) {
            report["coat"] = coat::coat(g, sizes.noise.0, sizes.noise.1)?;
        }
        if on(Section::Shard) {
            report["shard"] = shard::shards(sizes.runs, sizes.shard.0, sizes.shard.1)?;
        }
    }
    report["total_s"] = json!(t0.elapsed().as_secs_f64());
    println!("bench total {:.1} s", t0.elapsed().as_secs_f64());
    if let Some(path) = &args.json {
        std::fs::write(path, serde_json::to_string_pretty(&report)? + "\n")
            .with_context(|| format!("{}: writing the bench JSON", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The nine-level DPF pyramid on the GPU with the direct cone rule (the previous fixed one) and
/// the fast rule (sized to the lobe), median build times side by side, and the fast tables'
/// relative error against the direct ones per level: max and median over the cells above 1 % of
/// the level's peak where the direct rule is converged (cone above the horizon, θo + γ ≤ 85°,
/// θi ≤ 60°; `fast_cone_rule_matches_the_direct_integral` in crates/glint/tests/glint.rs says why), and the
/// max over all cells above 1 % of the peak.
fn dpf_pyramid(gpu: &Gpu, mode: Mode, sizes: &Sizes) -> Result<Value> {
    use facet_fit::model::microfacet::{AnalyticNdf, Ndf, NdfKind};
    use facet_glint::cone_rule::ConeRule;
    use facet_glint::dpf::{DpfConfig, DpfTable, LEVELS_DEG};
    let cfg = if mode == Mode::Smoke {
        DpfConfig::preview()
    } else {
        DpfConfig::standard()
    };
    let all: Vec<usize> = (0..LEVELS_DEG.len()).collect();
    let runs = sizes.runs.min(3);
    let mut rows = Vec::new();
    println!(
        "DPF pyramid, nine levels, {}×{}×{} cells, GPU:",
        cfg.n_theta, cfg.n_theta, cfg.n_dphi
    );
    for (name, kind, alpha) in [
        ("beckmann 0.1", NdfKind::Beckmann, 0.1),
        ("ggx 0.15", NdfKind::Ggx, 0.15),
        ("ggx 0.05", NdfKind::Ggx, 0.05),
    ] {
        let ndf = Ndf::Analytic(AnalyticNdf::isotropic(kind, alpha));
        let build = |rule: &ConeRule| {
            facet_glint::gpu::build_levels_with(gpu, &ndf, cfg, &all, rule)
                .context("building the DPF pyramid on the GPU")
        };
        let direct_ms = median_ms(runs, || build(&ConeRule::direct()).map(|_| ()))?;
        let fast_ms = median_ms(runs, || build(&ConeRule::fast()).map(|_| ()))?;
        let (direct, fast) = (build(&ConeRule::direct())?, build(&ConeRule::fast())?);
        let mut levels = Vec::new();
        let mut line = String::new();
        for (d, f) in direct
            .pyramid
            .levels
            .iter()
            .flatten()
            .zip(fast.pyramid.levels.iter().flatten())
        {
            let peak = d.values.iter().cloned().fold(0.0f32, f32::max) as f64;
            let (mut trusted, mut any) = (Vec::new(), 0.0f64);
            for (k, (a, b)) in f.values.iter().zip(&d.values).enumerate() {
                let (a, b) = (*a as f64, *b as f64);
                if b <= 1e-2 * peak {
                    continue;
                }
                let e = (a / b - 1.0).abs();
                any = any.max(e);
                let (o, i) = (k / (cfg.n_theta * cfg.n_dphi), k / cfg.n_dphi % cfg.n_theta);
                let (to, ti, _) = DpfTable::cell_centre(cfg, o, i, 0);
                if (to + d.gamma).to_degrees() <= 85.0 && ti.to_degrees() <= 60.0 {
                    trusted.push(e);
                }
            }
            let max = trusted.iter().cloned().fold(0.0, f64::max);
            let med = if trusted.is_empty() {
                0.0
            } else {
                median(&mut trusted)
            };
            let deg = d.gamma.to_degrees();
            line += &format!(" {deg:.0}°: {max:.1e}/{med:.0e}");
            levels.push(json!({"gamma_deg": deg, "max_rel": max, "median_rel": med, "cells": trusted.len(), "max_rel_all_cells": any}));
        }
        println!(
            "  {name}: direct rule {direct_ms:.0} ms, fast rule {fast_ms:.0} ms ({:.1}× faster)",
            direct_ms / fast_ms
        );
        println!("    fast vs direct, max/median relative error per level:{line}");
        rows.push(json!({"ndf": name, "n_theta": cfg.n_theta, "n_dphi": cfg.n_dphi, "direct_ms": direct_ms, "fast_ms": fast_ms, "speedup": direct_ms / fast_ms, "levels": levels}));
    }
    Ok(Value::Array(rows))
}

/// The default material (a gold GGX conductor) as an in-memory MERL table.
fn fit_source() -> Result<MerlBrdf> {
    let model = facet_fit::model::analytic::parse_analytic(DEFAULT_MATERIAL)
        .map_err(|e| anyhow::anyhow!("{DEFAULT_MATERIAL}: {e}"))?;
    MerlBrdf::from_table(DEFAULT_MATERIAL, MerlTable::sample(&model))
        .map_err(|e| anyhow::anyhow!("{DEFAULT_MATERIAL}: {e}"))
}

fn fit(gpu: Option<&Gpu>, sizes: &Sizes) -> Result<Value> {
    let src = fit_source()?;
    let fitter = gpu
        .map(GpuFitter::new)
        .transpose()
        .context("GPU fit pipelines")?;
    let iso = FitConfig {
        extract: ExtractConfig {
            resolution: sizes.fit_resolution,
            ..ExtractConfig::isotropic()
        },
        ..FitConfig::isotropic()
    };
    let tabulated_only = FitConfig {
        models: Models {
            tabulated: true,
            ggx: false,
            beckmann: false,
        },
        ..iso
    };
    let (nt, np) = sizes.aniso;
    let aniso = FitConfig {
        extract: ExtractConfig {
            resolution: nt,
            phi_resolution: np,
            ..ExtractConfig::anisotropic()
        },
        models: Models::NONE,
        ..FitConfig::anisotropic()
    };
    let n = sizes.fit_resolution;
    let cases = [
        (format!("isotropic N = {n}, all models"), iso, sizes.runs),
        (
            format!("isotropic N = {n}, tabulated only"),
            tabulated_only,
            sizes.runs,
        ),
        (
            format!("anisotropic {nt} × {np} extraction"),
            aniso,
            sizes.aniso_runs,
        ),
    ];
    let mut rows = Vec::new();
    println!(
        "\nfit ({DEFAULT_MATERIAL} as a MERL table), ms per material, median of the runs after a warm-up"
    );
    for (label, cfg, runs) in &cases {
        let mut backends = vec![("cpu", Backend::Cpu)];
        if let Some(f) = &fitter {
            backends.push(("gpu", Backend::Gpu(f)));
        }
        for (name, backend) in backends {
            let mut used = String::new();
            let ms = median_ms(*runs, || {
                let m = fit_material_on(&src, DEFAULT_MATERIAL, cfg, backend)?;
                used = m.record.backend.clone();
                Ok(())
            })?;
            println!("  {label:<40} {name:<4} {ms:>10.1} ms   ({runs} runs; {used})");
            rows.push(json!({"case": label, "backend": name, "median_ms": ms, "runs": runs, "record_backend": used}));
        }
    }
    Ok(Value::Array(rows))
}

/// The demo scene and sky; with `glints` false the glint sphere renders its smooth GGX model.
/// A `side` × `side` image with a path in flight per pixel.
fn square(side: u32) -> ImageConfig {
    ImageConfig {
        width: side,
        height: side,
        wavefront: side * side,
    }
}

fn demo_scene(glints: bool) -> Result<(Scene, Environment)> {
    let (gltf, sky) = demo_assets();
    let mut scene = load_gltf(&gltf, &LoadOptions::default())?;
    if !glints {
        for m in &mut scene.materials {
            if let Some(f) = &mut m.facet {
                f.glint = None;
            }
        }
    }
    let (map, _) = EnvironmentMap::load(&sky)?;
    Ok((scene, Environment::Map(Arc::new(map))))
}

/// The integrator section's image and sampling: the mode's size and spp, depth 5.
fn demo_render(sizes: &Sizes) -> (ImageConfig, SampleConfig) {
    let (width, height, spp) = sizes.render;
    let image = ImageConfig {
        width,
        height,
        ..ImageConfig::standard()
    };
    let sampling = SampleConfig {
        spp,
        max_depth: 5,
        ..SampleConfig::standard()
    };
    (image, sampling)
}

fn integrator(gpu: &Gpu, sizes: &Sizes) -> Result<(Value, Value, Value)> {
    let (w, h, spp) = sizes.render;
    let (image, sampling) = demo_render(sizes);
    let mut rows = Vec::new();
    let mut stages = json!({});
    // Msamples/s without glints, with glints (the filter on), and with the filter off.
    let mut rates = [0.0; 3];
    let mut dpf_ms = 0.0;
    println!(
        "\nintegrator: the demo scene at {w} × {h}, depth 5, {spp} spp a render, median of {}",
        sizes.runs
    );
    let configs = [
        ("without glints", false, true),
        ("with glints", true, true),
        ("glints unfiltered", true, false),
    ];
    for (k, (label, glints, filter)) in configs.into_iter().enumerate() {
        let (scene, env) = demo_scene(glints)?;
        let resources = ResourceConfig {
            glint_filter: filter,
            ..ResourceConfig::standard()
        };
        let res = SceneResources::new(gpu, &scene, Some(&env), resources)?;
        if glints {
            dpf_ms = res.built.glint_build_ms;
        }
        let integrator = Integrator::new(&gpu.device, &res)?;
        let camera = CameraFrame::new(&scene.camera)?;
        let mut wf = integrator.wavefront(gpu, &res, image)?;
        let ms = median_ms(sizes.runs, || {
            wf.clear(gpu);
            integrator.render_more(gpu, &mut wf, &camera, &sampling, &mut |_| {})?;
            Ok(())
        })?;
        let msps = w as f64 * h as f64 * spp as f64 / (ms * 1e3);
        rates[k] = msps;
        println!(
            "  {label:<17} {msps:>10.2} Msamples/s   ({ms:.0} ms a render, {} paths in flight)",
            wf.slots()
        );
        rows.push(json!({"scene": "demo", "glints": glints, "glint_filter": filter, "width": w, "height": h, "spp": spp, "depth": 5, "msamples_per_s": msps, "ms": ms, "slots": wf.slots()}));
        let (times, clock) =
            integrator.profile_iteration(gpu, &mut wf, &camera, &sampling, sizes.stage_warm)?;
        let total: f64 = times.iter().map(|t| t.ms).sum();
        println!("    one iteration by stage ({clock:?}), {total:.3} ms:");
        for t in &times {
            println!(
                "      {:<18} {:>9.3} ms {:>5.1} %",
                t.stage,
                t.ms,
                100.0 * t.ms / total.max(1e-12)
            );
        }
        stages[label.replace(' ', "_")] = json!({
            "clock": format!("{clock:?}").to_lowercase(),
            "iteration_ms": total,
            "stages": times.iter().map(|t| json!({"stage": t.stage, "ms": t.ms})).collect::<Vec<_>>(),
        });
    }
    // Overhead at equal spp: the time a sample takes with glints over the time without, − 1.
    let overhead = 100.0 * (rates[0] / rates[1] - 1.0);
    let unfiltered = 100.0 * (rates[0] / rates[2] - 1.0);
    println!(
        "  glint overhead at equal spp {overhead:+.1} % (filter off {unfiltered:+.1} %); DPF pyramid built in {dpf_ms:.0} ms"
    );
    let glint = json!({"overhead_percent": overhead, "unfiltered_overhead_percent": unfiltered, "dpf_build_ms": dpf_ms});
    Ok((Value::Array(rows), stages, glint))
}

fn viewer(gpu: &Gpu, sizes: &Sizes) -> Result<Value> {
    let (side, frames) = sizes.viewer;
    let fit = facet_fit::FittedMaterial::load(&demo_assets().0.with_file_name("default_fit.json"))?;
    let sphere = Material {
        name: "preview".into(),
        facet: Some(facet_render::scene::FacetMaterial {
            source: "default_fit.json".into(),
            fit: Arc::new(fit),
            model: facet_fit::model::material::ModelChoice::Ggx,
            glint: None,
        }),
        ..Default::default()
    };
    let scene = facet_render::scene::sphere::SphereScene::PREVIEW.build(sphere);
    let (_, env) = demo_scene(false)?;
    let res = SceneResources::new(gpu, &scene, Some(&env), ResourceConfig::standard())?;
    let integrator = Integrator::new(&gpu.device, &res)?;
    let camera = CameraFrame::new(&scene.camera)?;
    let mut wf = integrator.wavefront(gpu, &res, square(side))?;
    let (mut batch, mut ms_all, mut spp_all) = (1u32, Vec::new(), Vec::new());
    for _ in 0..frames {
        let cfg = SampleConfig {
            spp: batch,
            spp_per_pass: facet_render::integrator::pacing::MAX_SPP_PER_FRAME,
            ..SampleConfig::preview()
        };
        let t = Instant::now();
        integrator.render_more(gpu, &mut wf, &camera, &cfg, &mut |_| {})?;
        let rgba = wf.tone_mapped(gpu, 0.0)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        if rgba.len() != (side * side) as usize {
            bail!("the preview read back {} pixels", rgba.len());
        }
        ms_all.push(ms);
        spp_all.push(batch);
        batch = facet_render::integrator::pacing::next_batch(batch, ms);
    }
    // Steady state: the second half of the frames.
    let half = frames as usize / 2;
    let mut steady: Vec<f64> = ms_all[half..].to_vec();
    steady.sort_by(f64::total_cmp);
    let median = steady[steady.len() / 2];
    let spp_steady: u32 = spp_all[half..].iter().sum();
    let secs: f64 = ms_all[half..].iter().sum::<f64>() / 1e3;
    let msps = (side * side) as f64 * spp_steady as f64 / secs / 1e6;
    let fps = 1e3 / median;
    println!(
        "\nviewer preview path: {side} × {side}, {frames} frames: {median:.1} ms a frame ({fps:.1} frames/s), {} spp a frame at the end, {msps:.2} Msamples/s",
        spp_all.last().copied().unwrap_or(0)
    );
    Ok(
        json!({"width": side, "height": side, "frames": frames, "median_frame_ms": median, "frames_per_s": fps, "spp_per_frame": spp_all.last(), "msamples_per_s": msps, "frame_ms": ms_all}),
    )
}

/// A fit of an analytic GGX gold conductor, as a Facet material rendering its GGX model.
fn gold_ggx(alpha: f64) -> Result<Material> {
    gold_fit(alpha, facet_fit::model::material::ModelChoice::Ggx)
}

/// A fit of gold GGX(α) written as a MERL table, rendered by `model` of the fit.
fn gold_fit(alpha: f64, model: facet_fit::model::material::ModelChoice) -> Result<Material> {
    let spec = format!("ggx?alpha={alpha}&conductor=gold");
    let truth =
        facet_fit::model::analytic::parse_analytic(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
    let src = MerlBrdf::from_table(&spec, MerlTable::sample(&truth))
        .map_err(|e| anyhow::anyhow!("{spec}: {e}"))?;
    let fit = facet_fit::fit_material(&src, &spec, &FitConfig::isotropic())?;
    Ok(Material {
        name: spec.clone(),
        facet: Some(facet_render::scene::FacetMaterial {
            source: spec.into(),
            fit: Arc::new(fit),
            model,
            glint: None,
        }),
        ..Default::default()
    })
}

/// Issue 12's gold scene ([`SphereScene::GOLD`](facet_render::scene::sphere::SphereScene::GOLD):
/// `sphere` on a 20 × 20 grey Lambertian floor, a 40 W/sr point light) under a constant sky of
/// 0.5.
fn gold_scene(sphere: Material) -> Result<(Scene, Environment)> {
    Ok((
        facet_render::scene::sphere::SphereScene::GOLD.build(sphere),
        Environment::Constant(Vec3::splat(0.5)),
    ))
}

/// The noise and speed of one configuration on one scene.
/// `material` on the gold scene's sphere at `side`² and `spp` ([`measure_noise`]), with its
/// time a sample and variance as ratios to the first call's (`first` keeps them): one row of a
/// side-by-side section, as measured, as [time ratio, variance ratio], and as JSON.
pub(crate) fn gold_row(
    gpu: &Gpu,
    material: Material,
    side: u32,
    spp: u32,
    first: &mut Option<(f64, f64)>,
) -> Result<(Measured, [f64; 2], Value)> {
    let (scene, env) = gold_scene(material)?;
    let m = measure_noise(
        gpu,
        &scene,
        Some(&env),
        ResourceConfig::standard(),
        square(side),
        spp,
        facet_render::NdfSampling::Visible,
    )?;
    let (v0, t0) = *first.get_or_insert((m.var, m.ns));
    let ratios = [m.ns / t0, m.var / v0];
    let row = json!({"ns_per_sample": m.ns, "time_ratio": ratios[0], "variance": m.var, "variance_ratio": ratios[1], "mean": m.mean});
    Ok((m, ratios, row))
}

pub(crate) struct Measured {
    /// The variance of a pixel: E[(a − b)²] / 2 over two seeds, averaged over pixels and
    /// channels.
    pub var: f64,
    /// Nanoseconds a sample (median of three renders).
    pub ns: f64,
    /// The mean of both renders' pixels.
    pub mean: f64,
    /// The squared standard error of that mean (pixels independent).
    pub se2: f64,
    /// The two renders (seeds 0 and 1).
    pub images: [facet_render::Image; 2],
}

impl Measured {
    /// The variance of a pixel over the pixels `keep` accepts.
    pub fn variance_where(&self, keep: impl Fn(usize) -> bool) -> f64 {
        let [a, b] = &self.images;
        let (mut sum, mut n) = (0.0, 0usize);
        for (k, (pa, pb)) in a.pixels.iter().zip(&b.pixels).enumerate() {
            if keep(k) {
                sum += (0..3)
                    .map(|c| 0.5 * (pa[c] as f64 - pb[c] as f64).powi(2))
                    .sum::<f64>();
                n += 3;
            }
        }
        sum / n.max(1) as f64
    }
}

/// Renders `scene` at `image` and `spp` (depth 5) with seeds 0, 1 and 2 after an untimed
/// 1-spp render: the variance from the first two, the time a sample the median of the three.
pub(crate) fn measure_noise(
    gpu: &Gpu,
    scene: &Scene,
    env: Option<&Environment>,
    rc: ResourceConfig,
    image: ImageConfig,
    spp: u32,
    ndf_sampling: facet_render::NdfSampling,
) -> Result<Measured> {
    let camera = CameraFrame::new(&scene.camera)?;
    let res = SceneResources::new(gpu, scene, env, rc)?;
    let integrator = Integrator::new(&gpu.device, &res)?;
    let mut wf = integrator.wavefront(gpu, &res, image)?;
    let mut images = Vec::new();
    let mut ms = Vec::new();
    // An untimed render first: the first dispatches of fresh pipelines are slower.
    let warm = SampleConfig {
        spp: 1,
        ndf_sampling,
        ..SampleConfig::standard()
    };
    integrator.render_more(gpu, &mut wf, &camera, &warm, &mut |_| {})?;
    // Seeds 0 and 1 give the variance; seed 2 only a third time for the median.
    for seed in [0, 1, 2] {
        let cfg = SampleConfig {
            spp,
            max_depth: 5,
            seed,
            ndf_sampling,
            ..SampleConfig::standard()
        };
        wf.clear(gpu);
        ms.push(
            integrator
                .render_more(gpu, &mut wf, &camera, &cfg, &mut |_| {})?
                .ms,
        );
        if seed < 2 {
            images.push(wf.image(gpu)?);
        }
    }
    let n = images[0].pixels.len() * 3;
    let var = images[0]
        .pixels
        .iter()
        .flatten()
        .zip(images[1].pixels.iter().flatten())
        .map(|(a, b)| 0.5 * (*a as f64 - *b as f64).powi(2))
        .sum::<f64>()
        / n as f64;
    let ns = median(&mut ms) * 1e6 / (image.width as f64 * image.height as f64 * spp as f64);
    let mean = images
        .iter()
        .flat_map(|im| im.pixels.iter().flatten())
        .map(|v| *v as f64)
        .sum::<f64>()
        / (2 * n) as f64;
    let [a, b]: [facet_render::Image; 2] = images.try_into().expect("two renders");
    Ok(Measured {
        var,
        ns,
        mean,
        se2: var / (2 * n) as f64,
        images: [a, b],
    })
}

/// Noise at equal spp and time per sample, before (D cos θh sampling, selection by flux) and
/// after (visible normals, robust selection), and each change alone, on the gold scene (GGX and
/// the fit's tabulated NDF), the demo and a glossy (α = 0.05) sphere under the sky. The
/// variance of a pixel is estimated from two renders with different seeds: E[(a − b)²] / 2,
/// averaged over pixels and channels; the time a sample is the median of three renders.
fn noise(gpu: &Gpu, sizes: &Sizes) -> Result<Value> {
    use facet_render::{LightSelection, NdfSampling};
    let (side, spp) = sizes.noise;
    let (demo, sky) = demo_scene(true)?;
    let glossy = facet_render::scene::sphere::SphereScene::PREVIEW.build(gold_ggx(0.05)?);
    let tabulated = gold_fit(0.3, facet_fit::model::material::ModelChoice::Tabulated)?;
    let scenes = [
        (
            "gold sphere, sky and point light",
            gold_scene(gold_ggx(0.3)?)?,
        ),
        ("the same, the fit's tabulated NDF", gold_scene(tabulated)?),
        ("demo", (demo, sky.clone())),
        ("glossy GGX α = 0.05 sphere under the sky", (glossy, sky)),
    ];
    let configs = [
        ("before", NdfSampling::DCos, LightSelection::Power),
        (
            "visible normals only",
            NdfSampling::Visible,
            LightSelection::Power,
        ),
        (
            "robust selection only",
            NdfSampling::DCos,
            LightSelection::Robust,
        ),
        ("after", NdfSampling::Visible, LightSelection::Robust),
    ];
    println!("\nnoise: variance per pixel at {spp} spp ({side} × {side}) and time per sample");
    let mut rows = Vec::new();
    for (name, (scene, env)) in &scenes {
        let mut base: Option<(f64, f64, f64, f64)> = None;
        for (label, ndf_sampling, light_selection) in configs {
            let rc = ResourceConfig {
                light_selection,
                ..ResourceConfig::standard()
            };
            let Measured {
                var, ns, mean, se2, ..
            } = measure_noise(gpu, scene, Some(env), rc, square(side), spp, ndf_sampling)?;
            let (v0, t0, m0, s0) = *base.get_or_insert((var, ns, mean, se2));
            // The expected image is the same: the means differ by a few standard errors at most.
            let z = (mean - m0) / (se2 + s0).sqrt().max(1e-30);
            println!(
                "  {name:<42} {label:<22} variance {var:.3e} ({:.2}× before), {ns:.0} ns a sample ({:.2}×), time × variance {:.2}× before; mean {mean:.4} ({z:+.1} σ from before)",
                var / v0,
                ns / t0,
                var * ns / (v0 * t0)
            );
            rows.push(json!({"scene": name, "config": label, "spp": spp, "side": side, "variance": var, "ns_per_sample": ns, "variance_vs_before": var / v0, "time_vs_before": ns / t0, "time_variance_vs_before": var * ns / (v0 * t0), "mean": mean, "mean_z_vs_before": z}));
        }
    }
    Ok(Value::Array(rows))
}
