//! The trace section: closest- and any-hit rays a second through `trace.wgsl` against procedural
//! scenes of the mode's sizes, camera and random rays. With `--variants` every
//! [`TraceVariant`] is timed side by side: within each case the variants take turns run by run
//! (one warm-up each first), so that a clock drifting during the section touches them alike.
//! Each run is timed by the wall clock (submit to idle) and, where the adapter has timestamp
//! queries, by GPU timestamps around its passes; rays a second come from the GPU's time then.

use super::{Sizes, median};
use anyhow::Result;
use facet_gpu::Gpu;
use facet_gpu::timer::GpuTimer;
use facet_render::StageVariants;
use facet_render::bvh::{Bvh, BvhConfig, GpuBvh};
use facet_render::procedural::{self, Rng};
use facet_render::trace::{GpuHit, RayTracer, TraceBatch, TraceQuery, TraceVariant};
use glam::Vec3;
use serde_json::{Value, json};
use std::time::Instant;

/// Every [`TraceVariant`] `device` can run, each one it cannot named on the terminal.
fn runnable_variants(device: &wgpu::Device) -> Vec<TraceVariant> {
    let runnable = TraceVariant::runnable(device);
    for v in TraceVariant::ALL.iter().filter(|v| !runnable.contains(v)) {
        if let Err(e) = v.validate(device) {
            println!("  not timed: {e}");
        }
    }
    runnable
}

/// The section's rows, printed as they come.
pub fn trace(gpu: &Gpu, sizes: &Sizes, all_variants: bool) -> Result<Value> {
    let d = &gpu.device;
    let variants = if all_variants {
        runnable_variants(d)
    } else {
        vec![TraceVariant::DEFAULT]
    };
    let tracers = variants
        .iter()
        .map(|&v| RayTracer::with_variant(d, v))
        .collect::<Result<Vec<_>, _>>()?;
    let n = sizes.rays.min(RayTracer::max_rays_per_dispatch(d) as u32);
    let hits = facet_gpu::buffer::storage_zeroed(d, "hits", n as u64 * size_of::<GpuHit>() as u64);
    let occluded = facet_gpu::buffer::storage_zeroed(d, "occluded", n as u64 * 4);
    let mut timer = GpuTimer::new(d, &gpu.queue, 1);
    let clock = if timer.is_some() { "gpu" } else { "wall" };
    println!(
        "\ntrace: Mrays/s ({clock} clock), {n} rays a dispatch, median of {}, {} variant(s)",
        sizes.runs,
        variants.len()
    );
    let mut rows = Vec::new();
    for &tris in sizes.triangles {
        let mesh = procedural::test_scene(tris, 1);
        let bvh = Bvh::build(&mesh.positions, &mesh.indices, BvhConfig::medium());
        let gpu_bvh = GpuBvh::upload(d, &bvh)?;
        for (set, rays) in ray_sets(n) {
            let rays = facet_gpu::buffer::storage(d, "rays", &rays[..n as usize]);
            for (query, out) in [(TraceQuery::Closest, &hits), (TraceQuery::Any, &occluded)] {
                let batch = TraceBatch {
                    rays: &rays,
                    out,
                    count: n,
                };
                let case = Case {
                    bvh: &gpu_bvh,
                    query,
                    batch,
                };
                let times = case.time(gpu, &tracers, sizes.runs, timer.as_mut())?;
                let base = times[0].rate(n);
                for (tracer, t) in tracers.iter().zip(&times) {
                    let rate = t.rate(n);
                    let key = tracer.variant().key();
                    let query = format!("{query:?}").to_lowercase();
                    println!(
                        "  {tris:>9} triangles {set:<7} {query:<8} {key:<30} {rate:>10.1} Mrays/s  {:>5.2}×   (wall {:.3} ms; BVH {} nodes, built in {:.0} ms)",
                        rate / base,
                        t.wall_ms,
                        bvh.cwbvh.nodes.len(),
                        bvh.build_ms
                    );
                    rows.push(json!({
                        "triangles": tris, "rays": set, "query": query, "variant": key,
                        "mrays_per_s": rate, "clock": clock, "ms": t.wall_ms, "gpu_ms": t.gpu_ms,
                        "vs_default": rate / base,
                        "bvh_nodes": bvh.cwbvh.nodes.len(), "bvh_build_ms": bvh.build_ms,
                    }));
                }
            }
        }
        gpu.check_lost()?;
    }
    Ok(Value::Array(rows))
}

/// Camera rays over the scene (a 1024-wide image) and random rays inside its box.
fn ray_sets(n: u32) -> [(&'static str, Vec<facet_render::trace::GpuRay>); 2] {
    let camera = procedural::camera_rays(
        Vec3::new(-8.0, 6.0, 9.0),
        Vec3::new(2.0, 2.0, -3.0),
        60f32.to_radians(),
        1024,
        n.div_ceil(1024),
    );
    let random = procedural::random_rays(
        n as usize,
        Vec3::new(-9.9, 0.1, -9.9),
        Vec3::new(9.9, 9.9, 9.9),
        &mut Rng::new(5),
    );
    [("camera", camera), ("random", random)]
}

/// One query over one BVH and ray set.
struct Case<'a> {
    bvh: &'a GpuBvh,
    query: TraceQuery,
    batch: TraceBatch<'a>,
}

/// The medians of one variant on one case.
struct Times {
    wall_ms: f64,
    /// `None` without timestamp queries.
    gpu_ms: Option<f64>,
}

impl Times {
    /// Millions of rays a second, from the GPU's time where there is one.
    fn rate(&self, rays: u32) -> f64 {
        rays as f64 / (self.gpu_ms.unwrap_or(self.wall_ms) * 1e3)
    }
}

impl Case<'_> {
    /// Each tracer once untimed, then `runs` rounds of each in turn; the medians per tracer.
    fn time(
        &self,
        gpu: &Gpu,
        tracers: &[RayTracer],
        runs: usize,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<Vec<Times>> {
        for tracer in tracers {
            self.run(gpu, tracer, None)?;
        }
        let mut wall = vec![Vec::new(); tracers.len()];
        let mut on_gpu = vec![Vec::new(); tracers.len()];
        for _ in 0..runs.max(1) {
            for (k, tracer) in tracers.iter().enumerate() {
                let (ms, passes) = self.run(gpu, tracer, timer.as_deref_mut())?;
                wall[k].push(ms);
                on_gpu[k].extend(passes);
            }
        }
        Ok(wall
            .iter_mut()
            .zip(&mut on_gpu)
            .map(|(w, g)| Times {
                wall_ms: median(w),
                gpu_ms: (!g.is_empty()).then(|| median(g)),
            })
            .collect())
    }

    /// One submission of the query, waited for: its wall time (encoding to idle) and, when
    /// timed, its passes' GPU time, in ms.
    fn run(
        &self,
        gpu: &Gpu,
        tracer: &RayTracer,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<(f64, Option<f64>)> {
        let (d, q) = (&gpu.device, &gpu.queue);
        let start = Instant::now();
        let mut encoder = d.create_command_encoder(&Default::default());
        if let Some(t) = timer.as_deref_mut() {
            t.reset();
        }
        let batch = self.batch;
        tracer.encode(
            d,
            &mut encoder,
            self.bvh,
            self.query,
            batch,
            timer.as_deref_mut(),
        );
        q.submit([encoder.finish()]);
        d.poll(wgpu::PollType::wait_indefinitely())?;
        let wall = start.elapsed().as_secs_f64() * 1e3;
        let passes = match timer {
            Some(t) => Some(t.read_ms(d, q)?.iter().sum()),
            None => None,
        };
        Ok((wall, passes))
    }
}

/// The integrator with each [`StageVariants`] on the demo scene without glints at the
/// integrator section's size: the extend stage in every [`TraceVariant`]. The variants take
/// turns run by run after one warm-up each; Msamples/s of whole renders, against the first (the
/// default), and the time in one iteration of the extend stage.
pub fn stage_variants(gpu: &Gpu, sizes: &Sizes) -> Result<Value> {
    let (w, h, spp) = sizes.render;
    println!(
        "\nstage variants: the demo at {w} × {h}, depth 5, {spp} spp, median of {}",
        sizes.runs
    );
    let extend: Vec<StageVariants> = runnable_variants(&gpu.device)
        .into_iter()
        .map(|extend| StageVariants { extend })
        .collect();
    Ok(Value::Array(compare(gpu, sizes, false, &extend, "extend")?))
}

/// One scene's rows of [`stage_variants`]; `stage` names the stages whose time is reported
/// (those whose name contains it).
fn compare(
    gpu: &Gpu,
    sizes: &Sizes,
    glints: bool,
    variants: &[StageVariants],
    stage: &str,
) -> Result<Vec<Value>> {
    let (w, h, spp) = sizes.render;
    let (image, sampling) = super::demo_render(sizes);
    let (scene, env) = super::demo_scene(glints)?;
    let config = facet_render::ResourceConfig::standard();
    let res = facet_render::SceneResources::new(gpu, &scene, Some(&env), config)?;
    let camera = facet_render::camera::CameraFrame::new(&scene.camera)?;
    let mut runs = Vec::new();
    for &v in variants {
        let integrator = facet_render::Integrator::with_variants(&gpu.device, &res, v)?;
        let wf = integrator.wavefront(gpu, &res, image)?;
        runs.push((integrator, wf, Vec::new()));
    }
    // Round 0 warms up.
    for round in 0..=sizes.runs.max(1) {
        for (integrator, wf, ms) in &mut runs {
            wf.clear(gpu);
            let stats = integrator.render_more(gpu, wf, &camera, &sampling, &mut |_| {})?;
            if round > 0 {
                ms.push(stats.ms);
            }
        }
    }
    let mut rows = Vec::new();
    let mut base = None;
    for (integrator, wf, ms) in &mut runs {
        let ms = median(ms);
        let msps = w as f64 * h as f64 * spp as f64 / (ms * 1e3);
        let base = *base.get_or_insert(msps);
        let (times, clock) =
            integrator.profile_iteration(gpu, wf, &camera, &sampling, sizes.stage_warm)?;
        let stage_ms: f64 = times
            .iter()
            .filter(|t| t.stage.contains(stage))
            .map(|t| t.ms)
            .sum();
        let v = integrator.variants();
        let key = format!("extend {}", v.extend.key());
        println!(
            "  {:<15} {key:<54} {msps:>10.2} Msamples/s  {:>5.2}×   ({ms:.0} ms a render; {stage} stages {stage_ms:.3} ms of one iteration, {clock:?})",
            if glints {
                "with glints"
            } else {
                "without glints"
            },
            msps / base,
        );
        rows.push(json!({
            "glints": glints, "extend": v.extend.key(),
            "msamples_per_s": msps, "ms": ms, "vs_default": msps / base,
            "stage": stage, "stage_iteration_ms": stage_ms,
            "stage_clock": format!("{clock:?}").to_lowercase(),
            "width": w, "height": h, "spp": spp, "depth": 5,
        }));
    }
    Ok(rows)
}
