//! CPU and GPU side by side: run time against α error for isotropic N up to 1024 and
//! anisotropic grids up to 128×256 directions; kernel throughput from GPU timestamps.
//!
//! `cargo bench --bench gpu_fit`. Without an adapter it prints why and measures nothing.
//! One-shot figures (the largest grid, throughput) go to stderr.

use criterion::{Criterion, criterion_group, criterion_main};
use facet_fit::extract::{CpuSolver, ExtractConfig, Solver, build_problem, extract_with};
use facet_fit::fitting::params::fit_moments;
use facet_fit::fitting::{Backend, FitConfig, fit_material_on};
use facet_fit::gpu::GpuFitter;
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::microfacet::NdfKind;
use facet_gpu::Gpu;
use std::time::{Duration, Instant};

fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => {
            eprintln!("adapter: {}", g.describe());
            Some(g)
        }
        Err(e) => {
            eprintln!("gpu_fit benchmarks skipped: {e}");
            None
        }
    }
}

fn isotropic(c: &mut Criterion) {
    let Some(gpu) = gpu() else { return };
    let fitter = GpuFitter::new(&gpu).unwrap();
    let src = facet_bench::scenes::analytic_table("ggx?alpha=0.2&f0=0.04").unwrap();
    let mut g = c.benchmark_group("iso");
    g.sample_size(10);
    for n in [32, 64, 90, 128, 256, 1024] {
        let cfg = ExtractConfig {
            resolution: n,
            ..ExtractConfig::isotropic()
        };
        for (label, solver) in [
            ("cpu", &CpuSolver as &dyn Solver),
            ("gpu", &fitter as &dyn Solver),
        ] {
            let ex = extract_with(&src, &cfg, false, solver).unwrap();
            let a = fit_moments(NdfKind::Ggx, &ex.ndf).alpha_x;
            eprintln!(
                "iso/{label}/{n}: α error {:+.4} %, {} iterations",
                (a / 0.2 - 1.0) * 100.0,
                ex.iterations
            );
            g.bench_function(format!("{label}/{n}"), |b| {
                b.iter(|| extract_with(&src, &cfg, false, solver).unwrap())
            });
        }
    }
    let cfg = FitConfig::isotropic();
    g.bench_function("gpu/full_fit_after_load_n90", |b| {
        b.iter(|| fit_material_on(&src, "bench", &cfg, Backend::Gpu(&fitter)).unwrap())
    });
    g.finish();
}

fn anisotropic(c: &mut Criterion) {
    let Some(gpu) = gpu() else { return };
    let fitter = GpuFitter::new(&gpu).unwrap();
    let src = parse_analytic("ggx?alpha_x=0.1&alpha_y=0.3&f0=0.04").unwrap();
    let report = |label: &str, nt: usize, np: usize, solver: &dyn Solver| {
        let cfg = ExtractConfig {
            resolution: nt,
            phi_resolution: np,
            ..ExtractConfig::anisotropic()
        };
        let t = Instant::now();
        let ex = extract_with(&src, &cfg, true, solver).unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let a = fit_moments(NdfKind::Ggx, &ex.ndf);
        eprintln!(
            "aniso/{label}/{nt}x{np}: {ms:.0} ms (one run), α = ({:.4}, {:.4}), error ({:+.3} %, {:+.3} %), {} iterations",
            a.alpha_x,
            a.alpha_y,
            (a.alpha_x / 0.1 - 1.0) * 100.0,
            (a.alpha_y / 0.3 - 1.0) * 100.0,
            ex.iterations
        );
        cfg
    };
    let mut g = c.benchmark_group("aniso");
    g.sample_size(10);
    for (nt, np) in [(32, 64), (64, 64), (64, 128)] {
        for (label, solver) in [
            ("cpu", &CpuSolver as &dyn Solver),
            ("gpu", &fitter as &dyn Solver),
        ] {
            let cfg = report(label, nt, np, solver);
            g.bench_function(format!("{label}/{nt}x{np}"), |b| {
                b.iter(|| extract_with(&src, &cfg, true, solver).unwrap())
            });
        }
    }
    g.finish();
    // The largest grid, 32768 unknowns: one run each.
    report("cpu", 128, 256, &CpuSolver);
    report("gpu", 128, 256, &fitter);
    // Kernel throughput from GPU timestamps: one K·v product.
    for (label, nt, np, aniso, flops) in [
        ("aniso 128x256", 128, 256, true, 7.0),
        ("iso 1024", 1024, 1, false, 30.0),
    ] {
        let cfg = ExtractConfig {
            resolution: nt,
            phi_resolution: np,
            ..ExtractConfig::anisotropic()
        };
        let p = build_problem(&src, &cfg, aniso).unwrap();
        let n = p.dirs.len() as f64;
        match fitter.power.time_kernel(&gpu, &p, 5).unwrap() {
            Some(ms) => eprintln!(
                "kernel {label}: {ms:.3} ms per K·v, {:.2} Gpairs/s, {:.1} GFLOP/s at {flops} flops per pair",
                n * n / ms * 1e-6,
                n * n * flops / ms * 1e-6
            ),
            None => eprintln!("kernel {label}: no timestamp queries on this adapter"),
        }
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    targets = isotropic, anisotropic
}
criterion_main!(benches);
