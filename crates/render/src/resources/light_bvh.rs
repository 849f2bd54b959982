//! The light BVH (Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive
//! Tree Splitting"; pbrt-v4's `BVHLightSampler`): punctual lights and emissive triangles in a
//! binary tree whose nodes bound their lights' positions (a box), emission directions (a cone of
//! axes of half-angle θo, emission falling to 0 within θe beyond it) and power φ. A shading point
//! (p, n) walks down from the root choosing a child with probability ∝ its importance — a bound on
//! what the child's lights can deliver to p (`LightBounds::importance`; ½ each where both
//! bounds are 0, so that the pmf is a distribution everywhere) — so a lamp beside p
//! gets the light samples a lamp across the room does not; the probability of a light is the
//! product of the choices on its path, which `LightBvh::pmf` recomputes from the leaf up, as the
//! WGSL does (`shaders/render/light_tree.inc.wgsl`) for MIS when a BSDF sample hits an emitter.
//!
//! Units: φ bounds the irradiance numerator — a point or spot light's intensity I (E = I cos/d²),
//! an emissive triangle's Le·A (E ≤ Le A cos/d²) — so that lights of different kinds compare.

use crate::layout::gpu_types::NONE;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use std::f32::consts::PI;

/// What a light or a cluster of lights can emit, where and in which directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Box of the emitting positions.
    pub lo: Vec3,
    /// Its other corner.
    pub hi: Vec3,
    /// Axis of the cone of emission axes (unit).
    pub w: Vec3,
    /// Power bound φ (see the module doc).
    pub phi: f32,
    /// cos θo: the emission axes lie within θo of `w` (−1: all directions).
    pub cos_o: f32,
    /// cos θe: emission reaches θe beyond an emission axis (0: a hemisphere, π/2).
    pub cos_e: f32,
}

/// cos(max(0, a − b)) from the sines and cosines of a, b ∈ [0, π].
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// sin(max(0, a − b)).
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

impl LightBounds {
    /// A point light of intensity `i` (luminance), emitting in every direction.
    pub fn point(p: Vec3, i: f32) -> Self {
        LightBounds {
            lo: p,
            hi: p,
            w: Vec3::Z,
            phi: i,
            cos_o: -1.0,
            cos_e: 0.0,
        }
    }

    /// A spot light at `p` along `w`: full intensity within `inner`, none beyond `outer`.
    pub fn spot(p: Vec3, w: Vec3, i: f32, inner: f32, outer: f32) -> Self {
        LightBounds {
            lo: p,
            hi: p,
            w: w.normalize_or(Vec3::Z),
            phi: i,
            cos_o: inner.cos(),
            cos_e: (outer - inner).max(0.0).cos(),
        }
    }

    /// A one-sided emissive triangle of radiance `le` (luminance): its box, its normal, Le·A.
    pub fn triangle(a: Vec3, b: Vec3, c: Vec3, le: f32) -> Self {
        let cross = (b - a).cross(c - a);
        LightBounds {
            lo: a.min(b).min(c),
            hi: a.max(b).max(c),
            w: cross.normalize_or(Vec3::Z),
            phi: le * 0.5 * cross.length(),
            cos_o: 1.0,
            cos_e: 0.0,
        }
    }

    /// The bounds of both (pbrt-v4's `Union` of light bounds and of direction cones).
    pub fn union(&self, o: &LightBounds) -> LightBounds {
        if self.phi == 0.0 {
            return *o;
        }
        if o.phi == 0.0 {
            return *self;
        }
        let (w, cos_o) = cone_union((self.w, self.cos_o), (o.w, o.cos_o));
        LightBounds {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
            w,
            phi: self.phi + o.phi,
            cos_o,
            cos_e: self.cos_e.min(o.cos_e),
        }
    }

    /// The centre of the box.
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.lo + self.hi)
    }

    /// A bound on what these lights deliver to a point `p` whose geometric normal is `n` (zero:
    /// no normal): φ · cos θ'ₚ / d² · cos θ'ᵢ, where θ'ₚ bounds the angle between an emission
    /// axis and the direction to p less the spread of the box seen from p and θe, and θ'ᵢ the
    /// angle between n and the box less that spread. 0 when no light in the box can reach p's
    /// upper side: emission cones that face away, or the whole box below p's tangent plane.
    /// pbrt-v4's `LightBounds::Importance`, one-sided in n (this renderer reflects only).
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        GpuLightNode::new(self, 0, NONE, true).importance(p, n)
    }

    /// pbrt-v4's cost of a cluster for the split: φ · M_Ω · (solid angle of the cone of emission)
    /// · the box's surface area · Kr (the box's longest side over its side along `axis`).
    fn cost(&self, axis: usize) -> f32 {
        let theta_o = self.cos_o.clamp(-1.0, 1.0).acos();
        let theta_e = self.cos_e.clamp(-1.0, 1.0).acos();
        let theta_w = (theta_o + theta_e).min(PI);
        let sin_o = theta_o.sin();
        let m_omega = 2.0 * PI * (1.0 - self.cos_o)
            + PI / 2.0
                * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                    + self.cos_o);
        let d = self.hi - self.lo;
        let kr = d.max_element() / d[axis].max(1e-12);
        let area = 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
        self.phi * m_omega * kr * area
    }
}

/// The smallest cone holding two cones (axis, cos of half-angle) (pbrt-v4's `Union`).
fn cone_union(a: (Vec3, f32), b: (Vec3, f32)) -> (Vec3, f32) {
    // The common cases first, without an acos: a whole sphere, or the same cone.
    if a.1 <= -1.0 || a == b {
        return a;
    }
    if b.1 <= -1.0 {
        return b;
    }
    let theta_a = a.1.clamp(-1.0, 1.0).acos();
    let theta_b = b.1.clamp(-1.0, 1.0).acos();
    let theta_d = a.0.angle_between(b.0);
    if (theta_d + theta_b).min(PI) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(PI) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= PI {
        return (a.0, -1.0);
    }
    let theta_r = theta_o - theta_a;
    let wr = a.0.cross(b.0);
    if wr.length_squared() == 0.0 {
        return (a.0, -1.0);
    }
    let w = glam::Quat::from_axis_angle(wr.normalize(), theta_r) * a.0;
    (w, theta_o.cos())
}

/// WGSL `LightNode` (`shaders/render/light_tree.inc.wgsl`): a node of the light BVH, holding
/// what its importance needs: the box as its bounding sphere (centre, radius), the cone, φ.
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLightNode {
    /// xyz the centre of the box, w φ.
    pub centre_phi: [f32; 4],
    /// xyz the cone's axis, w cos θo.
    pub axis_cos_o: [f32; 4],
    /// Half the box's diagonal.
    pub radius: f32,
    pub cos_e: f32,
    /// sin θo.
    pub sin_o: f32,
    /// A leaf: the light's index; inside: the second child (the first is the next node).
    pub child: u32,
    /// The parent node (NONE at the root).
    pub parent: u32,
    /// 1 for a leaf.
    pub leaf: u32,
    pub pad0: u32,
    pub pad1: u32,
}

impl GpuLightNode {
    fn new(b: &LightBounds, child: u32, parent: u32, leaf: bool) -> Self {
        GpuLightNode {
            centre_phi: b.centroid().extend(b.phi).to_array(),
            axis_cos_o: b.w.extend(b.cos_o).to_array(),
            radius: 0.5 * (b.hi - b.lo).length(),
            cos_e: b.cos_e,
            sin_o: safe_sqrt(1.0 - b.cos_o * b.cos_o),
            child,
            parent,
            leaf: leaf as u32,
            pad0: 0,
            pad1: 0,
        }
    }

    /// [`LightBounds::importance`] of the lights below it (the WGSL's `light_node_importance`).
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let phi = self.centre_phi[3];
        if phi <= 0.0 {
            return 0.0;
        }
        let pc = Vec3::from_slice(&self.centre_phi[..3]);
        let w = Vec3::from_slice(&self.axis_cos_o[..3]);
        let cos_o = self.axis_cos_o[3];
        let dc2 = p.distance_squared(pc);
        // pbrt's clamp: d² at least half the box's diagonal (the radius), so no cluster is
        // favoured without bound near its centre.
        let d2 = dc2.max(self.radius);
        let wi = if dc2 > 0.0 {
            (p - pc) / dc2.sqrt()
        } else {
            Vec3::ZERO
        };
        let cos_w = w.dot(wi);
        let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
        // The cone of directions from p toward the box's bounding sphere.
        let r2 = self.radius * self.radius;
        let cos_b = if dc2 < r2 {
            -1.0
        } else {
            safe_sqrt(1.0 - r2 / dc2)
        };
        let sin_b = safe_sqrt(1.0 - cos_b * cos_b);
        let cos_x = cos_sub_clamped(sin_w, cos_w, self.sin_o, cos_o);
        let sin_x = sin_sub_clamped(sin_w, cos_w, self.sin_o, cos_o);
        let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
        if cos_p <= self.cos_e {
            return 0.0;
        }
        let mut importance = phi * cos_p / d2;
        if n != Vec3::ZERO {
            // The direction to the lights is −wi.
            let cos_i = (-wi).dot(n);
            let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
            importance *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b).max(0.0);
        }
        importance.max(0.0)
    }
}

/// Buckets per axis of the split search.
const BUCKETS: usize = 12;

/// The tree over some of a scene's lights.
#[derive(Clone, Debug, Default)]
pub struct LightBvh {
    /// Depth-first: a node's first child follows it.
    pub nodes: Vec<GpuLightNode>,
    /// Per light (of the scene's list), its leaf node; NONE for a light outside the tree.
    pub leaf_of: Vec<u32>,
}

impl LightBvh {
    /// The tree over `lights` (index in the scene's list of `n_lights`, bounds); lights of
    /// φ = 0 are left out (they never reach anything). Subtrees of many lights are built in
    /// parallel: a subtree of k lights takes the 2k − 1 nodes after its root's index, so each
    /// knows where its nodes go.
    pub fn build(lights: &[(u32, LightBounds)], n_lights: usize) -> Self {
        let mut items: Vec<(u32, LightBounds)> = lights
            .iter()
            .copied()
            .filter(|(_, b)| b.phi > 0.0)
            .collect();
        let mut nodes = vec![GpuLightNode::default(); (2 * items.len()).saturating_sub(1)];
        if !items.is_empty() {
            build_subtree(&mut nodes, &mut items, 0, NONE);
        }
        let mut leaf_of = vec![NONE; n_lights];
        for (i, node) in nodes.iter().enumerate() {
            if node.leaf == 1 {
                leaf_of[node.child as usize] = i as u32;
            }
        }
        LightBvh { nodes, leaf_of }
    }

    /// Whether it holds no light.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The importance of node `i` to (p, n).
    fn importance(&self, i: u32, p: Vec3, n: Vec3) -> f32 {
        self.nodes[i as usize].importance(p, n)
    }

    /// The probability of the first child of interior node `i` at (p, n): its share of the
    /// two children's importance, ½ where both are 0 (a cluster whose bound admits p while its
    /// halves' do not: no light there reaches p, but the pmf stays a distribution).
    fn first_child_share(&self, i: u32, p: Vec3, n: Vec3) -> f32 {
        let (c0, c1) = (i + 1, self.nodes[i as usize].child);
        let (i0, i1) = (self.importance(c0, p, n), self.importance(c1, p, n));
        if i0 + i1 > 0.0 { i0 / (i0 + i1) } else { 0.5 }
    }

    /// A light for (p, n) from `u` ∈ [0, 1): its index and its probability (the WGSL's
    /// `light_tree_sample`, on the CPU). None only for an empty tree.
    pub fn sample(&self, p: Vec3, n: Vec3, mut u: f32) -> Option<(u32, f32)> {
        if self.is_empty() {
            return None;
        }
        let mut i = 0u32;
        let mut pmf = 1.0f32;
        loop {
            let node = &self.nodes[i as usize];
            if node.leaf == 1 {
                return Some((node.child, pmf));
            }
            let p0 = self.first_child_share(i, p, n);
            if u < p0 {
                i += 1;
                pmf *= p0;
                u = (u / p0).min(ONE_MINUS_EPSILON);
            } else {
                i = node.child;
                pmf *= 1.0 - p0;
                u = ((u - p0) / (1.0 - p0)).min(ONE_MINUS_EPSILON);
            }
        }
    }

    /// The probability that [`LightBvh::sample`] at (p, n) picks `light`: the product of the
    /// choices on its path, from its leaf up (0 for a light outside the tree).
    pub fn pmf(&self, p: Vec3, n: Vec3, light: u32) -> f32 {
        let Some(&leaf) = self.leaf_of.get(light as usize) else {
            return 0.0;
        };
        if leaf == NONE {
            return 0.0;
        }
        let mut pmf = 1.0f32;
        let mut i = leaf;
        loop {
            let parent = self.nodes[i as usize].parent;
            if parent == NONE {
                return pmf;
            }
            let p0 = self.first_child_share(parent, p, n);
            pmf *= if i == parent + 1 { p0 } else { 1.0 - p0 };
            i = parent;
        }
    }
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Subtrees of fewer lights on either side are built on the calling thread.
const PARALLEL_BELOW: usize = 4096;

/// Writes the subtree of `items` into `nodes` (its 2k − 1 nodes, the root first, at global index
/// `index`) under `parent`; returns the bounds of its lights.
fn build_subtree(
    nodes: &mut [GpuLightNode],
    items: &mut [(u32, LightBounds)],
    index: u32,
    parent: u32,
) -> LightBounds {
    debug_assert_eq!(nodes.len(), 2 * items.len() - 1);
    if let [(light, b)] = items {
        nodes[0] = GpuLightNode::new(b, *light, parent, true);
        return *b;
    }
    let mid = split(items);
    let (left, right) = items.split_at_mut(mid);
    let (root, rest) = nodes.split_first_mut().expect("a subtree has a root");
    let (left_nodes, right_nodes) = rest.split_at_mut(2 * mid - 1);
    let second = index + 2 * mid as u32;
    let (lb, rb) = if mid.min(right.len()) >= PARALLEL_BELOW {
        rayon::join(
            || build_subtree(left_nodes, left, index + 1, index),
            || build_subtree(right_nodes, right, second, index),
        )
    } else {
        (
            build_subtree(left_nodes, left, index + 1, index),
            build_subtree(right_nodes, right, second, index),
        )
    };
    let bounds = lb.union(&rb);
    *root = GpuLightNode::new(&bounds, second, parent, false);
    bounds
}

/// Reorders `items` into two non-empty groups by the cheapest bucket split over the three
/// axes (pbrt-v4's `buildBVH`); returns the size of the first. Lights whose centroids coincide
/// are halved in their order.
fn split(items: &mut [(u32, LightBounds)]) -> usize {
    let (mut clo, mut chi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (_, b) in items.iter() {
        clo = clo.min(b.centroid());
        chi = chi.max(b.centroid());
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        let extent = chi[axis] - clo[axis];
        if extent <= 0.0 {
            continue;
        }
        let bucket = |b: &LightBounds| {
            (((b.centroid()[axis] - clo[axis]) / extent * BUCKETS as f32) as usize).min(BUCKETS - 1)
        };
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for (_, b) in items.iter() {
            let k = bucket(b);
            buckets[k] = Some(buckets[k].map_or(*b, |x| x.union(b)));
        }
        // The union of the buckets below each cut and above it, each built once.
        let join = |acc: &mut Option<LightBounds>, b: &Option<LightBounds>| {
            if let Some(b) = b {
                *acc = Some(acc.map_or(*b, |a| a.union(b)));
            }
            *acc
        };
        let mut acc = None;
        let below: Vec<Option<LightBounds>> = buckets.iter().map(|b| join(&mut acc, b)).collect();
        let mut acc = None;
        let mut above: Vec<Option<LightBounds>> =
            buckets.iter().rev().map(|b| join(&mut acc, b)).collect();
        above.reverse();
        for cut in 1..BUCKETS {
            let (Some(l), Some(r)) = (below[cut - 1], above[cut]) else {
                continue;
            };
            let cost = l.cost(axis) + r.cost(axis);
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, cut));
            }
        }
    }
    let Some((_, axis, cut)) = best else {
        return items.len() / 2;
    };
    let extent = chi[axis] - clo[axis];
    let left = |b: &LightBounds| {
        (((b.centroid()[axis] - clo[axis]) / extent * BUCKETS as f32) as usize).min(BUCKETS - 1)
            < cut
    };
    let mut mid = 0;
    for k in 0..items.len() {
        if left(&items[k].1) {
            items.swap(k, mid);
            mid += 1;
        }
    }
    debug_assert!(
        mid > 0 && mid < items.len(),
        "a bucket cut leaves both sides non-empty"
    );
    mid
}
