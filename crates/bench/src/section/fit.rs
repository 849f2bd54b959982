//! `facet bench`'s fit section: an analytic material sampled into a MERL table, fitted on the
//! CPU and on the GPU (all models, the tabulated model alone, an anisotropic extraction), ms per
//! material, the median of the runs after a warm-up.

use crate::Sizes;
use crate::error::Result;
use crate::scenes::analytic_table;
use crate::timing::median_ms;
use facet_fit::extract::ExtractConfig;
use facet_fit::fitting::{Backend, FitConfig, Models, fit_material_on};
use facet_fit::gpu::GpuFitter;
use facet_gpu::Gpu;
use serde_json::{Value, json};

/// The section: `material` (an analytic spec) sampled into a MERL table and fitted by each
/// backend (the CPU; the GPU where there is one).
pub fn fit(gpu: Option<&Gpu>, sizes: &Sizes, material: &str) -> Result<Value> {
    let src = analytic_table(material)?;
    let fitter = gpu.map(GpuFitter::new).transpose()?;
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
        "\nfit ({material} as a MERL table), ms per material, median of the runs after a warm-up"
    );
    for (label, cfg, runs) in &cases {
        let mut backends = vec![("cpu", Backend::Cpu)];
        if let Some(f) = &fitter {
            backends.push(("gpu", Backend::Gpu(f)));
        }
        for (name, backend) in backends {
            let mut used = String::new();
            let ms = median_ms(*runs, || {
                let m = fit_material_on(&src, material, cfg, backend)?;
                used = m.record.backend.clone();
                Ok(())
            })?;
            println!("  {label:<40} {name:<4} {ms:>10.1} ms   ({runs} runs; {used})");
            rows.push(json!({"case": label, "backend": name, "median_ms": ms, "runs": runs, "record_backend": used}));
        }
    }
    Ok(Value::Array(rows))
}
