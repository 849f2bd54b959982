//! The CWBVH: every preset builds and finds the same hits as brute force; barycentrics give back
//! the hit point; the WGSL traversal (`shaders/render/bvh.inc.wgsl`) returns obvhs's CPU hits.
//!
//! GPU-vs-CPU budget: at most 1 ray in 10^4 may differ (primitive, t beyond 1e-5 relative or
//! barycentrics beyond 1e-4). On lavapipe the traversal is exact (no contraction of the f32
//! arithmetic); on real GPUs fused multiply-adds move box and triangle tests by an ulp, which
//! flips about 1 ray in 10^5 at a box edge, a triangle edge or a tie in t between two triangles
//! (design.md, "GPU notes"). Each mismatch is printed, with ties in t marked.

use facet_render::bvh::procedural::{self, Rng};
use facet_render::bvh::query::{GpuHit, GpuRay, RayTracer};
use facet_render::bvh::{Bvh, BvhConfig, BvhPreset, GpuBvh};
use glam::Vec3;

fn scene_bvh(triangles: usize, config: BvhConfig) -> (procedural::Mesh, Bvh) {
    let mesh = procedural::test_scene(triangles, 7);
    let bvh = Bvh::build(&mesh.positions, &mesh.indices, config);
    (mesh, bvh)
}

/// Camera rays through the scene, random rays inside (a quarter bounded), rays from outside the
/// room, and axis-aligned rays whose zero (and −0.0) components exercise `safe_inverse`.
fn ray_set(camera: (u32, u32), random: usize, seed: u64) -> Vec<GpuRay> {
    let mut rng = Rng::new(seed);
    let mut rays = procedural::camera_rays(
        Vec3::new(-8.0, 6.0, 9.0),
        Vec3::new(2.0, 2.0, -3.0),
        60f32.to_radians(),
        camera.0,
        camera.1,
    );
    rays.extend(procedural::random_rays(
        random,
        Vec3::new(-9.9, 0.1, -9.9),
        Vec3::new(9.9, 9.9, 9.9),
        &mut rng,
    ));
    rays.extend(procedural::random_rays(
        random / 16,
        Vec3::splat(-20.0),
        Vec3::splat(20.0),
        &mut rng,
    ));
    let axes = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
        Vec3::new(-0.0, -1.0, -0.0),
        Vec3::new(0.6, 0.0, -0.8),
    ];
    for k in 0..random / 64 {
        let origin = rng.in_box(Vec3::new(-9.0, 0.5, -9.0), Vec3::new(9.0, 9.5, 9.0));
        rays.push(GpuRay::new(origin, axes[k % axes.len()], f32::INFINITY));
    }
    rays
}

fn cpu_closest(bvh: &Bvh, r: &GpuRay) -> Option<facet_render::Hit> {
    bvh.closest_hit(r.origin.into(), r.dir.into(), r.tmax)
}

fn brute_force(bvh: &Bvh, r: &GpuRay) -> Option<(u32, f32)> {
    let ray = Bvh::ray(r.origin.into(), r.dir.into(), r.tmax);
    bvh.triangles
        .iter()
        .enumerate()
        .map(|(i, t)| (i as u32, t.intersect(&ray)))
        .filter(|&(_, t)| t < r.tmax)
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

#[test]
fn every_preset_builds_and_matches_brute_force() {
    let rays = ray_set((24, 16), 600, 3);
    for preset in BvhPreset::ALL {
        let (mesh, bvh) = scene_bvh(3_000, BvhConfig { preset });
        assert_eq!(bvh.triangles.len(), mesh.triangle_count());
        assert!(!bvh.cwbvh.nodes.is_empty());
        let mut hits = 0;
        for r in &rays {
            let got = cpu_closest(&bvh, r);
            let want = brute_force(&bvh, r);
            match (got, want) {
                (None, None) => {}
                (Some(h), Some((p, t))) => {
                    hits += 1;
                    // A tie between two triangles may resolve either way; t may not differ.
                    assert!(
                        h.prim == p || h.t == t,
                        "{preset:?}: {r:?} hit {h:?}, brute force ({p}, {t})"
                    );
                    assert_eq!(h.t, t, "{preset:?}: {r:?}");
                }
                (g, w) => panic!("{preset:?}: {r:?}: bvh {g:?}, brute force {w:?}"),
            }
        }
        println!(
            "{preset:?}: {} nodes, {} primitive slots, {hits}/{} rays hit, built in {:.1} ms",
            bvh.cwbvh.nodes.len(),
            bvh.cwbvh.primitive_indices.len(),
            rays.len(),
            bvh.build_ms
        );
        assert!(hits > rays.len() / 2);
    }
}

#[test]
fn barycentrics_reproduce_the_hit_point() {
    let (_, bvh) = scene_bvh(5_000, BvhConfig::medium());
    let rays = ray_set((32, 24), 2_000, 5);
    let mut checked = 0;
    for r in &rays {
        let Some(h) = cpu_closest(&bvh, r) else {
            continue;
        };
        let on_ray = Vec3::from(r.origin) + h.t * Vec3::from(r.dir);
        let from_uv = bvh.hit_point(&h);
        // f32 over a 20-unit scene: a few ulps of 10.
        assert!(
            (on_ray - from_uv).length() < 2e-4 * (1.0 + on_ray.length()),
            "{r:?}: {h:?}: ray point {on_ray}, barycentric point {from_uv}"
        );
        assert!(h.u >= 0.0 && h.v >= 0.0 && h.u + h.v <= 1.0 + 1e-6, "{h:?}");
        checked += 1;
    }
    assert!(checked > rays.len() / 2, "{checked}");
}

/// `Bvh::validate`, which debug builds (tests included) run after every build: it passes on a
/// built tree, with every triangle found once, and panics on a tree whose triangle was moved
/// out of its leaf's box after the build.
#[test]
fn validation_passes_built_trees_and_catches_a_moved_triangle() {
    let (mesh, bvh) = scene_bvh(20_000, BvhConfig::medium());
    let t = std::time::Instant::now();
    let stats = bvh.validate();
    let ms = t.elapsed().as_secs_f64() * 1e3;
    println!(
        "validate: {ms:.1} ms for {} nodes, {} triangles (build {:.1} ms)",
        stats.node_count, stats.prim_count, bvh.build_ms
    );
    assert_eq!(stats.prim_count, mesh.triangle_count());
    assert_eq!(stats.node_count, bvh.cwbvh.nodes.len());
    assert!(stats.max_depth < 32, "depth {}", stats.max_depth);
    // obvhs checks a leaf's triangles against the box of the node holding the leaf, and the
    // root has none: move a triangle that is not in a leaf of the root.
    let root = &bvh.cwbvh.nodes[0];
    let in_root_leaf: Vec<u32> = (0..8)
        .filter(|&ch| !root.is_child_empty(ch) && root.is_leaf(ch))
        .flat_map(|ch| {
            let (first, count) = root.child_primitives(ch);
            (first..first + count).map(|slot| bvh.cwbvh.primitive_indices[slot as usize])
        })
        .collect();
    let victim = (0..bvh.triangles.len() as u32)
        .find(|i| !in_root_leaf.contains(i))
        .unwrap() as usize;
    let mut moved = bvh.clone();
    moved.triangles[victim].v0 += glam::Vec3A::splat(100.0);
    let caught = std::panic::catch_unwind(|| moved.validate()).is_err();
    assert!(caught, "validate accepted a triangle outside its leaf");
}

#[test]
fn empty_scene_misses_on_the_cpu() {
    let bvh = Bvh::build(&[], &[], BvhConfig::default());
    assert!(bvh.is_empty());
    assert_eq!(bvh.closest_hit(Vec3::ZERO, Vec3::X, f32::INFINITY), None);
    assert!(!bvh.occluded(Vec3::ZERO, Vec3::X, f32::INFINITY));
}

#[test]
fn empty_scene_uploads_and_misses_on_the_gpu() {
    let Some(gpu) = facet_gpu::gpu_for_tests("empty_scene_uploads_and_misses_on_the_gpu") else {
        return;
    };
    let bvh = Bvh::build(&[], &[], BvhConfig::default());
    let gpu_bvh = GpuBvh::upload(&gpu.device, &bvh).unwrap();
    assert_eq!(gpu_bvh.node_count, 0);
    let tracer = RayTracer::new(&gpu.device).unwrap();
    let rays = ray_set((8, 8), 256, 1);
    let hits = tracer
        .trace_closest(&gpu.device, &gpu.queue, &gpu_bvh, &rays)
        .unwrap();
    assert!(hits.iter().all(|h| !h.is_hit()), "{:?}", &hits[..4]);
    let any = tracer
        .trace_any(&gpu.device, &gpu.queue, &gpu_bvh, &rays)
        .unwrap();
    assert!(any.iter().all(|&o| o == 0));
}

/// Counts GPU/CPU disagreements, printing the first few.
struct Mismatches {
    what: &'static str,
    count: usize,
    ties: usize,
}

impl Mismatches {
    fn new(what: &'static str) -> Self {
        Mismatches {
            what,
            count: 0,
            ties: 0,
        }
    }

    fn record(&mut self, tie: bool, message: impl FnOnce() -> String) {
        self.count += 1;
        self.ties += tie as usize;
        if self.count <= 10 {
            eprintln!(
                "{}{}: {}",
                self.what,
                if tie { " (tie)" } else { "" },
                message()
            );
        }
    }

    /// At most 1 ray in 10^4 (rounded up).
    fn check(&self, rays: usize) {
        let budget = rays.div_ceil(10_000);
        println!(
            "{}: {} mismatches ({} ties in t) of {rays} rays, budget {budget}",
            self.what, self.count, self.ties
        );
        assert!(
            self.count <= budget,
            "{}: {} > {budget}",
            self.what,
            self.count
        );
    }
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-30)
}

/// Closest hits and any-hit on the GPU by `tracer` against obvhs on the CPU, for one BVH and
/// ray set.
fn gpu_matches_cpu(
    gpu: &facet_gpu::Gpu,
    tracer: &RayTracer,
    bvh: &Bvh,
    rays: &[GpuRay],
    label: &str,
) {
    let (d, q) = (&gpu.device, &gpu.queue);
    let gpu_bvh = GpuBvh::upload(d, bvh).unwrap();

    let start = std::time::Instant::now();
    let hits = tracer.trace_closest(d, q, &gpu_bvh, rays).unwrap();
    let gpu_s = start.elapsed().as_secs_f64();
    let start = std::time::Instant::now();
    let cpu: Vec<_> = rays.iter().map(|r| cpu_closest(bvh, r)).collect();
    let cpu_s = start.elapsed().as_secs_f64();
    println!(
        "{label}: {} triangles, {} rays: GPU {:.2} Mrays/s ({}), CPU {:.2} Mrays/s",
        bvh.triangles.len(),
        rays.len(),
        rays.len() as f64 / gpu_s * 1e-6,
        gpu.describe(),
        rays.len() as f64 / cpu_s * 1e-6
    );

    let mut closest = Mismatches::new("closest");
    let mut hit_count = 0;
    for ((r, g), c) in rays.iter().zip(&hits).zip(&cpu) {
        match c {
            None if !g.is_hit() => {}
            Some(c) if g.is_hit() => {
                hit_count += 1;
                let same = g.prim == c.prim
                    && close(g.t, c.t, 1e-5)
                    && (g.u - c.u).abs() <= 1e-4
                    && (g.v - c.v).abs() <= 1e-4;
                if !same {
                    let tie = g.prim != c.prim && close(g.t, c.t, 1e-5);
                    closest.record(tie, || format!("{r:?}: GPU {g:?}, CPU {c:?}"));
                }
            }
            _ => closest.record(false, || format!("{r:?}: GPU {g:?}, CPU {c:?}")),
        }
    }
    assert!(hit_count > rays.len() / 2, "{hit_count} hits");
    closest.check(rays.len());

    // Any-hit against ray_traverse_miss: (a) the rays as they are, (b) unbounded, (c) stopped
    // just short of the CPU's closest hit, where nothing may be found.
    let unbounded: Vec<GpuRay> = rays
        .iter()
        .map(|r| GpuRay {
            tmax: f32::INFINITY,
            ..*r
        })
        .collect();
    let short: Vec<GpuRay> = rays
        .iter()
        .zip(&cpu)
        .filter_map(|(r, c)| {
            c.map(|c| GpuRay {
                tmax: c.t * 0.999,
                ..*r
            })
        })
        .collect();
    for (what, set) in [
        ("any (ray tmax)", rays),
        ("any (tmax = inf)", &unbounded[..]),
        ("any (tmax = 0.999 t)", &short[..]),
    ] {
        let gpu_any = tracer.trace_any(d, q, &gpu_bvh, set).unwrap();
        let mut any = Mismatches::new(what);
        let mut occluded = 0;
        for (r, &g) in set.iter().zip(&gpu_any) {
            let c = bvh.occluded(r.origin.into(), r.dir.into(), r.tmax);
            occluded += c as usize;
            if (g != 0) != c {
                any.record(false, || format!("{r:?}: GPU {g}, CPU {c}"));
            }
        }
        any.check(set.len());
        println!("{what}: {occluded} of {} occluded", set.len());
        if what.contains("0.999") {
            assert!(occluded <= set.len().div_ceil(10_000), "{occluded}");
        }
    }
    // Any-hit at tmax = inf agrees with closest-hit's hit / miss.
    let cpu_any_inf = unbounded
        .iter()
        .filter(|r| bvh.occluded(r.origin.into(), r.dir.into(), r.tmax))
        .count();
    let cpu_closest_inf = unbounded
        .iter()
        .filter(|r| cpu_closest(bvh, r).is_some())
        .count();
    assert_eq!(cpu_any_inf, cpu_closest_inf);
}

/// ~5·10^4 triangles, ~1.2·10^5 rays with the default preset; a pre-split preset (triangles in
/// several leaves) on fewer rays.
#[test]
fn gpu_traversal_matches_obvhs() {
    let Some(gpu) = facet_gpu::gpu_for_tests("gpu_traversal_matches_obvhs") else {
        return;
    };
    let (_, bvh) = scene_bvh(50_000, BvhConfig::medium());
    let rays = ray_set((256, 192), 65_536, 11);
    assert!(rays.len() >= 100_000);
    let tracer = RayTracer::new(&gpu.device).unwrap();
    gpu_matches_cpu(&gpu, &tracer, &bvh, &rays, "medium");

    let (_, split) = scene_bvh(50_000, BvhConfig::very_slow());
    assert!(split.cwbvh.uses_spatial_splits);
    let rays = ray_set((64, 48), 8_192, 12);
    gpu_matches_cpu(&gpu, &tracer, &split, &rays, "very slow (pre-split)");
}

/// A batch split into dispatches of 4096 rays gives obvhs's hits, and one encode over several
/// dispatches in one encoder gives the same hits as the batches, one submission each.
#[test]
fn a_batch_split_into_dispatches_matches_obvhs() {
    let Some(gpu) = facet_gpu::gpu_for_tests("a_batch_split_into_dispatches_matches_obvhs") else {
        return;
    };
    let (d, q) = (&gpu.device, &gpu.queue);
    let (_, bvh) = scene_bvh(50_000, BvhConfig::medium());
    let rays = ray_set((96, 64), 12_000, 13);
    let split = RayTracer::new(d).unwrap().with_rays_per_dispatch(4096);
    gpu_matches_cpu(&gpu, &split, &bvh, &rays, "medium, 4096 rays a dispatch");
    let gpu_bvh = GpuBvh::upload(d, &bvh).unwrap();
    let ray_buf = facet_gpu::buffer::storage(d, "rays", &rays);
    let hit_buf = facet_gpu::buffer::storage_zeroed(d, "hits", (rays.len() * 16) as u64);
    let mut encoder = d.create_command_encoder(&Default::default());
    split.encode_closest(
        d,
        &mut encoder,
        &gpu_bvh,
        &ray_buf,
        &hit_buf,
        rays.len() as u32,
    );
    q.submit([encoder.finish()]);
    let once: Vec<GpuHit> = facet_gpu::buffer::read(d, q, &hit_buf, rays.len()).unwrap();
    let batched = split.trace_closest(d, q, &gpu_bvh, &rays).unwrap();
    let differ = once.iter().zip(&batched).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "of {} rays", rays.len());
}

#[test]
fn gpu_hit_layout() {
    // The WGSL side is checked against naga in the root package's tests/shaders.rs.
    assert_eq!(std::mem::size_of::<GpuRay>(), 32);
    assert_eq!(std::mem::size_of::<GpuHit>(), 16);
}
