//! The quadrature about the reflected lobe that the DPF integral uses on wide cones, shared by
//! the CPU ([`crate::dpf::dpf_on_lobe`]) and the GPU (`shaders/glint/dpf_build.wgsl` walks the
//! same intervals with the same Gauss–Legendre nodes).
//!
//! A cone much wider than the lobe (γ ≫ w) spends most of a ring rule's nodes where the
//! integrand is nearly zero. This rule centres polar coordinates (ρ, φ) on the mirror direction
//! r = (−ωi.x, −ωi.y, ωi.z), where the integrand peaks:
//!   P = ∫ sin ρ dρ ∫_{arc(ρ)} q(ρ, φ) dφ,
//! with arc(ρ) the part of the ring of radius ρ about r inside the cone: with β the angle from r
//! to ωo and φ measured from the great circle through ωo, the ring point is in the cone where
//! cos φ ≥ c(ρ) = (cos γ − cos ρ cos β) / (sin ρ sin β), an arc [−a, a], a = acos c (the whole
//! ring for c ≤ −1). ρ runs over [max(0, β − γ), min(π, β + γ)], cut into intervals at the lobe
//! scales w·2^k (the integrand changes on the scale of its distance from the peak, so geometric
//! intervals resolve the sharp core and the heavy GGX tails alike) and at |γ − β|, where a ring
//! stops being whole. Each interval gets `radial` Gauss–Legendre nodes, through a [`RadialMap`]
//! that smooths the square-root behaviour of the arc length at ends where a ring touches the
//! cone; each ring gets `angular` nodes over its arc (`tail_angular` beyond 4w). The
//! cost per cell depends on the lobe, not on γ.

use facet_brdf::numerics::quadrature::gauss_legendre;
use glam::DVec3;
use std::f64::consts::PI;

/// Below this length (radians) an interval or an arc is dropped: a ring that only touches the
/// cone, or an interval between two edges that coincide. The WGSL uses the same value.
pub const LOBE_EPS: f64 = 1e-6;

/// How close, relative to itself, a lobe scale point may come to a point where a ring touches
/// the cone before it is dropped as an interval edge ([`interval_end`]); the WGSL takes it too.
/// Larger values lengthen the intervals the low-order rule sees (0.25: up to 1.1e-2 error at
/// 4 × 12, against 6e-3 at 0.03).
pub const TOUCH_MERGE: f64 = 0.03;

/// Where the lobe's tail starts, in lobe widths: rings of intervals starting at ρ ≥ 4w, where
/// the integrand varies on the scale of ρ itself, get [`LobeRule::tail_angular`] nodes.
pub const TAIL_START: f64 = 4.0;

/// Node counts of the rule about the lobe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeRule {
    /// Gauss–Legendre nodes in ρ per interval.
    pub radial: usize,
    /// Gauss–Legendre nodes in φ per ring (over its arc inside the cone) in the lobe's core.
    pub angular: usize,
    /// Gauss–Legendre nodes in φ per ring in the tail (intervals from [`TAIL_START`]·w on).
    pub tail_angular: usize,
}

impl LobeRule {
    /// 4 nodes per radial interval, 12 per ring in the core and 6 in the tail: measured against
    /// a converged ring rule in `tests/glint.rs` (`lobe_rule_converges_to_the_cone_integral`;
    /// 12 nodes in the tail change its error by under 1e-3).
    pub const fn standard() -> Self {
        LobeRule {
            radial: 4,
            angular: 12,
            tail_angular: 6,
        }
    }

    /// `radial` nodes in ρ and `angular` in φ everywhere, core and tail alike.
    pub const fn uniform(radial: usize, angular: usize) -> Self {
        LobeRule {
            radial,
            angular,
            tail_angular: angular,
        }
    }

    /// The most intervals a cell's ρ range is cut into for a lobe of width `width`: those of
    /// the scales w·2^k below π, one more above the last, and one for |γ − β|.
    pub fn max_intervals(width: f64) -> usize {
        let mut n = 1;
        let mut s = width;
        while s < PI {
            n += 1;
            s *= 2.0;
        }
        n + 1
    }

    /// The most intervals starting in the lobe's core (below [`TAIL_START`]·w): those from 0
    /// and from the scales below it, and one for |γ − β|.
    pub fn max_core_intervals(width: f64) -> usize {
        let mut n = 1;
        let mut s = width;
        while s < PI.min(TAIL_START * width) {
            n += 1;
            s *= 2.0;
        }
        n + 1
    }

    /// The most D evaluations a cell takes (its ρ range may hold fewer intervals).
    pub fn max_evaluations(&self, width: f64) -> usize {
        let all = Self::max_intervals(width);
        let core = Self::max_core_intervals(width).min(all);
        self.radial * (core * self.angular + (all - core) * self.tail_angular)
    }

    /// The Gauss–Legendre nodes on [0, 1] as the shader reads them, (x, weight): the `radial`
    /// ones, the `angular` ones, then the `tail_angular` ones.
    pub fn nodes(&self) -> Vec<[f32; 2]> {
        gauss_legendre(self.radial)
            .into_iter()
            .chain(gauss_legendre(self.angular))
            .chain(gauss_legendre(self.tail_angular))
            .map(|(x, w)| [x as f32, w as f32])
            .collect()
    }

    /// Calls `node(ω, weight)` for every node of the cone of half-angle `gamma` about `wo`, for
    /// the lobe of width `width` reflected from `wi`: Σ weight · q(ω) ≈ ∫_cone q dω.
    pub fn for_each_node(
        &self,
        wi: DVec3,
        wo: DVec3,
        gamma: f64,
        width: f64,
        mut node: impl FnMut(DVec3, f64),
    ) {
        let radial = gauss_legendre(self.radial);
        let (core, tail) = (
            gauss_legendre(self.angular),
            gauss_legendre(self.tail_angular),
        );
        let r = DVec3::new(-wi.x, -wi.y, wi.z);
        let cb = r.dot(wo).clamp(-1.0, 1.0);
        let perp = wo - cb * r;
        let sb = perp.length();
        // u points from r towards ωo, so every arc is centred on φ = 0.
        let u = if sb > LOBE_EPS {
            perp / sb
        } else {
            any_perpendicular(r)
        };
        let v = r.cross(u);
        let beta = sb.atan2(cb); // not acos(cb): lavapipe's acos is good to ~1e-4 only
        let (lo, hi) = ((beta - gamma).max(0.0), (beta + gamma).min(PI));
        let whole_below = gamma - beta;
        let cos_gamma = gamma.cos();
        // The ends where a ring touches the cone's edge (not ρ = 0, not a lobe scale).
        let tangent = |x: f64| (x == lo && lo > 0.0) || (x == hi && hi < PI) || x == whole_below;
        let mut a = lo;
        let mut scale = width;
        while a < hi - LOBE_EPS {
            while scale <= a + LOBE_EPS {
                scale *= 2.0;
            }
            let next_tangent = if whole_below > a + LOBE_EPS && whole_below < hi {
                whole_below
            } else {
                hi
            };
            let b = interval_end(a, tangent(a), scale, next_tangent);
            let map = RadialMap::new(tangent(a), tangent(b));
            let len = b - a;
            let angular = if a < TAIL_START * width { &core } else { &tail };
            for &(s, ws) in &radial {
                let (g, dg) = map.at(s);
                let rho = a + len * g;
                let d_rho = ws * len * dg;
                let (sr, cr) = rho.sin_cos();
                let half = arc_half_width(cr, sr, cb, sb, cos_gamma);
                if half < LOBE_EPS {
                    continue;
                }
                for &(t, wt) in angular {
                    // φ = half (2t − 1), dφ = 2 half dt
                    let phi = half * (2.0 * t - 1.0);
                    let (sp, cp) = phi.sin_cos();
                    let dir = cr * r + sr * (cp * u + sp * v);
                    node(dir, d_rho * sr * 2.0 * half * wt);
                }
            }
            a = b;
        }
    }
}

/// Where the interval of ρ starting at `a` ends: at the first lobe scale point from `scale` on
/// (w·2^k, the smallest above `a`), or at the next point where a ring touches the cone,
/// `next_tangent`. A scale point closer than [`TOUCH_MERGE`] of itself to a touching point is
/// skipped: the arc length's square root there would sit just outside the interval, where the
/// [`RadialMap`] cannot smooth it (at 16 × 48 nodes: 2e-4 left against 1e-7 without).
pub fn interval_end(a: f64, a_touches: bool, scale: f64, next_tangent: f64) -> f64 {
    let mut s = scale;
    while s < next_tangent - TOUCH_MERGE * s {
        if !(a_touches && s - a < TOUCH_MERGE * s) {
            return s;
        }
        s *= 2.0;
    }
    next_tangent
}

/// The substitution ρ = a + (b − a) g(s) of a radial interval: g(s) = s², 1 − (1 − s)² or
/// (1 − cos πs)/2 at ends where a ring touches the cone (the arc length grows as a square root
/// there, which g smooths), g(s) = s where neither end does. The WGSL uses the same codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RadialMap {
    /// Neither end touches the cone: g(s) = s.
    Linear = 0,
    /// The start does: g(s) = s².
    Start = 1,
    /// The end does: g(s) = 1 − (1 − s)².
    End = 2,
    /// Both do: g(s) = (1 − cos πs)/2.
    Both = 3,
}

impl RadialMap {
    /// The map of an interval whose start and end touch the cone, or not.
    pub fn new(start: bool, end: bool) -> Self {
        match (start, end) {
            (false, false) => RadialMap::Linear,
            (true, false) => RadialMap::Start,
            (false, true) => RadialMap::End,
            (true, true) => RadialMap::Both,
        }
    }

    /// g(s) and g′(s).
    pub fn at(self, s: f64) -> (f64, f64) {
        match self {
            RadialMap::Linear => (s, 1.0),
            RadialMap::Start => (s * s, 2.0 * s),
            RadialMap::End => (1.0 - (1.0 - s) * (1.0 - s), 2.0 * (1.0 - s)),
            RadialMap::Both => (0.5 * (1.0 - (PI * s).cos()), 0.5 * PI * (PI * s).sin()),
        }
    }
}

/// The half-width a of the arc of the ring at ρ (cos ρ = `cr`, sin ρ = `sr`) about r inside the
/// cone of half-angle γ about ωo (cos β = `cb`, sin β = `sb`): cos φ ≥ c(ρ) on the arc, π for a
/// whole ring, 0 for none.
pub fn arc_half_width(cr: f64, sr: f64, cb: f64, sb: f64, cos_gamma: f64) -> f64 {
    let denom = sr * sb;
    let cos_mid = cr * cb; // cos of the angle to ωo at φ = ±π/2
    if denom < LOBE_EPS * LOBE_EPS {
        // ρ ≈ 0 or ωo ≈ ±r: every point of the ring is at the same angle from ωo.
        return if cos_mid >= cos_gamma { PI } else { 0.0 };
    }
    let c = (cos_gamma - cos_mid) / denom;
    if c <= -1.0 {
        PI
    } else if c >= 1.0 {
        0.0
    } else {
        ((1.0 - c) * (1.0 + c)).sqrt().atan2(c) // acos c
    }
}

/// A unit vector perpendicular to `n`.
fn any_perpendicular(n: DVec3) -> DVec3 {
    let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    a.cross(n).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No cell takes more nodes than [`LobeRule::max_evaluations`] says (what the choice between
    /// the rules counts on), over cones from 1° to 90° and lobes from the floor up.
    #[test]
    fn node_count_stays_within_its_bound() {
        let rule = LobeRule::standard();
        for width in [0.1, 0.2, 0.3, 0.6, 1.2] {
            for deg in [1.0f64, 5.0, 20.0, 45.0, 60.0, 90.0] {
                let gamma = deg.to_radians();
                let mut most = 0;
                for k in 0..400 {
                    let (ti, to, dphi) = (
                        (k % 20) as f64 * 0.078,
                        (k / 20) as f64 * 0.078,
                        k as f64 * 0.37,
                    );
                    let wi = DVec3::new(ti.sin(), 0.0, ti.cos());
                    let wo = DVec3::new(to.sin() * dphi.cos(), to.sin() * dphi.sin(), to.cos());
                    let mut n = 0;
                    rule.for_each_node(wi, wo, gamma, width, |_, _| n += 1);
                    most = most.max(n);
                }
                assert!(
                    most <= rule.max_evaluations(width),
                    "w = {width}, γ = {deg}°: {most} nodes, bound {}",
                    rule.max_evaluations(width)
                );
            }
        }
    }
}
