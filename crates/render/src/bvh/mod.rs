//! The scene's acceleration structure: an obvhs compressed wide BVH8 (CWBVH, Ylitie, Karras and
//! Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", HPG 2017),
//! built on the CPU, queried on the CPU as the reference, and uploaded for the WGSL traversal in
//! `shaders/render/bvh.inc.wgsl`.
//!
//! ```
//! use facet_render::bvh::{Bvh, BvhConfig};
//! use glam::Vec3;
//! let positions = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
//! let bvh = Bvh::build(&positions, &[[0, 1, 2]], BvhConfig::default());
//! let hit = bvh.closest_hit(Vec3::new(0.0, 0.0, 1.0), Vec3::NEG_Z, f32::INFINITY).unwrap();
//! assert_eq!(hit.prim, 0);
//! assert!((hit.t - 1.0).abs() < 1e-6);
//! ```

/// Procedural geometry and rays for the tests and the benchmarks (feature `bench-scenes`).
#[cfg(feature = "bench-scenes")]
pub mod procedural;
pub mod query;

use facet_gpu::{GpuError, buffer};
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::cwbvh::node::CwBvhNode;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use std::time::{Duration, Instant};

/// obvhs's build presets, fastest build (slowest traversal) to slowest build.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BvhPreset {
    /// obvhs's `fastest_build`.
    Fastest,
    /// obvhs's `very_fast_build`.
    VeryFast,
    /// obvhs's `fast_build`.
    Fast,
    #[default]
    /// obvhs's `medium_build`.
    Medium,
    /// Pre-splits large triangles: a triangle may sit in several leaves.
    Slow,
    /// Pre-splits large triangles, as `Slow`.
    VerySlow,
}

impl BvhPreset {
    /// Every preset, fastest build first.
    pub const ALL: [BvhPreset; 6] = [
        BvhPreset::Fastest,
        BvhPreset::VeryFast,
        BvhPreset::Fast,
        BvhPreset::Medium,
        BvhPreset::Slow,
        BvhPreset::VerySlow,
    ];

    /// The obvhs parameters of this preset.
    pub const fn params(self) -> BvhBuildParams {
        match self {
            BvhPreset::Fastest => BvhBuildParams::fastest_build(),
            BvhPreset::VeryFast => BvhBuildParams::very_fast_build(),
            BvhPreset::Fast => BvhBuildParams::fast_build(),
            BvhPreset::Medium => BvhBuildParams::medium_build(),
            BvhPreset::Slow => BvhBuildParams::slow_build(),
            BvhPreset::VerySlow => BvhBuildParams::very_slow_build(),
        }
    }
}

/// How the BVH is built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BvhConfig {
    /// Build quality against build time.
    pub preset: BvhPreset,
}

impl BvhConfig {
    /// For interactive edits: the quickest build.
    pub const fn fastest() -> Self {
        BvhConfig {
            preset: BvhPreset::Fastest,
        }
    }
    /// The default: about embree's build time with faster traversal (obvhs's words).
    pub const fn medium() -> Self {
        BvhConfig {
            preset: BvhPreset::Medium,
        }
    }
    /// For final renders of static scenes: the best traversal.
    pub const fn very_slow() -> Self {
        BvhConfig {
            preset: BvhPreset::VerySlow,
        }
    }
}

/// A ray–triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray in units of `dir` (p = origin + t·dir).
    pub t: f32,
    /// Index of the triangle in the `indices` given to [`Bvh::build`].
    pub prim: u32,
    /// Barycentrics: p = (1−u−v)·v0 + u·v1 + v·v2, vertices in the triangle's index order.
    pub u: f32,
    /// See `u`.
    pub v: f32,
}

/// A CWBVH over a triangle list, and the triangles (in their original order).
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Empty (no nodes) when there are no triangles.
    pub cwbvh: CwBvh,
    /// The triangles as given, `triangles[i]` from `indices[i]`; leaves refer to them through
    /// `cwbvh.primitive_indices`.
    pub triangles: Vec<Triangle>,
    /// Wall-clock build time, milliseconds (obvhs's core build plus the triangle gather).
    pub build_ms: f64,
}

/// (u, v, inv_det) of obvhs's Möller–Trumbore test (`Triangle::intersect`), with the same
/// operations in the same order so that the values are bit-identical to the ones it tested:
/// e1 = v0 − v1, e2 = v2 − v0, n = e1 × e2, c = v0 − o, r = d × c, u = (r·e2)/(n·d),
/// v = (r·e1)/(n·d). By Cramer's rule on o + t·d = v0 + u·(v1 − v0) + v·(v2 − v0) these are
/// already the weights of v1 and v2, so no conversion is needed.
fn barycentrics(tri: &Triangle, ray: &Ray) -> (f32, f32) {
    let e1 = tri.v0 - tri.v1;
    let e2 = tri.v2 - tri.v0;
    let n = e1.cross(e2);
    let c = tri.v0 - ray.origin;
    let r = ray.direction.cross(c);
    let inv_det = 1.0 / n.dot(ray.direction);
    (r.dot(e2) * inv_det, r.dot(e1) * inv_det)
}

impl Bvh {
    /// Builds the BVH over `indices` (triangles of `positions`). Panics if an index is out of
    /// range (a scene loader validates indices first).
    pub fn build(positions: &[Vec3], indices: &[[u32; 3]], config: BvhConfig) -> Bvh {
        let start = Instant::now();
        let triangles: Vec<Triangle> = indices
            .iter()
            .map(|&[a, b, c]| Triangle {
                v0: positions[a as usize].into(),
                v1: positions[b as usize].into(),
                v2: positions[c as usize].into(),
            })
            .collect();
        if triangles.is_empty() {
            // obvhs's builder needs at least one primitive; no nodes makes every query miss.
            return Bvh::default();
        }
        let cwbvh =
            build_cwbvh_from_tris(&triangles, config.preset.params(), &mut Duration::default());
        let bvh = Bvh {
            cwbvh,
            triangles,
            build_ms: start.elapsed().as_secs_f64() * 1e3,
        };
        // Debug builds check every tree they build (tests too: the test profile keeps debug
        // assertions on at opt-level 2). obvhs 0.4's builder runs the same check under its own
        // `cfg(debug_assertions)`; this one does not depend on obvhs keeping it, nor on how
        // obvhs itself was compiled.
        #[cfg(debug_assertions)]
        bvh.validate();
        bvh
    }

    /// Checks the tree with obvhs's `CwBvh::validate` against [`Bvh::triangles`]: every node
    /// and primitive slot reached exactly once, one slot per triangle (without spatial
    /// splits), each node's origin inside its parent's child box, the child metadata
    /// consistent with `imask`, and the depth under obvhs's traversal stack of 32 entries
    /// (`BVH_STACK_SIZE` of the WGSL traversal too). Without spatial splits, each triangle must
    /// also lie inside the box of the node holding its leaf (not checked for leaves of the
    /// root, nor at all with the pre-split presets). Panics on the first violation; returns
    /// obvhs's statistics. Linear in the tree's size: about 2 ms for 2·10^4 triangles at the
    /// test profile's opt-level, against about 26 ms for the build. Debug builds run it after
    /// every [`Bvh::build`].
    pub fn validate(&self) -> obvhs::cwbvh::CwBvhValidationResult {
        if self.is_empty() {
            return Default::default();
        }
        self.cwbvh.validate(&self.triangles, false)
    }

    /// Whether the BVH holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.cwbvh.nodes.is_empty()
    }

    /// obvhs's ray: tmin 0 for triangles (its node test clips at 1e-4 by itself), the inverse
    /// direction through `safe_inverse`.
    ///
    /// Deviation from obvhs: −0.0 direction components become +0.0. obvhs inverts them to
    /// −1/ε (`signum` reads the sign bit) but picks the slab ends and child order with `d < 0`
    /// (false for −0.0), so such a ray misses every box it starts inside. The WGSL traversal
    /// does the same (`bvh_traverse`).
    pub fn ray(origin: Vec3, dir: Vec3, tmax: f32) -> Ray {
        let dir = Vec3::select(dir.cmpeq(Vec3::ZERO), Vec3::ZERO, dir);
        Ray::new(origin.into(), dir.into(), 0.0, tmax)
    }

    fn triangle(&self, slot: usize) -> &Triangle {
        &self.triangles[self.cwbvh.primitive_indices[slot] as usize]
    }

    /// The nearest hit with t < tmax (obvhs `ray_traverse`), the CPU reference of WGSL
    /// `trace_closest`.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, tmax: f32) -> Option<Hit> {
        if self.is_empty() {
            return None;
        }
        let ray = Self::ray(origin, dir, tmax);
        let mut hit = RayHit::none();
        if !self
            .cwbvh
            .ray_traverse(ray, &mut hit, |r, slot| self.triangle(slot).intersect(r))
        {
            return None;
        }
        let slot = hit.primitive_id as usize;
        // The ray the traversal tested with differs from `ray` only in tmax, which u and v ignore.
        let (u, v) = barycentrics(self.triangle(slot), &ray);
        Some(Hit {
            t: hit.t,
            prim: self.cwbvh.primitive_indices[slot],
            u,
            v,
        })
    }

    /// Whether any triangle lies at t < tmax (obvhs `ray_traverse_miss`), the CPU reference of
    /// WGSL `trace_any`.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmax: f32) -> bool {
        if self.is_empty() {
            return false;
        }
        let ray = Self::ray(origin, dir, tmax);
        !self
            .cwbvh
            .ray_traverse_miss(ray, |r, slot| self.triangle(slot).intersect(r))
    }

    /// The point of `hit` from its barycentrics, for checks: (1−u−v)·v0 + u·v1 + v·v2.
    pub fn hit_point(&self, hit: &Hit) -> Vec3 {
        let t = &self.triangles[hit.prim as usize];
        Vec3::from((1.0 - hit.u - hit.v) * t.v0 + hit.u * t.v1 + hit.v * t.v2)
    }
}

/// The BVH in GPU storage buffers, as `shaders/render/bvh.inc.wgsl` reads them.
pub struct GpuBvh {
    /// `array<CwNode>`: obvhs's 80-byte `CwBvhNode`s as they are.
    pub nodes: wgpu::Buffer,
    /// `array<u32>`: per primitive slot of the leaves, the original triangle index.
    pub primitives: wgpu::Buffer,
    /// `array<vec4<f32>>`: per primitive slot its three vertices (w unused), in slot order so
    /// that traversal reads them without the indirection through `primitives`.
    pub triangles: wgpu::Buffer,
    /// Number of nodes (0 for an empty scene, whose buffers hold one inert placeholder each).
    pub node_count: u32,
}

impl GpuBvh {
    /// Uploads `bvh`. An empty BVH gets one zeroed node (no children: every ray misses), so
    /// that no binding is zero-sized.
    pub fn upload(device: &wgpu::Device, bvh: &Bvh) -> Result<GpuBvh, GpuError> {
        let (nodes, primitives, vertices): (Vec<CwBvhNode>, Vec<u32>, Vec<[f32; 4]>) =
            if bvh.is_empty() {
                (
                    vec![CwBvhNode::default()],
                    vec![u32::MAX],
                    vec![[0.0; 4]; 3],
                )
            } else {
                let v4 = |p: Vec3A| [p.x, p.y, p.z, 0.0];
                let vertices = bvh
                    .cwbvh
                    .primitive_indices
                    .iter()
                    .flat_map(|&i| {
                        let t = &bvh.triangles[i as usize];
                        [v4(t.v0), v4(t.v1), v4(t.v2)]
                    })
                    .collect();
                (
                    bvh.cwbvh.nodes.clone(),
                    bvh.cwbvh.primitive_indices.clone(),
                    vertices,
                )
            };
        let bytes = |n: usize, size: usize| (n * size) as u64;
        buffer::check_binding(device, "BVH nodes", bytes(nodes.len(), 80))?;
        buffer::check_binding(device, "BVH primitives", bytes(primitives.len(), 4))?;
        buffer::check_binding(device, "BVH triangles", bytes(vertices.len(), 16))?;
        Ok(GpuBvh {
            nodes: buffer::storage(device, "bvh nodes", &nodes),
            primitives: buffer::storage(device, "bvh primitives", &primitives),
            triangles: buffer::storage(device, "bvh triangles", &vertices),
            node_count: bvh.cwbvh.nodes.len() as u32,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_is_80_bytes() {
        // The WGSL CwNode mirrors this layout word for word.
        assert_eq!(std::mem::size_of::<CwBvhNode>(), 80);
    }
}
