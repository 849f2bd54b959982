//! `facet bench`'s integrator section: the demo scene rendered without glints, with glints and
//! with the glint filter off, Msamples/s (the median of the mode's runs), one iteration's time
//! by stage (GPU timestamps where the adapter has them), and the glints' overhead at equal spp.

use crate::error::Result;
use crate::scenes::demo_scene;
use crate::timing::median_ms;
use crate::{Assets, Sizes};
use facet_gpu::Gpu;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::{ImageConfig, Integrator, ResourceConfig, SampleConfig, SceneResources};
use serde_json::{Value, json};

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

/// The section: rows (Msamples/s), the stages' shares of one iteration, the glints' overhead.
pub fn integrator(gpu: &Gpu, sizes: &Sizes, assets: &Assets) -> Result<(Value, Value, Value)> {
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
        let (scene, env) = demo_scene(assets, glints)?;
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
