//! Flakes over texture space and their counting over a footprint (Jakob et al. 2014; Wang et
//! al. 2018).
//!
//! The flakes of a material are a fixed procedural set over the UV torus [0, 1)²: the root of a
//! quadtree holds Poisson(density) flakes, and every node splits its count among its four
//! children by binomial draws keyed on the node itself, so any node's count is one
//! deterministic number and nested footprints give nested counts. Leaves (≤ [`LEAF_FLAKES`]
//! flakes) place their flakes uniformly, from pcg3d keyed on (leaf, k). Which flakes are lit for
//! a query (each with probability P(ωi, ωo, γ), keyed on the direction cell of the query — the
//! half vector quantised to cells of size γ — never on the traversal) is [`crate::lit`]'s.

use crate::tea::{pcg3d, tea_unit, unit};
use glam::{DMat2, DVec2, DVec3};

/// Leaves hold at most this many flakes. A leaf's lit flakes are a run of its flakes
/// ([`crate::lit`]), so a boundary leaf costs its lit flakes, not its flakes, and large leaves
/// cut the levels a walk splits its lit counts through. On lavapipe, against 64-flake leaves
/// scanned by selection sampling: `glint_gpu_count` 207 → 110 ms (256: 132 ms, 512: 111 ms); the
/// CPU query of 3000 flakes 9.2 → 3.9 µs. Every split is of more than [`BINOMIAL_EXACT_MAX`]
/// flakes and takes the normal approximation.
pub const LEAF_FLAKES: u64 = 1024;
/// The third word of the pcg3d hash of a node's position split (its three uniforms; WGSL:
/// `SPLIT_SALT` in `shaders/glint/flakes.inc.wgsl`).
pub const SPLIT_SALT: u32 = 0x5851_f42d;
/// The third word of the pcg3d hash of a flake's position (WGSL: `POSITION_SALT`).
pub const POSITION_SALT: u32 = 0x68e3_1da4;
/// Deepest level of the quadtree (2²⁰ cells per side).
pub const MAX_DEPTH: u32 = 20;
/// Deepest level whose nodes' flake counts a [`SplitTable`] holds (4⁸ nodes, 256 KiB there).
pub const SPLIT_TABLE_LEVELS: u32 = 8;
/// Binomial splits of up to this many flakes are exact inverse CDFs; larger ones use the
/// continuity-corrected normal approximation. Kept small because the exact search is a loop, and
/// llvmpipe (lavapipe) caps a loop's iterations per invocation at 65 535: at 100 a GPU walk over
/// a footprint of more than ~3000 flakes came back short; at 24, ~5500.
pub const BINOMIAL_EXACT_MAX: u64 = 24;

/// A procedural flake field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlakeField {
    /// Expected flakes per unit UV area.
    pub density: f64,
    /// Selects another, independent field.
    pub seed: u32,
}

/// An ellipse in UV: points c + s·a + t·b with s² + t² ≤ 1 (a, b conjugate semi-axes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Centre in UV.
    pub center: DVec2,
    /// First half-axis in UV.
    pub a: DVec2,
    /// Second half-axis in UV.
    pub b: DVec2,
}

impl Footprint {
    /// Area in UV units.
    pub fn area(&self) -> f64 {
        PI * (self.a.x * self.b.y - self.a.y * self.b.x).abs()
    }

    /// The same ellipse scaled about its centre.
    pub fn scaled(&self, k: f64) -> Footprint {
        Footprint {
            a: self.a * k,
            b: self.b * k,
            ..*self
        }
    }

    pub(crate) fn half_extent(&self) -> DVec2 {
        DVec2::new(self.a.x.hypot(self.b.x), self.a.y.hypot(self.b.y))
    }

    /// The copies of the ellipse, shifted by whole periods of the UV torus, that reach into
    /// [0, 1)².
    pub(crate) fn copies(&self) -> Vec<Footprint> {
        let ext = self.half_extent();
        let lo = (self.center - ext).floor();
        let hi = (self.center + ext).floor();
        let mut out = Vec::new();
        for sx in lo.x as i64..=hi.x as i64 {
            for sy in lo.y as i64..=hi.y as i64 {
                out.push(Footprint {
                    center: self.center - DVec2::new(sx as f64, sy as f64),
                    ..*self
                });
            }
        }
        out
    }

    /// Whether `uv` lies in the ellipse; `inv` is [`Footprint::inverse`].
    pub(crate) fn contains(&self, inv: &DMat2, uv: DVec2) -> bool {
        (*inv * (uv - self.center)).length_squared() <= 1.0
    }

    /// The inverse of [a b], mapping offsets to (s, t).
    pub(crate) fn inverse(&self) -> DMat2 {
        DMat2::from_cols(self.a, self.b).inverse()
    }
}

use std::f64::consts::PI;

/// The direction cell of a query: the half vector in the azimuthal equidistant projection
/// (θh cos φh, θh sin φh), where distances are at least the angles on the sphere, quantised to
/// squares of side γ/√2. Moving the light by more than 2γ moves the half vector by about γ or
/// more, which always changes the cell; a move below γ/4 changes it about one time in four.
pub fn direction_cell(wi: DVec3, wo: DVec3, gamma: f64) -> (u32, u32) {
    let c = direction_coords(wi, wo, gamma).floor();
    let q = |x: f64| (x as i64 + (1 << 24)) as u32;
    (q(c.x), q(c.y))
}

/// The half vector's position in cells: (θh cos φh, θh sin φh) / (γ/√2); the cell is its floor.
pub fn direction_coords(wi: DVec3, wo: DVec3, gamma: f64) -> DVec2 {
    let h = (wi + wo).normalize();
    let r = h.x.hypot(h.y);
    let theta = h.z.clamp(-1.0, 1.0).acos();
    let k = if r > 1e-12 { theta / r } else { 1.0 };
    DVec2::new(h.x, h.y) * (k / (gamma / std::f64::consts::SQRT_2))
}

/// A flake found by a query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flake {
    /// Its identity: the same flake has the same id in every query.
    pub id: u64,
    /// Position in UV.
    pub uv: DVec2,
}

impl FlakeField {
    pub(crate) fn node_hash(&self, level: u32, ix: u32, iy: u32) -> u64 {
        let v = pcg3d([ix | (level << 21), iy, self.seed.wrapping_mul(0x9e37_79b9)]);
        ((v[1] as u64) << 32) | v[0] as u64
    }

    /// Flakes in the root (the whole torus).
    pub fn root_count(&self) -> u64 {
        poisson(self.density, tea_unit(0xffff_ffff, self.seed) as f64)
    }

    /// Counts of the four children (x-major: (0,0), (1,0), (0,1), (1,1)) of a node with n flakes.
    pub(crate) fn split(&self, level: u32, ix: u32, iy: u32, n: u64) -> [u64; 4] {
        let h = self.node_hash(level, ix, iy);
        let u = pcg3d([h as u32, (h >> 32) as u32, SPLIT_SALT]).map(unit);
        let left = binomial(n, u[0]);
        let (l0, r0) = (binomial(left, u[1]), binomial(n - left, u[2]));
        [l0, r0, left - l0, n - left - r0]
    }

    /// The flake counts of the top of the quadtree, drawn once ([`SplitTable`]).
    pub fn split_table(&self) -> SplitTable {
        let mut counts = vec![self.root_count() as u32];
        let (mut levels, mut first) = (0, 0);
        while levels < SPLIT_TABLE_LEVELS.min(MAX_DEPTH) {
            let side = 1u32 << levels;
            let parents = &counts[first..];
            if parents.iter().all(|&n| n as u64 <= LEAF_FLAKES) {
                break;
            }
            // Level + 1, row-major: the children of (ix, iy) at (2 ix + dx, 2 iy + dy).
            let mut next = vec![0u32; 4 * parents.len()];
            for (i, &n) in parents.iter().enumerate() {
                if n as u64 <= LEAF_FLAKES {
                    continue; // a leaf: its children are never read
                }
                let (ix, iy) = (i as u32 % side, i as u32 / side);
                for (k, c) in self.split(levels, ix, iy, n as u64).into_iter().enumerate() {
                    let (x, y) = (2 * ix + (k as u32 & 1), 2 * iy + (k as u32 >> 1));
                    next[(y * 2 * side + x) as usize] = c as u32;
                }
            }
            first = counts.len();
            counts.extend(next);
            levels += 1;
        }
        SplitTable { levels, counts }
    }

    /// Every flake inside the footprint (UVs wrap), found through the quadtree.
    pub fn flakes_in(&self, fp: &Footprint) -> Vec<Flake> {
        let mut out = Vec::new();
        let ext = fp.half_extent();
        for shifted in fp.copies() {
            let inv = shifted.inverse();
            self.visit(&shifted, &inv, ext, 0, 0, 0, self.root_count(), &mut out);
        }
        out
    }

    /// Flake `k` of the leaf (level, ix, iy) whose cell starts at `min` with side `size`.
    pub(crate) fn leaf_flake(&self, h: u64, k: u32, min: DVec2, size: f64) -> Flake {
        Self::flake_at(Self::leaf_flake_id(h, k), min, size)
    }

    /// The id of flake `k` of the leaf whose node hash is `h` (one pcg3d; its position takes
    /// one more, [`FlakeField::flake_at`]).
    pub(crate) fn leaf_flake_id(h: u64, k: u32) -> u64 {
        let v = pcg3d([h as u32 ^ k.wrapping_mul(0x85eb_ca6b), (h >> 32) as u32, k]);
        ((v[1] as u64) << 32) | v[0] as u64
    }

    /// The flake of id `id` in the leaf cell starting at `min` with side `size`.
    pub(crate) fn flake_at(id: u64, min: DVec2, size: f64) -> Flake {
        let u = pcg3d([id as u32, (id >> 32) as u32, POSITION_SALT]).map(unit);
        Flake {
            id,
            uv: min + size * DVec2::new(u[0], u[1]),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn visit(
        &self,
        fp: &Footprint,
        inv: &DMat2,
        ext: DVec2,
        level: u32,
        ix: u32,
        iy: u32,
        n: u64,
        out: &mut Vec<Flake>,
    ) {
        if n == 0 {
            return;
        }
        let size = 1.0 / (1u64 << level) as f64;
        let min = DVec2::new(ix as f64, iy as f64) * size;
        let max = min + size;
        if max.x < fp.center.x - ext.x
            || min.x > fp.center.x + ext.x
            || max.y < fp.center.y - ext.y
            || min.y > fp.center.y + ext.y
        {
            return;
        }
        if n <= LEAF_FLAKES || level == MAX_DEPTH {
            let h = self.node_hash(level, ix, iy);
            for k in 0..n as u32 {
                let flake = self.leaf_flake(h, k, min, size);
                if fp.contains(inv, flake.uv) {
                    out.push(flake);
                }
            }
            return;
        }
        let c = self.split(level, ix, iy, n);
        for (k, &m) in c.iter().enumerate() {
            let (dx, dy) = ((k & 1) as u32, (k >> 1) as u32);
            self.visit(fp, inv, ext, level + 1, 2 * ix + dx, 2 * iy + dy, m, out);
        }
    }
}

/// The flake counts of the quadtree's nodes from the root down to `levels` (at most
/// [`SPLIT_TABLE_LEVELS`], and no deeper than the deepest inner node's children), level by
/// level, each level row-major (iy · 2^level + ix; level d starts at (4^d − 1) / 3), as
/// the position splits draw them (the children of a leaf hold 0). A GPU walk reads a node's
/// children's counts here instead of drawing them (`split_table` in
/// `shaders/glint/flakes.inc.wgsl`): the CPU's draws (f64), not three f32 normal quantiles a node.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitTable {
    /// The deepest level held.
    pub levels: u32,
    /// The counts.
    pub counts: Vec<u32>,
}

/// Inverse CDF of Poisson(mean) at u; a normal approximation above mean 500.
pub fn poisson(mean: f64, u: f64) -> u64 {
    if mean <= 0.0 {
        return 0;
    }
    if mean > 500.0 {
        return (mean + mean.sqrt() * normal_quantile(u) + 0.5).max(0.0) as u64;
    }
    let (mut k, mut p) = (0u64, (-mean).exp());
    let mut cdf = p;
    while cdf < u && k < 10_000 {
        k += 1;
        p *= mean / k as f64;
        cdf += p;
    }
    k
}

/// Inverse CDF of Binomial(n, ½) at u; the normal approximation above [`BINOMIAL_EXACT_MAX`].
pub fn binomial(n: u64, u: f64) -> u64 {
    if n == 0 {
        return 0;
    }
    if n > BINOMIAL_EXACT_MAX {
        let x = n as f64 / 2.0 + (n as f64).sqrt() / 2.0 * normal_quantile(u) + 0.5;
        return (x.max(0.0) as u64).min(n);
    }
    let (mut k, mut p) = (0u64, 0.5f64.powi(n as i32));
    let mut cdf = p;
    while cdf < u && k < n {
        p *= (n - k) as f64 / (k + 1) as f64;
        k += 1;
        cdf += p;
    }
    k
}

/// The standard normal quantile (Acklam's rational approximation, |error| < 1.2e-9); the WGSL
/// twin is in `shaders/glint/flakes.inc.wgsl`.
pub fn normal_quantile(u: f64) -> f64 {
    let p = u.clamp(1e-12, 1.0 - 1e-12);
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table holds what the splits draw: each inner node's children as `split` gives
    /// them, every level's counts summing to the root's until the leaves stop it, and it stops
    /// at the first level of leaves only (or at `SPLIT_TABLE_LEVELS`).
    #[test]
    fn split_table_holds_the_splits() {
        for density in [3.0e3, 3.0e5, 2.0e6, 5.0e8] {
            let field = FlakeField { density, seed: 7 };
            let t = field.split_table();
            let start = |d: u32| (((1u64 << (2 * d)) - 1) / 3) as usize;
            assert_eq!(t.counts.len(), start(t.levels + 1), "density {density}");
            assert_eq!(t.counts[0] as u64, field.root_count());
            for d in 0..t.levels {
                let side = 1u32 << d;
                let mut leaves = 0;
                for iy in 0..side {
                    for ix in 0..side {
                        let n = t.counts[start(d) + (iy * side + ix) as usize] as u64;
                        let child = |dx: u32, dy: u32| {
                            let i =
                                start(d + 1) + ((2 * iy + dy) * 2 * side + 2 * ix + dx) as usize;
                            t.counts[i] as u64
                        };
                        let kids = [child(0, 0), child(1, 0), child(0, 1), child(1, 1)];
                        if n <= LEAF_FLAKES {
                            leaves += 1;
                            assert_eq!(kids, [0; 4]);
                        } else {
                            assert_eq!(kids, field.split(d, ix, iy, n), "{d} {ix} {iy}");
                        }
                    }
                }
                // Not all of level d are leaves, else the table would have stopped above.
                assert!(
                    leaves < side * side,
                    "density {density}: level {d} all leaves"
                );
            }
            let last = &t.counts[start(t.levels)..];
            assert!(
                t.levels == SPLIT_TABLE_LEVELS || last.iter().all(|&n| n as u64 <= LEAF_FLAKES),
                "density {density}: stopped at {} with inner nodes left",
                t.levels
            );
        }
    }
}
