//! `facet bench`'s light-selection section: the variance at equal spp and the time a sample of
//! each `--light-selection` (bvh, robust, power) on the many-light rooms (`assets/many_lights/`:
//! 100 point and spot lamps; 100 emissive panels of 10⁴ triangles), the gold scene and the demo,
//! against robust's, with the image means (which must agree: every selection is unbiased); and
//! the light BVH's build time and memory for emissive triangles.

use crate::error::Result;
use crate::measure::measure_noise;
use crate::scenes::{demo_scene, gold_ggx, gold_scene, square};
use crate::timing::median;
use crate::{Assets, Sizes};
use facet_render::resources::light_bvh::{GpuLightNode, LightBounds, LightBvh};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Environment, LoadOptions, Scene, load_gltf};
use facet_render::{
    Integrator, LightSelection, NdfSampling, RenderConfig, ResourceConfig, SampleConfig,
    SceneResources,
};
use glam::Vec3;
use serde_json::{Value, json};
use std::time::Instant;

/// A many-light room of `assets/many_lights/`.
fn room(assets: &Assets, file: &str) -> Result<(Scene, Option<Environment>)> {
    let path = assets.room(file);
    Ok((load_gltf(&path, &LoadOptions::default())?, None))
}

/// The section: the renders, then the builds.
pub fn lights(gpu: &facet_gpu::Gpu, sizes: &Sizes, assets: &Assets) -> Result<Value> {
    let (side, spp, builds) = sizes.lights;
    let (demo, sky) = demo_scene(assets, true)?;
    let (gold, gold_sky) = gold_scene(gold_ggx(0.3)?);
    let scenes = [
        (
            "room, 100 point and spot lamps",
            room(assets, "room_points.gltf")?,
        ),
        (
            "room, 100 emissive panels (10^4 triangles)",
            room(assets, "room_panels.gltf")?,
        ),
        ("gold sphere, sky and point light", (gold, Some(gold_sky))),
        ("demo", (demo, Some(sky))),
    ];
    let selections = [
        ("robust", LightSelection::Robust),
        ("power", LightSelection::Power),
        ("bvh", LightSelection::Bvh),
    ];
    println!(
        "\nlight selection: variance per pixel at {spp} spp ({side} × {side}) and time a sample, against robust"
    );
    let mut rows = Vec::new();
    for (name, (scene, env)) in &scenes {
        let lit = seen_emitters(gpu, scene, side)?;
        let keep = |k: usize| !lit[k];
        let mut base: Option<(f64, f64, f64, f64, f64)> = None;
        for (label, light_selection) in selections {
            let rc = ResourceConfig {
                light_selection,
                ..ResourceConfig::standard()
            };
            let m = measure_noise(
                gpu,
                scene,
                env.as_ref(),
                rc,
                square(side),
                spp,
                NdfSampling::Visible,
            )?;
            let var_lit = m.variance_where(keep);
            let (v0, t0, m0, s0, l0) = *base.get_or_insert((m.var, m.ns, m.mean, m.se2, var_lit));
            let z = (m.mean - m0) / (m.se2 + s0).sqrt().max(1e-30);
            let (v, t, vl) = (m.var / v0, m.ns / t0, var_lit / l0.max(1e-30));
            println!(
                "  {name:<44} {label:<7} variance {:.3e} ({v:.3}×; {vl:.3}× off the emitters in view), {:.0} ns a sample ({t:.2}×), time × variance {:.3}×; mean {:.4} ({z:+.1} σ)",
                m.var,
                m.ns,
                v * t,
                m.mean
            );
            rows.push(
                json!({"scene": name, "selection": label, "side": side, "spp": spp,
                "variance": m.var, "ns_per_sample": m.ns, "variance_vs_robust": v,
                "time_vs_robust": t, "time_variance_vs_robust": v * t, "mean": m.mean,
                "mean_z_vs_robust": z, "variance_off_emitters": var_lit,
                "variance_off_emitters_vs_robust": vl,
                "pixels_off_emitters": lit.iter().filter(|l| !**l).count()}),
            );
        }
    }
    let builds: Vec<Value> = builds.iter().map(|&n| tree_build(n)).collect();
    Ok(json!({"renders": rows, "builds": builds}))
}

/// Per pixel, whether the camera sees an emitter in it or beside it: an emission-only render
/// (depth 0, 16 spp) nonzero there or at a neighbour. Such pixels' variance is the anti-aliasing
/// of the emitter's edges, the same for every selection; the section reports the variance
/// without them too.
fn seen_emitters(gpu: &facet_gpu::Gpu, scene: &Scene, side: u32) -> Result<Vec<bool>> {
    let res = SceneResources::new(gpu, scene, None, ResourceConfig::standard())?;
    let integrator = Integrator::new(&gpu.device, &res)?;
    let camera = CameraFrame::new(&scene.camera)?;
    let config = RenderConfig {
        image: square(side),
        sampling: SampleConfig {
            spp: 16,
            max_depth: 0,
            ..SampleConfig::standard()
        },
    };
    let (image, _) = integrator.render(gpu, &res, &camera, &config, &mut |_| {})?;
    let s = side as i64;
    let bright = |x: i64, y: i64| {
        (0..s).contains(&x)
            && (0..s).contains(&y)
            && image.pixels[(y * s + x) as usize].iter().any(|v| *v > 0.0)
    };
    Ok((0..s * s)
        .map(|k| {
            let (x, y) = (k % s, k / s);
            (-1..=1).any(|dy| (-1..=1).any(|dx| bright(x + dx, y + dy)))
        })
        .collect())
}

/// The light BVH over `n` emissive triangles scattered in a 10 m cube, facing every way:
/// its build time (median of 3, 1 above 10⁵ triangles) and memory.
fn tree_build(n: usize) -> Value {
    let mut h = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        h ^= h << 13;
        h ^= h >> 7;
        h ^= h << 17;
        (h >> 40) as f32 / (1u64 << 24) as f32
    };
    let lights: Vec<(u32, LightBounds)> = (0..n as u32)
        .map(|i| {
            let a = Vec3::new(next(), next(), next()) * 10.0;
            let e = |next: &mut dyn FnMut() -> f32| {
                Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.1
            };
            (
                i,
                LightBounds::triangle(a, a + e(&mut next), a + e(&mut next), 1.0),
            )
        })
        .collect();
    let runs = if n > 100_000 { 1 } else { 3 };
    let mut ms = Vec::new();
    let mut nodes = 0;
    for _ in 0..runs {
        let t = Instant::now();
        let tree = LightBvh::build(&lights, n);
        ms.push(t.elapsed().as_secs_f64() * 1e3);
        nodes = tree.nodes.len();
    }
    let ms = median(&mut ms);
    // The nodes and, per light, its leaf (in the light records on the GPU).
    let bytes = nodes * std::mem::size_of::<GpuLightNode>() + n * 4;
    println!(
        "  light BVH over {n} emissive triangles: {ms:.0} ms, {nodes} nodes, {:.1} MB",
        bytes as f64 / 1e6
    );
    json!({"triangles": n, "build_ms": ms, "nodes": nodes, "bytes": bytes})
}
