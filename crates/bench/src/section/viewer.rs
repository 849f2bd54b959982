//! `facet bench`'s viewer section: the viewer's preview path (the preview sphere under the demo's
//! sky, batches paced as the viewer paces them, each frame tone mapped and read back), its frame
//! time and Msamples/s in the steady state.

use crate::error::{BenchError, Result};
use crate::scenes::{demo_scene, square};
use crate::{Assets, Sizes};
use facet_gpu::Gpu;
use facet_render::scene::Material;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::sphere::SphereScene;
use facet_render::{Integrator, ResourceConfig, SampleConfig, SceneResources};
use serde_json::{Value, json};
use std::sync::Arc;
use std::time::Instant;

/// The section: `frames` frames of the preview's pacing at its size, the steady state's rate.
pub fn viewer(gpu: &Gpu, sizes: &Sizes, assets: &Assets) -> Result<Value> {
    let (side, frames) = sizes.viewer;
    let fit = facet_fit::FittedMaterial::load(&assets.demo_fit())?;
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
    let scene = SphereScene::PREVIEW.build(sphere);
    let (_, env) = demo_scene(assets, false)?;
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
            return Err(BenchError::Other(format!(
                "the preview read back {} pixels",
                rgba.len()
            )));
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
