//! Ray tracing throughput of the CWBVH (obvhs build, WGSL traversal of `render/bvh.inc.wgsl`):
//! Mrays/s (criterion's elements/s) of closest-hit and any-hit queries, for pinhole camera rays
//! and for random rays (uniform origins in the scene, uniform directions, a quarter of them
//! short), on procedural scenes of 10^4, 10^5 and 10^6 triangles; obvhs's single-threaded CPU
//! traversal alongside as the reference. BVH build times are printed. The scenes and rays are
//! facet-bench's, which `facet bench`'s trace section measures too.
//!
//! `cargo bench --bench render_trace`; `FACET_TRACE_SCENES=1e4,1e5` picks the scene sizes.

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use facet_bench::scenes::trace_rays;
use facet_bench::sizes::triangles_from_env;
use facet_render::bvh::procedural;
use facet_render::bvh::query::{GpuHit, RayTracer};
use facet_render::bvh::{Bvh, BvhConfig, GpuBvh};
use std::time::{Duration, Instant};

/// Rays per GPU batch: enough to fill any GPU's threads many times over, small enough for
/// lavapipe to finish a sample in well under a second.
const GPU_RAYS: u32 = 1 << 17;
/// Rays per CPU batch (one thread).
const CPU_RAYS: usize = 1 << 14;

fn label(tris: usize) -> String {
    match tris {
        t if t >= 1_000_000 && t % 1_000_000 == 0 => format!("{}M", t / 1_000_000),
        t if t >= 1_000 && t % 1_000 == 0 => format!("{}k", t / 1_000),
        t => t.to_string(),
    }
}

fn trace(c: &mut Criterion) {
    let gpu = match facet_gpu::Gpu::new() {
        Ok(g) => {
            eprintln!("GPU: {}", g.describe());
            Some(g)
        }
        Err(e) => {
            eprintln!("GPU benchmarks skipped: {e}");
            None
        }
    };
    for tris in triangles_from_env("FACET_TRACE_SCENES", &[10_000, 100_000, 1_000_000]) {
        let mesh = procedural::test_scene(tris, 1);
        let start = Instant::now();
        let bvh = Bvh::build(&mesh.positions, &mesh.indices, BvhConfig::medium());
        eprintln!(
            "scene {}: {} triangles, BVH (medium) {} nodes built in {:.0} ms ({:.0} ms with the triangle gather)",
            label(tris),
            bvh.triangles.len(),
            bvh.cwbvh.nodes.len(),
            bvh.build_ms,
            start.elapsed().as_secs_f64() * 1e3
        );
        let mut g = c.benchmark_group(format!("trace_{}", label(tris)));
        g.sample_size(10)
            .sampling_mode(SamplingMode::Flat)
            .warm_up_time(Duration::from_millis(300))
            .measurement_time(Duration::from_secs(2));

        // Camera rays of a 512-wide image and random rays (`facet bench`'s trace section: 1024).
        let sets = trace_rays(GPU_RAYS as usize, 512);
        for (name, rays) in &sets {
            let rays = &rays[..CPU_RAYS];
            g.throughput(Throughput::Elements(rays.len() as u64));
            g.bench_function(format!("cpu_closest/{name}"), |b| {
                b.iter(|| {
                    rays.iter()
                        .filter(|r| {
                            bvh.closest_hit(r.origin.into(), r.dir.into(), r.tmax)
                                .is_some()
                        })
                        .count()
                })
            });
            g.bench_function(format!("cpu_any/{name}"), |b| {
                b.iter(|| {
                    rays.iter()
                        .filter(|r| bvh.occluded(r.origin.into(), r.dir.into(), r.tmax))
                        .count()
                })
            });
        }

        if let Some(gpu) = &gpu {
            let (d, q) = (&gpu.device, &gpu.queue);
            let gpu_bvh = GpuBvh::upload(d, &bvh).expect("BVH upload");
            let tracer = RayTracer::new(d).expect("trace pipelines");
            let hits = facet_gpu::buffer::storage_zeroed(
                d,
                "hits",
                GPU_RAYS as u64 * size_of::<GpuHit>() as u64,
            );
            let occluded = facet_gpu::buffer::storage_zeroed(d, "occluded", GPU_RAYS as u64 * 4);
            for (name, rays) in &sets {
                let ray_buf = facet_gpu::buffer::storage(d, "rays", &rays[..GPU_RAYS as usize]);
                let run = |closest: bool| {
                    let mut encoder = d.create_command_encoder(&Default::default());
                    if closest {
                        tracer.encode_closest(d, &mut encoder, &gpu_bvh, &ray_buf, &hits, GPU_RAYS);
                    } else {
                        tracer.encode_any(d, &mut encoder, &gpu_bvh, &ray_buf, &occluded, GPU_RAYS);
                    }
                    q.submit([encoder.finish()]);
                    d.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
                };
                g.throughput(Throughput::Elements(GPU_RAYS as u64));
                g.bench_function(format!("gpu_closest/{name}"), |b| b.iter(|| run(true)));
                g.bench_function(format!("gpu_any/{name}"), |b| b.iter(|| run(false)));
            }
        }
        g.finish();
    }
}

criterion_group!(benches, trace);
criterion_main!(benches);
