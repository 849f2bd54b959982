//! The light BVH on the CPU: its pmf is a distribution over the lights at any shading point, the
//! sampler draws lights with that pmf, and the importance never excludes a light that can
//! reach the point.

use facet_render::resources::light_bvh::{LightBounds, LightBvh};
use glam::Vec3;

/// A deterministic uniform [0, 1) sequence (SplitMix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.next(), self.next(), self.next()) * (hi - lo) + Vec3::splat(lo)
    }

    fn dir(&mut self) -> Vec3 {
        loop {
            let v = self.vec(-1.0, 1.0);
            if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

/// 100 lights of every kind: points and spots under a ceiling (y = 3), triangles facing down,
/// across a 10 × 8 room.
fn room_lights(rng: &mut Rng) -> Vec<(u32, LightBounds)> {
    (0..100u32)
        .map(|k| {
            let p = Vec3::new(rng.next() * 10.0 - 5.0, 2.9, rng.next() * 8.0 - 4.0);
            let b = match k % 3 {
                0 => LightBounds::point(p, 1.0 + 10.0 * rng.next()),
                1 => LightBounds::spot(p, Vec3::NEG_Y, 5.0, 0.3, 0.6 + 0.5 * rng.next()),
                _ => LightBounds::triangle(
                    p,
                    p + Vec3::new(0.2, 0.0, 0.0),
                    p + Vec3::new(0.0, 0.0, 0.2),
                    20.0,
                ),
            };
            (k, b)
        })
        .collect()
}

/// At 200 random points and normals in and around the room, the pmfs of all lights sum to 1
/// (f32 products of at most the tree's depth of ratios: 1e-5).
#[test]
fn pmf_sums_to_one_over_the_lights() {
    let mut rng = Rng(1);
    let lights = room_lights(&mut rng);
    let tree = LightBvh::build(&lights, lights.len());
    assert_eq!(tree.nodes.len(), 2 * lights.len() - 1);
    let mut reached = 0;
    for _ in 0..200 {
        let p = rng.vec(-6.0, 6.0);
        let n = rng.dir();
        let sum: f64 = (0..100).map(|l| tree.pmf(p, n, l) as f64).sum();
        assert!(
            (sum - 1.0).abs() < 1e-5,
            "at {p} n {n}: the pmfs sum to {sum}"
        );
        reached += (0..100).any(|l| lights[l].1.importance(p, n) > 0.0) as usize;
    }
    assert!(reached > 100, "only {reached} points reached by any light");
}

/// Sampling follows the pmf: 200 000 draws at a point on the floor, each light's frequency
/// within 5 standard deviations of its pmf, and each draw's reported probability equal to the
/// pmf recomputed from its leaf.
#[test]
fn samples_follow_the_pmf() {
    let mut rng = Rng(2);
    let lights = room_lights(&mut rng);
    let tree = LightBvh::build(&lights, lights.len());
    let (p, n) = (Vec3::new(1.0, 0.0, -0.5), Vec3::Y);
    let draws = 200_000;
    let mut count = vec![0u32; lights.len()];
    for _ in 0..draws {
        let (l, pmf) = tree
            .sample(p, n, rng.next())
            .expect("the floor sees the lights");
        let again = tree.pmf(p, n, l);
        assert!(
            (pmf - again).abs() <= 1e-5 * again,
            "light {l}: {pmf} drawn, {again} recomputed"
        );
        count[l as usize] += 1;
    }
    for (l, &c) in count.iter().enumerate() {
        let q = tree.pmf(p, n, l as u32) as f64;
        let sd = (draws as f64 * q * (1.0 - q)).sqrt().max(1.0);
        assert!(
            (c as f64 - draws as f64 * q).abs() <= 5.0 * sd,
            "light {l}: {c} draws for pmf {q}"
        );
    }
}

/// A light that can reach a point is never given probability 0: for random points, normals and
/// lights, whenever a point of the light's emitter lies above the point's tangent plane within
/// the light's emission cone, its pmf is positive.
#[test]
fn no_light_that_reaches_the_point_is_excluded() {
    let mut rng = Rng(3);
    let lights = room_lights(&mut rng);
    let tree = LightBvh::build(&lights, lights.len());
    let mut checked = 0;
    for _ in 0..2000 {
        let p = rng.vec(-5.0, 2.5);
        let n = rng.dir();
        let (l, b) = lights[(rng.next() * 100.0) as usize % 100];
        // A point of the emitter: the light's position, or a triangle's vertex (a box corner
        // of these axis-aligned triangles).
        let q = b.lo;
        let to_q = (q - p).normalize();
        // It emits toward p when p is within θo + θe of its axis (a point: everywhere).
        let reach = b.cos_o.acos() + b.cos_e.acos();
        let emits_toward_p = b.cos_o <= -1.0 || b.w.angle_between(-to_q) < reach - 1e-3;
        if to_q.dot(n) > 1e-3 && emits_toward_p && (p - q).length() > 1e-2 {
            checked += 1;
            assert!(
                tree.pmf(p, n, l) > 0.0,
                "light {l} ({b:?}) reaches {p} n {n} but has pmf 0"
            );
        }
    }
    assert!(checked > 200, "{checked} cases");
}

/// The WGSL's choices equal the CPU's (`shaders/tests/render/light_tree_probe.wgsl`): at 4096 random
/// points, normals and random numbers, the pmf of a random light (f32 on both, products in the
/// same order: 1e-5 relative) and the light the walk picks with its probability.
#[test]
fn gpu_light_tree_matches_the_cpu() {
    let Some(gpu) = facet_gpu::gpu_for_tests("gpu_light_tree_matches_the_cpu") else {
        return;
    };
    let mut rng = Rng(5);
    let lights = room_lights(&mut rng);
    let tree = LightBvh::build(&lights, lights.len());
    let queries: Vec<(Vec3, Vec3, f32, u32)> = (0..4096)
        .map(|_| {
            let p = rng.vec(-6.0, 3.5);
            let n = if rng.next() < 0.1 {
                Vec3::ZERO
            } else {
                rng.dir()
            };
            (p, n, rng.next(), (rng.next() * 100.0) as u32 % 100)
        })
        .collect();
    let probes: Vec<[f32; 8]> = queries
        .iter()
        .map(|(p, n, u, l)| {
            let leaf = f32::from_bits(tree.leaf_of[*l as usize]);
            [p.x, p.y, p.z, *u, n.x, n.y, n.z, leaf]
        })
        .collect();
    let (d, q) = (&gpu.device, &gpu.queue);
    let pipeline =
        facet_gpu::shader::compute_pipeline(d, "tests/render/light_tree_probe.wgsl", "probe", &[])
            .unwrap();
    let nodes = facet_gpu::buffer::storage(d, "light tree", &tree.nodes);
    let probe_buf = facet_gpu::buffer::storage(d, "probes", &probes);
    let results = facet_gpu::buffer::storage_zeroed(d, "results", probes.len() as u64 * 16);
    facet_gpu::dispatch::run(
        d,
        q,
        &pipeline,
        "light tree probe",
        &[
            nodes.as_entire_binding(),
            probe_buf.as_entire_binding(),
            results.as_entire_binding(),
        ],
        probes.len() as u32,
        64,
    );
    let out: Vec<[f32; 4]> = facet_gpu::buffer::read(d, q, &results, probes.len()).unwrap();
    let mut picks_equal = 0;
    for ((p, n, u, l), r) in queries.iter().zip(&out) {
        let cpu = tree.pmf(*p, *n, *l);
        assert!(
            (r[0] - cpu).abs() <= 1e-5 * cpu.max(1e-30) + 1e-12,
            "light {l} at {p} n {n}: GPU pmf {} CPU {cpu}",
            r[0]
        );
        let (light, pmf) = tree.sample(*p, *n, *u).unwrap();
        // A random number within rounding of a child's boundary may go either way.
        if r[1].to_bits() == light {
            picks_equal += 1;
            assert!(
                (r[2] - pmf).abs() <= 1e-5 * pmf,
                "pick {light}: GPU pmf {} CPU {pmf}",
                r[2]
            );
        }
    }
    assert!(picks_equal >= 4090, "{picks_equal} of 4096 picks equal");
}
