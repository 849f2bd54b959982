//! Glint benchmarks: DPF pyramid build (CPU and GPU) and its memory, and the cost of one
//! glint query against footprint size, filter on and off.
//!
//! `cargo bench --bench glint`.

use criterion::{Criterion, criterion_group, criterion_main};
use facet_fit::model::microfacet::{AnalyticNdf, Ndf, NdfKind};
use facet_glint::dpf::{DpfConfig, DpfPyramid, dpf};
use facet_glint::flakes::{FlakeField, Footprint};
use facet_glint::glint_brdf::{GlintConfig, glint_count};
use glam::DVec2;
use std::time::{Duration, Instant};

fn ndf() -> Ndf {
    Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Beckmann, 0.1))
}

fn pyramid(c: &mut Criterion) {
    let mut g = c.benchmark_group("dpf_pyramid");
    g.sample_size(10);
    let cfg = DpfConfig::preview();
    g.bench_function("cpu_preview_12x12x24", |b| {
        b.iter(|| DpfPyramid::build(&ndf(), cfg))
    });
    g.finish();
    for cfg in [DpfConfig::preview(), DpfConfig::standard()] {
        let cells = cfg.n_theta * cfg.n_theta * cfg.n_dphi;
        eprintln!(
            "pyramid {}x{}x{}: {} cells per level, {:.2} MiB for nine f32 levels",
            cfg.n_theta,
            cfg.n_theta,
            cfg.n_dphi,
            cells,
            (9 * cells * 4) as f64 / (1 << 20) as f64
        );
        match facet_gpu::Gpu::new() {
            Ok(gpu) => {
                let _ = facet_glint::gpu::build_levels(&gpu, &ndf(), cfg, &[0]).unwrap(); // pipeline warm-up
                let t = Instant::now();
                facet_glint::gpu::build_pyramid(&gpu, &ndf(), cfg).unwrap();
                eprintln!(
                    "  GPU build on {}: {:.0} ms",
                    gpu.describe(),
                    t.elapsed().as_secs_f64() * 1e3
                );
            }
            Err(e) => eprintln!("  GPU build skipped: {e}"),
        }
        if cfg == DpfConfig::standard() {
            let t = Instant::now();
            DpfPyramid::build(&ndf(), cfg);
            eprintln!("  CPU build: {:.0} ms", t.elapsed().as_secs_f64() * 1e3);
        }
    }
}

fn queries(c: &mut Criterion) {
    let field = FlakeField {
        density: 1.0e7,
        seed: 1,
    };
    let (wi, wo) = (
        facet_fit::model::geometry::spherical(0.4, 0.0),
        facet_fit::model::geometry::spherical(0.45, 3.0),
    );
    let gamma = 1f64.to_radians();
    let p = dpf(&ndf(), wi, wo, gamma);
    let mut g = c.benchmark_group("glint_query");
    // About 30, 3000 and 300 000 flakes: r = √(N / (π · density)).
    for r in [9.8e-4, 9.8e-3, 9.8e-2] {
        let fp = Footprint {
            center: DVec2::splat(0.3),
            a: DVec2::new(r, 0.0),
            b: DVec2::new(0.0, r),
        };
        eprintln!(
            "footprint radius {r}: {:.0} flakes, expected lit {:.2}",
            field.density * fp.area(),
            field.density * fp.area() * p
        );
        for filtered in [true, false] {
            let cfg = GlintConfig {
                gamma,
                threshold: 16.0,
                filtered,
                blend: true,
            };
            let label = if filtered { "filtered" } else { "unfiltered" };
            g.bench_function(format!("{label}/r{r}"), |b| {
                b.iter(|| glint_count(&field, &fp, wi, wo, p, &cfg))
            });
        }
    }
    g.finish();
    // GPU evaluation throughput: 10⁵ queries per dispatch, upload and read-back included.
    let Ok(gpu) = facet_gpu::Gpu::new() else {
        return;
    };
    let model_ndf = AnalyticNdf::isotropic(NdfKind::Beckmann, 0.1);
    let levels = facet_glint::gpu::build_levels(&gpu, &ndf(), DpfConfig::preview(), &[0]).unwrap();
    let evaluator = facet_glint::gpu::GlintEvaluator::new(&gpu.device).unwrap();
    let fresnel = facet_fit::model::fresnel::FresnelTable::on_merl_bins(vec![[1.0; 3]; 90]);
    for r in [1e-4, 1e-3, 1e-2] {
        let qs: Vec<_> = (0..100_000)
            .map(|k| {
                let c = DVec2::new(
                    (k as f64 * 0.618_033_988_7).fract(),
                    (k as f64 * 0.414_213_562_4).fract(),
                );
                let fp = Footprint {
                    center: c,
                    a: DVec2::new(r, 0.0),
                    b: DVec2::new(0.0, r),
                };
                facet_glint::gpu::GlintEvalQuery::new(wi, wo, &fp)
            })
            .collect();
        for filtered in [true, false] {
            let cfg = GlintConfig {
                gamma,
                threshold: 16.0,
                filtered,
                blend: true,
            };
            let _ = evaluator
                .eval(
                    &gpu,
                    &field,
                    &cfg,
                    &model_ndf,
                    &fresnel,
                    &levels,
                    &qs[..1000],
                )
                .unwrap();
            let t = Instant::now();
            evaluator
                .eval(&gpu, &field, &cfg, &model_ndf, &fresnel, &levels, &qs)
                .unwrap();
            let s = t.elapsed().as_secs_f64();
            eprintln!(
                "GPU glint eval ({}), radius {r}, filter {}: {:.2} M queries/s",
                gpu.describe(),
                if filtered { "on" } else { "off" },
                1e-1 / s
            );
        }
    }
}

/// The lit-count walk alone on the GPU (`shaders/glint/glint_count.wgsl`), on pairs of queries
/// like a shading point's (a light sample and a BSDF sample): 20 000 pairs over footprints of
/// about 90 flakes (the demo's primary hits), expected lit counts 0.05–5 a query, direction
/// coordinates spread over many cells (so lanes read one, two or four blended cells), filter
/// on and off. One sample is one dispatch with its upload and read-back.
fn gpu_counts(c: &mut Criterion) {
    let Ok(gpu) = facet_gpu::Gpu::new() else {
        eprintln!("no GPU adapter: glint_gpu_count skipped");
        return;
    };
    let counter = facet_glint::gpu::GlintCounter::new(&gpu.device).unwrap();
    let field = FlakeField {
        density: 2.0e6,
        seed: 3,
    };
    let r = (90.0 / (std::f64::consts::PI * field.density)).sqrt();
    let unit = |k: u32, s: u32| facet_glint::tea::tea_unit(k, s) as f64;
    let pairs: Vec<_> = (0..20_000u32)
        .map(|k| {
            let fp = Footprint {
                center: DVec2::new(unit(k, 1), unit(k, 2)),
                a: DVec2::new(r * (0.7 + 0.6 * unit(k, 3)), 0.0),
                b: DVec2::new(0.3 * r * unit(k, 4), r * (0.7 + 0.6 * unit(k, 5))),
            };
            // Expected lit counts N a P from 0.05 to 5, log-uniform, per query.
            let p = [6, 7].map(|s| 0.05 * 100f64.powf(unit(k, s)) / (field.density * fp.area()));
            let coords = [8, 10].map(|s| DVec2::new(64.0 * unit(k, s), 64.0 * unit(k, s + 1)));
            facet_glint::gpu::GlintQuery::pair(&fp, p, coords)
        })
        .collect();
    let mut g = c.benchmark_group("glint_gpu_count");
    g.sample_size(10);
    for filtered in [true, false] {
        let cfg = GlintConfig {
            gamma: 1f64.to_radians(),
            threshold: 16.0,
            filtered,
            blend: true,
        };
        let label = if filtered { "filtered" } else { "unfiltered" };
        g.bench_function(format!("{label}/20000_pairs_90_flakes"), |b| {
            b.iter(|| counter.count(&gpu, &field, &cfg, &pairs).unwrap())
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    targets = pyramid, queries, gpu_counts
}
criterion_main!(benches);
