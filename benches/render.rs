//! The wavefront integrator end to end (`cargo bench --bench render`):
//! - `integrator/<n>`: Msamples/s (criterion's elements/s) at depth 5 with next-event estimation
//!   (a directional light and a constant sky), procedural scenes of 10^4, 10^5, 10^6 triangles
//!   (`FACET_RENDER_SCENES=1e4,1e5` picks them), 128 × 128 at 1 spp per sample;
//! - `glints/<variant>`: the demo scene with its glint sphere as the smooth GGX model, as glints
//!   with the filter, and as glints counted everywhere, at equal spp;
//! - printed once before those: run time and RMSE against a 256 spp reference as spp grows, for
//!   the demo scene (`FACET_RENDER_RMSE=0` skips it).
//!
//! The scenes are facet-bench's, which `facet bench`'s integrator section renders too.

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use facet_bench::Assets;
use facet_bench::scenes::{demo_scene, lit_procedural_scene};
use facet_bench::sizes::triangles_from_env;
use facet_gpu::Gpu;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Environment, Scene};
use facet_render::{
    Image, ImageConfig, Integrator, RenderConfig, ResourceConfig, SampleConfig, SceneResources,
};
use glam::Vec3;
use std::path::Path;
use std::time::{Duration, Instant};

struct Prepared {
    res: SceneResources,
    integrator: Integrator,
    camera: CameraFrame,
}

fn prepare(gpu: &Gpu, scene: &Scene, env: &Environment, rc: ResourceConfig) -> Prepared {
    let res = SceneResources::new(gpu, scene, Some(env), rc).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    Prepared {
        res,
        integrator,
        camera: CameraFrame::new(&scene.camera).unwrap(),
    }
}

fn render(gpu: &Gpu, p: &Prepared, config: &RenderConfig) -> Image {
    p.integrator
        .render(gpu, &p.res, &p.camera, config, &mut |_| {})
        .unwrap()
        .0
}

/// The demo scene and sky, glints on or off (facet-bench's, as `facet bench` renders it).
fn demo(glints: bool) -> (Scene, Environment) {
    let assets = Assets::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets"));
    demo_scene(&assets, glints).expect("the demo scene")
}

fn rmse_against_spp(gpu: &Gpu) {
    let (scene, env) = demo(true);
    let p = prepare(gpu, &scene, &env, ResourceConfig::standard());
    let base = RenderConfig {
        image: ImageConfig {
            width: 160,
            height: 90,
            ..ImageConfig::standard()
        },
        sampling: SampleConfig::standard(),
    };
    let reference = render(
        gpu,
        &p,
        &RenderConfig {
            sampling: SampleConfig {
                spp: 256,
                seed: 999,
                spp_per_pass: 16,
                ..base.sampling
            },
            ..base
        },
    );
    println!("demo scene 160×90, RMSE against 256 spp (another seed):");
    println!("  spp      ms     RMSE");
    for spp in [1, 2, 4, 8, 16, 32, 64] {
        let t = Instant::now();
        let sampling = SampleConfig {
            spp,
            ..base.sampling
        };
        let img = render(gpu, &p, &RenderConfig { sampling, ..base });
        println!(
            "  {spp:>3} {:>7.0} {:>8.4}",
            t.elapsed().as_secs_f64() * 1e3,
            img.rmse(&reference)
        );
    }
}

fn bench(c: &mut Criterion) {
    let Some(gpu) = facet_gpu::gpu_for_tests("bench render") else {
        return;
    };
    println!("adapter: {}", gpu.describe());
    if std::env::var("FACET_RENDER_RMSE").as_deref() != Ok("0") {
        rmse_against_spp(&gpu);
    }
    let sky = Environment::Constant(Vec3::new(0.4, 0.5, 0.7));
    let mut g = c.benchmark_group("integrator");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10));
    let config = RenderConfig {
        image: ImageConfig {
            width: 128,
            height: 128,
            ..ImageConfig::standard()
        },
        sampling: SampleConfig {
            spp: 1,
            max_depth: 5,
            ..SampleConfig::standard()
        },
    };
    g.throughput(Throughput::Elements(128 * 128));
    for n in triangles_from_env("FACET_RENDER_SCENES", &[10_000, 100_000, 1_000_000]) {
        let scene = lit_procedural_scene(n);
        let p = prepare(&gpu, &scene, &sky, ResourceConfig::standard());
        println!(
            "{} triangles: BVH {:.0} ms",
            scene.indices.len(),
            p.res.built.bvh_build_ms
        );
        g.bench_function(format!("{n}"), |b| b.iter(|| render(&gpu, &p, &config)));
    }
    g.finish();

    let (scene, env) = demo(true);
    let (smooth, _) = demo(false);
    let mut g = c.benchmark_group("glints");
    g.sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10));
    let config = RenderConfig {
        image: ImageConfig {
            width: 240,
            height: 135,
            ..ImageConfig::standard()
        },
        sampling: SampleConfig {
            spp: 2,
            ..SampleConfig::standard()
        },
    };
    g.throughput(Throughput::Elements(240 * 135 * 2));
    let filtered = ResourceConfig::standard();
    let counted = ResourceConfig {
        glint_filter: false,
        ..filtered
    };
    for (name, s, rc) in [
        ("smooth", &smooth, filtered),
        ("filtered", &scene, filtered),
        ("counted", &scene, counted),
    ] {
        let p = prepare(&gpu, s, &env, rc);
        g.bench_function(name, |b| b.iter(|| render(&gpu, &p, &config)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
