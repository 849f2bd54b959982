//! The fitter on the GPU against the f64 CPU reference (lavapipe here and in CI). Without an
//! adapter these tests skip with a visible `SKIPPED` line (`facet_gpu::gpu_for_tests`), unless
//! FACET_REQUIRE_GPU=1.

mod common;

use common::merl_from_spec;
use facet_fit::extract::{CpuSolver, ExtractConfig, extract_with};
use facet_fit::fitting::{Backend, FitConfig, fit_material_on};
use facet_fit::gpu::GpuFitter;
use facet_fit::metric::grid::{GridSamples, microfacet_error};
use facet_fit::metric::iso_tables::IsoTables;
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::brdf::Brdf;
use facet_fit::model::fresnel::Fresnel;
use facet_fit::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use facet_gpu::gpu_for_tests;
use std::sync::Arc;

/// Largest relative difference over entries above `floor` × the largest entry (f32 relative
/// precision is meaningless for entries 10⁶ times smaller than the peak).
fn rel_diff(a: &[f64], b: &[f64], floor: f64) -> f64 {
    let peak = b.iter().cloned().fold(0.0, f64::max);
    a.iter()
        .zip(b)
        .filter(|(_, y)| **y > floor * peak)
        .map(|(x, y)| (x / y - 1.0).abs())
        .fold(0.0, f64::max)
}

fn compare(name: &str, src: &dyn Brdf, cfg: &FitConfig, fitter: &GpuFitter) {
    let cpu = fit_material_on(src, "cpu", cfg, Backend::Cpu)
        .unwrap()
        .record;
    let gpu = fit_material_on(src, "gpu", cfg, Backend::Gpu(fitter))
        .unwrap()
        .record;
    assert!(
        gpu.backend.contains("llvmpipe") || !gpu.backend.starts_with("cpu"),
        "{name}: ran on {}",
        gpu.backend
    );
    let d = rel_diff(&gpu.tabulated.tables.d, &cpu.tabulated.tables.d, 1e-4);
    let g1 = rel_diff(&gpu.tabulated.tables.g1, &cpu.tabulated.tables.g1, 1e-3);
    let f = gpu
        .fresnel
        .rgb
        .iter()
        .zip(&cpu.fresnel.rgb)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] / b[c] - 1.0).abs()))
        .fold(0.0, f64::max);
    let alpha = |r: &facet_fit::model::material::FitRecord| {
        let g = r.ggx.as_ref().unwrap();
        [g.alpha_x, g.alpha_y, g.moments.alpha_x, g.moments.alpha_y]
    };
    let da = alpha(&gpu)
        .iter()
        .zip(alpha(&cpu))
        .map(|(a, b)| (a / b - 1.0).abs())
        .fold(0.0, f64::max);
    println!(
        "{name}: D {d:.1e}, G1 {g1:.1e}, F {f:.1e}, α {da:.1e}; iterations cpu {} gpu {}; λ {:.6} / {:.6}",
        cpu.iterations, gpu.iterations, cpu.eigenvalue, gpu.eigenvalue
    );
    // f32 tolerances: sums of N ≤ 4096 products in f32 carry ~1e-6 relative error; the
    // eigenvector's iteration stops at a residual of ~1e-7 in f32; 1e-4 leaves a wide margin.
    assert!(
        d < 1e-4 && g1 < 1e-4 && f < 1e-4,
        "{name}: D {d}, G1 {g1}, F {f}"
    );
    assert!(da < 1e-3, "{name}: α differs by {da}");
}

#[test]
fn gpu_and_cpu_fits_agree() {
    let Some(gpu) = gpu_for_tests("gpu_and_cpu_fits_agree") else {
        return;
    };
    let fitter = GpuFitter::new(&gpu).unwrap();
    println!("adapter: {}", gpu.describe());
    // The single lobe: the GPU runs both the extraction and the Fresnel average.
    let mut iso = FitConfig::single_lobe();
    iso.models.beckmann = false;
    for spec in [
        "ggx?alpha=0.05&f0=0.04",
        "ggx?alpha=0.3&conductor=gold",
        "beckmann?alpha=0.2&f0=0.5",
    ] {
        compare(spec, &merl_from_spec(spec), &iso, &fitter);
    }
    let lib = common::nbrdf();
    for name in [
        "blue-acrylic",
        "gold-metallic-paint",
        "alum-bronze",
        "chrome",
        "red-fabric",
    ] {
        compare(name, &lib.get(name).unwrap(), &iso, &fitter);
    }
    // Anisotropic, sized for lavapipe.
    let mut aniso = FitConfig::anisotropic();
    aniso.models.beckmann = false;
    aniso.extract.resolution = 24;
    aniso.extract.phi_resolution = 32;
    let src = parse_analytic("ggx?alpha_x=0.15&alpha_y=0.35&rotation=20&f0=0.04").unwrap();
    compare("anisotropic GGX (0.15, 0.35, 20°)", &src, &aniso, &fitter);
}

#[test]
fn gpu_extraction_matches_cpu_at_large_n() {
    let Some(gpu) = gpu_for_tests("gpu_extraction_matches_cpu_at_large_n") else {
        return;
    };
    let fitter = GpuFitter::new(&gpu).unwrap();
    let src = merl_from_spec("ggx?alpha=0.1&f0=0.04");
    let cfg = ExtractConfig {
        resolution: 1024,
        ..ExtractConfig::isotropic()
    };
    let cpu = extract_with(&src, &cfg, false, &CpuSolver).unwrap();
    let g = extract_with(&src, &cfg, false, &fitter).unwrap();
    let d = rel_diff(&g.ndf.tables().d, &cpu.ndf.tables().d, 1e-4);
    println!(
        "N = 1024: D {d:.1e}, λ {} vs {}",
        g.eigenvalue, cpu.eigenvalue
    );
    assert!(d < 1e-4 && (g.eigenvalue / cpu.eigenvalue - 1.0).abs() < 1e-5);
}

#[test]
fn without_an_adapter_gpu_tests_skip_or_fail_as_asked() {
    // Re-runs one GPU test of this binary with the GPU switched off (FACET_BACKEND=cpu), its
    // skips logged to a file of its own (not to the FACET_SKIP_LOG of this run, if any).
    let log = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("skip-log-{}.txt", std::process::id()));
    let run = |require: bool| {
        let _ = std::fs::remove_file(&log);
        let mut cmd = std::process::Command::new(std::env::current_exe().unwrap());
        cmd.args(["gpu_extraction_matches_cpu_at_large_n", "--exact"])
            .env("FACET_BACKEND", "cpu")
            .env(facet_gpu::skip::SKIP_LOG_VAR, &log);
        if require {
            cmd.env("FACET_REQUIRE_GPU", "1");
        } else {
            cmd.env_remove("FACET_REQUIRE_GPU");
        }
        let out = cmd.output().unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).to_string(),
            String::from_utf8_lossy(&out.stderr).to_string(),
            std::fs::read_to_string(&log).unwrap_or_default(),
        )
    };
    // Without --nocapture: the SKIPPED line still reaches the terminal (stderr) past libtest's
    // capture, and the log holds exactly that line.
    let (ok, stdout, stderr, logged) = run(false);
    let line = "SKIPPED gpu_extraction_matches_cpu_at_large_n: ";
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stderr.contains(line),
        "the skip is not on the terminal:\n{stdout}\n{stderr}"
    );
    assert!(
        logged.starts_with(line)
            && logged.contains("FACET_BACKEND=cpu")
            && logged.lines().count() == 1,
        "the skip log holds {logged:?}"
    );
    let (ok, stdout, stderr, logged) = run(true);
    let text = stdout + &stderr;
    assert!(!ok && text.contains("FACET_REQUIRE_GPU=1"), "{text}");
    assert!(logged.is_empty(), "a failure is no skip: {logged:?}");
    let _ = std::fs::remove_file(&log);
}

/// With the diffuse lobe the GPU runs every extraction of the separation and every full-grid
/// error (the F and ρd solves run on the CPU): the answers agree with the CPU's to the
/// extraction's f32 precision.
#[test]
fn gpu_and_cpu_diffuse_fits_agree() {
    let Some(gpu) = gpu_for_tests("gpu_and_cpu_diffuse_fits_agree") else {
        return;
    };
    let fitter = GpuFitter::new(&gpu).unwrap();
    let src = merl_from_spec("ggx?alpha=0.2&f0=0.04&kd=0.3,0.1,0.05");
    let mut cfg = FitConfig::isotropic();
    cfg.models.beckmann = false;
    let g = fit_material_on(&src, "gpu", &cfg, Backend::Gpu(&fitter))
        .unwrap()
        .record;
    let c = fit_material_on(&src, "cpu", &cfg, Backend::Cpu)
        .unwrap()
        .record;
    assert!(!g.backend.starts_with("cpu"), "{}", g.backend);
    let (gp, cp) = (g.ggx.unwrap(), c.ggx.unwrap());
    println!(
        "ρd gpu {:?} cpu {:?}; tabulated {:?} / {:?}; α {} / {}",
        g.tabulated.diffuse,
        c.tabulated.diffuse,
        g.tabulated.error,
        c.tabulated.error,
        gp.alpha_x,
        cp.alpha_x
    );
    // GGX's fit does not depend on the extraction beyond its moment start: equal to 1e-4.
    assert!((gp.alpha_x / cp.alpha_x - 1.0).abs() < 1e-4);
    for k in 0..3 {
        assert!((g.tabulated.diffuse[k] - c.tabulated.diffuse[k]).abs() < 1e-3);
    }
    let (ge, ce) = (g.tabulated.error.unwrap(), c.tabulated.error.unwrap());
    assert!((ge - ce).abs() < 0.05 * ce + 1e-5, "{ge} vs {ce}");
}

/// The error metric over the whole grid on the GPU against the CPU's, for a GGX, a Beckmann
/// and a tabulated NDF, with and without a diffuse lobe. The terms differ by the logs: the
/// CPU's polynomial is within 2e-7 of ln, WGSL's `log` within 3 ulp (2e-6 at ln(1 + x) ≈ 5);
/// the GPU adds each θd bin's ~10⁴ terms in f32 (256 lanes of ~50 terms, then a tree: ~1e-6
/// relative). Tolerance 4e-6 + 2e-5 × the error, a few times both.
#[test]
fn gpu_error_metric_matches_cpu() {
    let Some(gpu) = gpu_for_tests("gpu_error_metric_matches_cpu") else {
        return;
    };
    let fitter = GpuFitter::new(&gpu).unwrap();
    let src = merl_from_spec("ggx?alpha=0.2&f0=0.04&kd=0.3,0.1,0.05");
    let set = GridSamples::new(&src);
    let samples = fitter.upload(&set).unwrap();
    let tabulated = extract_with(&src, &ExtractConfig::isotropic(), false, &CpuSolver)
        .unwrap()
        .ndf;
    let ndfs = [
        (
            "GGX",
            Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.15)),
        ),
        (
            "Beckmann",
            Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Beckmann, 0.3)),
        ),
        ("tabulated", Ndf::Tabulated(Arc::new(tabulated))),
    ];
    for (name, ndf) in ndfs {
        for diffuse in [[0.0; 3], [0.25, 0.12, 0.04]] {
            let model = MicrofacetBrdf {
                fresnel: Fresnel::Schlick { f0: [0.05; 3] },
                diffuse,
                ..MicrofacetBrdf::ideal("m", ndf.clone())
            };
            let cpu = microfacet_error(&model, &set);
            let tables = IsoTables::new(&model).unwrap();
            let on_gpu = fitter.error.mean(&gpu, &samples, &tables).unwrap();
            println!(
                "{name} ρd {diffuse:?}: cpu {cpu:.8} gpu {on_gpu:.8} ({:.1e})",
                on_gpu / cpu - 1.0
            );
            assert!(
                (on_gpu - cpu).abs() <= 4e-6 + 2e-5 * cpu,
                "{name} ρd {diffuse:?}: GPU {on_gpu} CPU {cpu}"
            );
        }
    }
}

#[test]
fn a_gpu_failure_falls_back_to_the_cpu_and_says_so() {
    let Some(_) = gpu_for_tests("a_gpu_failure_falls_back_to_the_cpu_and_says_so") else {
        return;
    };
    // A device whose storage bindings are capped at 1 MiB cannot hold the MERL grid.
    let mut opts = facet_gpu::GpuOptions::from_env().unwrap();
    opts.max_storage_binding = Some(1 << 20);
    let gpu = facet_gpu::Gpu::with_options(&opts).unwrap();
    let fitter = GpuFitter::new(&gpu).unwrap();
    let src = merl_from_spec("ggx?alpha=0.2&f0=0.04");
    // The single lobe uploads the grid samples for the GPU's Fresnel average.
    let mut cfg = FitConfig::single_lobe();
    cfg.models.beckmann = false;
    let fell_back = fit_material_on(&src, "gpu", &cfg, Backend::Gpu(&fitter))
        .unwrap()
        .record;
    let cpu = fit_material_on(&src, "cpu", &cfg, Backend::Cpu)
        .unwrap()
        .record;
    println!("backend: {}", fell_back.backend);
    assert!(
        fell_back.backend.starts_with("cpu (fallback") && fell_back.backend.contains("bytes"),
        "{}",
        fell_back.backend
    );
    // The answer is the CPU's, exactly.
    assert_eq!(fell_back.tabulated.tables, cpu.tabulated.tables);
    assert_eq!(fell_back.ggx.unwrap().alpha_x, cpu.ggx.unwrap().alpha_x);
}
