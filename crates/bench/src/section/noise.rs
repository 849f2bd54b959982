//! `facet bench`'s noise section: variance at equal spp and time a sample before and after
//! visible-normal sampling and robust light selection, and each change alone.

use crate::error::Result;
use crate::measure::{Measured, measure_noise};
use crate::scenes::{demo_scene, gold_fit, gold_ggx, gold_scene, square};
use crate::{Assets, Sizes};
use facet_fit::model::material::ModelChoice;
use facet_gpu::Gpu;
use facet_render::ResourceConfig;
use facet_render::scene::sphere::SphereScene;
use serde_json::{Value, json};

/// Noise at equal spp and time per sample, before (D cos θh sampling, selection by flux) and
/// after (visible normals, robust selection), and each change alone, on the gold scene (GGX and
/// the fit's tabulated NDF), the demo and a glossy (α = 0.05) sphere under the sky. The
/// variance of a pixel is estimated from two renders with different seeds: E[(a − b)²] / 2,
/// averaged over pixels and channels; the time a sample is the median of three renders.
pub fn noise(gpu: &Gpu, sizes: &Sizes, assets: &Assets) -> Result<Value> {
    use facet_render::{LightSelection, NdfSampling};
    let (side, spp) = sizes.noise;
    let (demo, sky) = demo_scene(assets, true)?;
    let glossy = SphereScene::PREVIEW.build(gold_ggx(0.05)?);
    let tabulated = gold_fit(0.3, ModelChoice::Tabulated)?;
    let scenes = [
        (
            "gold sphere, sky and point light",
            gold_scene(gold_ggx(0.3)?),
        ),
        ("the same, the fit's tabulated NDF", gold_scene(tabulated)),
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
