//! The trace section: closest- and any-hit rays a second through `trace_closest.wgsl` and
//! `trace_any.wgsl` against procedural scenes of the mode's sizes, camera and random rays, the
//! median of the mode's runs after one warm-up. Each run is timed by the wall clock (submit to idle) and, where the adapter has
//! timestamp queries, by GPU timestamps around its passes; rays a second come from the GPU's
//! time then.

use crate::Sizes;
use crate::error::Result;
use crate::scenes::trace_rays;
use crate::timing::median;
use facet_gpu::Gpu;
use facet_gpu::timer::GpuTimer;
use facet_render::bvh::procedural;
use facet_render::bvh::query::{GpuHit, RayTracer, TraceBatch, TraceQuery};
use facet_render::bvh::{Bvh, BvhConfig, GpuBvh};
use serde_json::{Value, json};
use std::time::Instant;

/// The section's rows, printed as they come.
pub fn trace(gpu: &Gpu, sizes: &Sizes) -> Result<Value> {
    let d = &gpu.device;
    let tracer = RayTracer::new(d)?;
    let n = sizes.rays.min(RayTracer::max_rays_per_dispatch(d) as u32);
    let hits = facet_gpu::buffer::storage_zeroed(d, "hits", n as u64 * size_of::<GpuHit>() as u64);
    let occluded = facet_gpu::buffer::storage_zeroed(d, "occluded", n as u64 * 4);
    let mut timer = GpuTimer::new(d, &gpu.queue, 1);
    let clock = if timer.is_some() { "gpu" } else { "wall" };
    println!(
        "\ntrace: Mrays/s ({clock} clock), {n} rays a dispatch, median of {}",
        sizes.runs
    );
    let mut rows = Vec::new();
    for &tris in sizes.triangles {
        let mesh = procedural::test_scene(tris, 1);
        let bvh = Bvh::build(&mesh.positions, &mesh.indices, BvhConfig::medium());
        let gpu_bvh = GpuBvh::upload(d, &bvh)?;
        for (set, rays) in trace_rays(n as usize, 1024) {
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
                let t = case.time(gpu, &tracer, sizes.runs, timer.as_mut())?;
                let rate = t.rate(n);
                let query = format!("{query:?}").to_lowercase();
                println!(
                    "  {tris:>9} triangles {set:<7} {query:<8} {rate:>10.1} Mrays/s   (wall {:.3} ms; BVH {} nodes, built in {:.0} ms)",
                    t.wall_ms,
                    bvh.cwbvh.nodes.len(),
                    bvh.build_ms
                );
                rows.push(json!({
                    "triangles": tris, "rays": set, "query": query,
                    "mrays_per_s": rate, "clock": clock, "ms": t.wall_ms, "gpu_ms": t.gpu_ms,
                    "bvh_nodes": bvh.cwbvh.nodes.len(), "bvh_build_ms": bvh.build_ms,
                }));
            }
        }
        gpu.check_lost()?;
    }
    Ok(Value::Array(rows))
}

/// One query over one BVH and ray set.
struct Case<'a> {
    bvh: &'a GpuBvh,
    query: TraceQuery,
    batch: TraceBatch<'a>,
}

/// The medians of one case.
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
    /// Once untimed, then `runs` times; the medians.
    fn time(
        &self,
        gpu: &Gpu,
        tracer: &RayTracer,
        runs: usize,
        mut timer: Option<&mut GpuTimer>,
    ) -> Result<Times> {
        self.run(gpu, tracer, None)?;
        let mut wall = Vec::new();
        let mut on_gpu = Vec::new();
        for _ in 0..runs.max(1) {
            let (ms, passes) = self.run(gpu, tracer, timer.as_deref_mut())?;
            wall.push(ms);
            on_gpu.extend(passes);
        }
        Ok(Times {
            wall_ms: median(&mut wall),
            gpu_ms: (!on_gpu.is_empty()).then(|| median(&mut on_gpu)),
        })
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
