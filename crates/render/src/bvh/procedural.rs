//! Procedural geometry and ray sets for tests and benchmarks: a box room, a noisy terrain,
//! displaced icospheres and loose random triangles (depth complexity, thin and large triangles,
//! all orientations), plus pinhole camera rays and random rays. Deterministic from a seed.

use crate::bvh::query::GpuRay;
use glam::Vec3;
use std::collections::HashMap;

/// A small deterministic generator (SplitMix64), so tests need no `rand`.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f32()
    }

    /// Uniform in the box [lo, hi).
    pub fn in_box(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
        Vec3::new(
            self.range(lo.x, hi.x),
            self.range(lo.y, hi.y),
            self.range(lo.z, hi.z),
        )
    }

    /// Uniform on the unit sphere: z = 1 − 2ξ1, φ = 2πξ2.
    pub fn unit_vector(&mut self) -> Vec3 {
        let z = 1.0 - 2.0 * self.f32();
        let phi = std::f32::consts::TAU * self.f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// An indexed triangle list.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    /// The number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// Appends `other`'s triangles.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.indices
            .extend(other.indices.iter().map(|t| t.map(|i| i + base)));
    }

    /// (min, max) of the positions; (0, 0) when empty.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        if self.positions.is_empty() {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        self.positions
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            })
    }
}

/// The inside of the box [lo, hi]: 12 triangles facing inwards.
pub fn box_room(lo: Vec3, hi: Vec3) -> Mesh {
    let positions = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    // Faces as corner quads (bit i of a corner index is its axis-i side), wound inwards.
    let quads: [[u32; 4]; 6] = [
        [0, 2, 6, 4], // x = lo
        [1, 5, 7, 3], // x = hi
        [0, 4, 5, 1], // y = lo
        [2, 3, 7, 6], // y = hi
        [0, 1, 3, 2], // z = lo
        [4, 6, 7, 5], // z = hi
    ];
    let indices = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    Mesh { positions, indices }
}

/// An n×n grid over [lo.xz, hi.xz] at height lo.y + a sum of sines and per-vertex noise up to
/// `amplitude`: 2n² triangles.
pub fn terrain(n: usize, lo: Vec3, hi: Vec3, amplitude: f32, rng: &mut Rng) -> Mesh {
    let n = n.max(1);
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            let (s, t) = (i as f32 / n as f32, j as f32 / n as f32);
            let wave = (s * 11.0).sin() * (t * 7.0).cos() * 0.5 + (s * 31.0 + t * 17.0).sin() * 0.2;
            let h = lo.y + amplitude * (0.5 + 0.6 * wave + 0.15 * rng.f32());
            positions.push(Vec3::new(
                lo.x + s * (hi.x - lo.x),
                h,
                lo.z + t * (hi.z - lo.z),
            ));
        }
    }
    let row = (n + 1) as u32;
    let mut indices = Vec::with_capacity(2 * n * n);
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * row + i;
            indices.push([a, a + row, a + 1]);
            indices.push([a + 1, a + row, a + row + 1]);
        }
    }
    Mesh { positions, indices }
}

/// An icosphere subdivided `subdivisions` times (20·4^s triangles) around `center`, its radius
/// displaced by up to ±`bumpiness`·radius with noise.
pub fn icosphere(
    center: Vec3,
    radius: f32,
    subdivisions: u32,
    bumpiness: f32,
    rng: &mut Rng,
) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut indices: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]).normalize());
                positions.len() as u32 - 1
            })
        };
        indices = indices
            .iter()
            .flat_map(|&[a, b, c]| {
                let ab = mid(a, b, &mut positions);
                let bc = mid(b, c, &mut positions);
                let ca = mid(c, a, &mut positions);
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    for p in &mut positions {
        let bump = 1.0 + bumpiness * (2.0 * rng.f32() - 1.0);
        *p = center + *p * radius * bump;
    }
    Mesh { positions, indices }
}

/// `count` unconnected triangles in [lo, hi], each a random centre plus edges up to `size`.
pub fn random_triangles(count: usize, lo: Vec3, hi: Vec3, size: f32, rng: &mut Rng) -> Mesh {
    let mut m = Mesh::default();
    for k in 0..count as u32 {
        let c = rng.in_box(lo, hi);
        for _ in 0..3 {
            m.positions.push(c + rng.unit_vector() * size * rng.f32());
        }
        m.indices.push([3 * k, 3 * k + 1, 3 * k + 2]);
    }
    m
}

/// A test scene of about `triangles` triangles in the room [−10, 10]×[0, 10]×[−10, 10]: the room,
/// a terrain (~50 %), displaced icospheres (~30 %, several overlapping layers along most rays)
/// and loose random triangles (the rest, large and thin ones included).
pub fn test_scene(triangles: usize, seed: u64) -> Mesh {
    let mut rng = Rng::new(seed);
    let (lo, hi) = (Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 10.0, 10.0));
    let mut scene = box_room(lo, hi);
    let grid = ((triangles as f32 * 0.25).sqrt() as usize).max(2);
    scene.append(&terrain(
        grid,
        Vec3::new(-9.5, 0.2, -9.5),
        Vec3::new(9.5, 0.0, 9.5),
        2.0,
        &mut rng,
    ));
    // Spheres of 20·4^s triangles: the largest s that fits ~30 % in 4..=8 spheres.
    let sphere_budget = triangles as f32 * 0.3;
    let s = (0..10u32)
        .rev()
        .find(|&s| 20.0 * 4f32.powi(s as i32) * 4.0 <= sphere_budget)
        .unwrap_or(0);
    let spheres = ((sphere_budget / (20.0 * 4f32.powi(s as i32))) as usize).clamp(1, 8);
    for _ in 0..spheres {
        let center = rng.in_box(Vec3::new(-6.0, 2.5, -6.0), Vec3::new(6.0, 7.5, 6.0));
        let radius = rng.range(1.0, 2.5);
        scene.append(&icosphere(center, radius, s, 0.05, &mut rng));
    }
    let rest = triangles.saturating_sub(scene.triangle_count());
    let loose = random_triangles(
        rest,
        Vec3::new(-9.0, 0.5, -9.0),
        Vec3::new(9.0, 9.5, 9.0),
        0.6,
        &mut rng,
    );
    scene.append(&loose);
    scene
}

/// Pinhole camera rays, one per pixel centre of a width×height image: from `eye` towards
/// `target`, vertical field of view `yfov` radians, unit directions, tmax = ∞.
pub fn camera_rays(eye: Vec3, target: Vec3, yfov: f32, width: u32, height: u32) -> Vec<GpuRay> {
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan = (0.5 * yfov).tan();
    let aspect = width as f32 / height as f32;
    let mut rays = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let sx = (2.0 * (x as f32 + 0.5) / width as f32 - 1.0) * tan * aspect;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / height as f32) * tan;
            let dir = (forward + sx * right + sy * up).normalize();
            rays.push(GpuRay::new(eye, dir, f32::INFINITY));
        }
    }
    rays
}

/// `count` rays from uniform points in [lo, hi] in uniform directions; a quarter of them with a
/// finite tmax in (0, |hi − lo|/4) (short occlusion-style rays), the rest unbounded.
pub fn random_rays(count: usize, lo: Vec3, hi: Vec3, rng: &mut Rng) -> Vec<GpuRay> {
    let reach = (hi - lo).length() * 0.25;
    (0..count)
        .map(|k| {
            let origin = rng.in_box(lo, hi);
            let dir = rng.unit_vector();
            let tmax = if k % 4 == 3 {
                rng.range(1e-3, 1.0) * reach
            } else {
                f32::INFINITY
            };
            GpuRay::new(origin, dir, tmax)
        })
        .collect()
}
