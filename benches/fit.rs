//! Criterion benchmarks of the fitter: MERL load, full isotropic fit, run time against error
//! over N, anisotropic extraction, one neural-proxy fit.
//!
//! `cargo bench --bench fit`; α errors are printed to stderr beside the timings.

use criterion::{Criterion, criterion_group, criterion_main};
use facet_fit::extract::{ExtractConfig, extract_anisotropic, extract_isotropic};
use facet_fit::fitting::params::fit_moments;
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::NdfKind;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use std::path::PathBuf;
use std::time::Duration;

fn merl_file() -> PathBuf {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bench-ggx-0.2.binary");
    if !path.exists() {
        MerlTable::sample(&parse_analytic("ggx?alpha=0.2&conductor=gold").unwrap())
            .write(&path)
            .unwrap();
    }
    path
}

fn load(c: &mut Criterion) {
    let path = merl_file();
    c.bench_function("merl_load", |b| b.iter(|| MerlBrdf::open(&path).unwrap()));
    // As `facet fit` opens it: mapped, not read (the page cache's pages, no buffer to clear).
    c.bench_function("merl_map", |b| b.iter(|| MerlBrdf::map(&path).unwrap()));
}

fn full_fit(c: &mut Criterion) {
    let src = MerlBrdf::open(&merl_file()).unwrap();
    let cfg = FitConfig::isotropic();
    let _ = fit_material(&src, "bench", &cfg).unwrap(); // builds the grid geometry once
    c.bench_function("full_fit_isotropic_n90", |b| {
        b.iter(|| fit_material(&src, "bench", &cfg).unwrap())
    });
    // The paper's scope: extraction, G1 table and Fresnel (the source's sample set included).
    let paper_scope = FitConfig {
        models: facet_fit::fitting::Models::NONE,
        ..cfg
    };
    c.bench_function("extract_g1_fresnel_n90", |b| {
        b.iter(|| fit_material(&src, "bench", &paper_scope).unwrap())
    });
    // The tabulated model alone: extraction, Fresnel and its error.
    let tabulated_only = FitConfig {
        models: facet_fit::fitting::Models {
            tabulated: true,
            ggx: false,
            beckmann: false,
        },
        ..cfg
    };
    c.bench_function("fit_tabulated_n90", |b| {
        b.iter(|| fit_material(&src, "bench", &tabulated_only).unwrap())
    });
}

fn resolution(c: &mut Criterion) {
    let src = MerlBrdf::open(&merl_file()).unwrap();
    let mut g = c.benchmark_group("extract_isotropic");
    for n in [32, 64, 90, 128, 256, 1024] {
        for (label, base) in [
            ("gl_sqrt", ExtractConfig::isotropic()),
            ("paper", ExtractConfig::paper(n)),
        ] {
            let cfg = ExtractConfig {
                resolution: n,
                ..base
            };
            let alpha =
                fit_moments(NdfKind::Ggx, &extract_isotropic(&src, &cfg).unwrap().ndf).alpha_x;
            eprintln!(
                "extract_isotropic/{label}/{n}: GGX α = {alpha:.5} (error {:+.3} %)",
                (alpha / 0.2 - 1.0) * 100.0
            );
            g.bench_function(format!("{label}/{n}"), |b| {
                b.iter(|| extract_isotropic(&src, &cfg).unwrap())
            });
        }
    }
    g.finish();
}

fn anisotropic(c: &mut Criterion) {
    let src = parse_analytic("ggx?alpha_x=0.1&alpha_y=0.3&f0=0.04").unwrap();
    let mut g = c.benchmark_group("extract_anisotropic");
    g.sample_size(10);
    for (nt, np) in [(32, 64), (64, 64)] {
        let cfg = ExtractConfig {
            resolution: nt,
            phi_resolution: np,
            ..ExtractConfig::anisotropic()
        };
        let ex = extract_anisotropic(&src, &cfg).unwrap();
        let a = fit_moments(NdfKind::Ggx, &ex.ndf);
        eprintln!(
            "extract_anisotropic/{nt}x{np}: {} iterations, moments α = ({:.4}, {:.4})",
            ex.iterations,
            a.alpha_x.min(a.alpha_y),
            a.alpha_x.max(a.alpha_y)
        );
        g.bench_function(format!("{nt}x{np}"), |b| {
            b.iter(|| extract_anisotropic(&src, &cfg).unwrap())
        });
    }
    g.bench_function("full_fit_64x64", |b| {
        b.iter(|| fit_material(&src, "bench", &FitConfig::anisotropic()).unwrap())
    });
    g.finish();
}

fn proxy(c: &mut Criterion) {
    let lib = NbrdfLibrary::embedded();
    let src = lib.get("gold-metallic-paint").unwrap();
    let mut g = c.benchmark_group("proxy");
    g.sample_size(10);
    g.bench_function("fit_gold_metallic_paint", |b| {
        b.iter(|| fit_material(&src, "bench", &FitConfig::isotropic()).unwrap())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
    targets = load, full_fit, resolution, anisotropic, proxy
}
criterion_main!(benches);
