//! The Directional Probability Function of the filterable glint model (Wang, Wang, Poulin,
//! Holzschuch 2018): P(ωi, ωo, γ), the probability that one flake, its normal m drawn from
//! p(m) = D(m) cos θm, reflects ωi into the cone of half-angle γ around ωo.
//!
//! Computed by integrating over the cone, not by summing 1° cells (which overestimates P(γ) by
//! 7–24 %): with h(ω) = normalize(ωi + ω) and dω_h = dω / (4 ωi·h),
//!   P = ∫_{ω ∈ cone(ωo, γ)} D(h) cos θh / (4 ωi·h) dω,
//! Gauss–Legendre in the cone's polar angle ψ (weight sin ψ) × midpoint in its azimuth χ, with
//! node counts sized to the NDF's lobe ([`crate::cone_rule`]), or on wide cones polar
//! coordinates about the lobe clipped to the cone ([`crate::lobe_rule`]).

use crate::cone_rule::{ConeRule, LevelRule, Ring, lobe_width};
use crate::lobe_rule::LobeRule;
use facet_brdf::model::microfacet::Ndf;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// The nine cone half-angles of the pyramid, in degrees.
pub const LEVELS_DEG: [f64; 9] = [1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0];

/// σ(γ) = 2π(1 − cos γ): the solid angle of a cone of half-angle γ.
pub fn cone_solid_angle(gamma: f64) -> f64 {
    2.0 * PI * (1.0 - gamma.cos())
}

/// P(ωi, ωo, γ) by quadrature over the cone with the [`ConeRule::fast`] rule sized to the NDF's
/// [`lobe_width`]; `wi`, `wo` unit vectors, z up. The tables ([`DpfTable::build`], and the GPU
/// build) use the same rule.
pub fn dpf(ndf: &Ndf, wi: DVec3, wo: DVec3, gamma: f64) -> f64 {
    dpf_with(ndf, wi, wo, gamma, &ConeRule::fast())
}

/// P by the [`ConeRule::direct`] rule: the reference integral the fast rule is measured against.
pub fn dpf_reference(ndf: &Ndf, wi: DVec3, wo: DVec3, gamma: f64) -> f64 {
    dpf_with(ndf, wi, wo, gamma, &ConeRule::direct())
}

/// P by the cone rule `rule`.
pub fn dpf_with(ndf: &Ndf, wi: DVec3, wo: DVec3, gamma: f64, rule: &ConeRule) -> f64 {
    dpf_on_level(ndf, wi, wo, gamma, &rule.level(gamma, lobe_width(ndf)))
}

/// P by the rule a level takes.
pub fn dpf_on_level(ndf: &Ndf, wi: DVec3, wo: DVec3, gamma: f64, level: &LevelRule) -> f64 {
    match level {
        LevelRule::Rings(rings) => dpf_on_rings(ndf, wi, wo, rings),
        LevelRule::Lobe { rule, width } => dpf_on_lobe(ndf, wi, wo, gamma, *width, rule),
    }
}

/// P by the rule about the lobe of width `width`: Σ weight · p(h)/(4 ωi·h) over its nodes.
pub fn dpf_on_lobe(
    ndf: &Ndf,
    wi: DVec3,
    wo: DVec3,
    gamma: f64,
    width: f64,
    rule: &LobeRule,
) -> f64 {
    let mut sum = 0.0;
    rule.for_each_node(wi, wo, gamma, width, |w, weight| {
        sum += weight * flake_density(ndf, wi, w)
    });
    sum
}

/// P by the rings of a cone rule: Σ_rings weight · Σ_χ p(h)/(4 ωi·h) (what the shader sums).
pub fn dpf_on_rings(ndf: &Ndf, wi: DVec3, wo: DVec3, rings: &[Ring]) -> f64 {
    let (t, b) = frame(wo);
    let mut sum = 0.0;
    for r in rings {
        let (sp, cp) = (r.sin_psi as f64, r.cos_psi as f64);
        let mut ring = 0.0;
        for k in 0..r.n_chi {
            let chi = (k as f64 + 0.5) / r.n_chi as f64 * 2.0 * PI;
            let w_dir = cp * wo + sp * (chi.cos() * t + chi.sin() * b);
            ring += flake_density(ndf, wi, w_dir);
        }
        sum += r.weight as f64 * ring;
    }
    sum
}

/// p(h) / (4 ωi·h) at h = normalize(ωi + ω): the density over reflected directions ω.
fn flake_density(ndf: &Ndf, wi: DVec3, w: DVec3) -> f64 {
    let s = wi + w;
    let len = s.length();
    if len < 1e-12 {
        return 0.0;
    }
    let h = s / len;
    let cos_ih = wi.dot(h);
    if h.z <= 0.0 || cos_ih <= 0.0 {
        return 0.0;
    }
    ndf.d(h) * h.z / (4.0 * cos_ih)
}

/// An orthonormal pair perpendicular to `n`.
fn frame(n: DVec3) -> (DVec3, DVec3) {
    let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t = a.cross(n).normalize();
    (t, n.cross(t))
}

/// Table resolution: cells over θo, θi ∈ [0°, 90°] and Δφ ∈ [0°, 180°].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DpfConfig {
    /// θ cells of the table (θo and θi).
    pub n_theta: usize,
    /// Δφ cells of the table.
    pub n_dphi: usize,
}

impl DpfConfig {
    /// 2.8° × 2.8° × 2.8° cells.
    pub const fn standard() -> Self {
        DpfConfig {
            n_theta: 32,
            n_dphi: 64,
        }
    }

    /// Small tables for tests and previews.
    pub const fn preview() -> Self {
        DpfConfig {
            n_theta: 12,
            n_dphi: 24,
        }
    }
}

/// P at one γ on a regular (θo, θi, Δφ) grid. Cell k covers [k, k + 1) · step and its value is
/// taken at the cell centre (k + ½) · step; lookups interpolate trilinearly between centres
/// (clamped at the edges). Δφ = φo − φi folded to [0°, 180°]; 180° is the mirror configuration.
#[derive(Clone, Debug)]
pub struct DpfTable {
    /// The cone half-angle γ it was built for, radians.
    pub gamma: f64,
    /// Its resolution.
    pub config: DpfConfig,
    /// Index (θo, θi, Δφ) → values[(o · n_theta + i) · n_dphi + p].
    pub values: Vec<f32>,
}

/// Directions of a table query: ωi at azimuth 0, ωo at azimuth Δφ.
pub fn query_directions(theta_o: f64, theta_i: f64, dphi: f64) -> (DVec3, DVec3) {
    let wi = DVec3::new(theta_i.sin(), 0.0, theta_i.cos());
    let wo = DVec3::new(
        theta_o.sin() * dphi.cos(),
        theta_o.sin() * dphi.sin(),
        theta_o.cos(),
    );
    (wi, wo)
}

impl DpfTable {
    /// The CPU reference build, cell centres in parallel, with the [`ConeRule::fast`] rule.
    pub fn build(ndf: &Ndf, gamma: f64, config: DpfConfig) -> Self {
        Self::build_with(ndf, gamma, config, &ConeRule::fast())
    }

    /// The CPU build with the cone rule `rule`.
    pub fn build_with(ndf: &Ndf, gamma: f64, config: DpfConfig, rule: &ConeRule) -> Self {
        let (nt, np) = (config.n_theta, config.n_dphi);
        let level = rule.level(gamma, lobe_width(ndf));
        let values = (0..nt * nt * np)
            .into_par_iter()
            .map(|c| {
                let (o, i, p) = (c / (nt * np), c / np % nt, c % np);
                let (theta_o, theta_i, dphi) = Self::cell_centre(config, o, i, p);
                let (wi, wo) = query_directions(theta_o, theta_i, dphi);
                dpf_on_level(ndf, wi, wo, gamma, &level) as f32
            })
            .collect();
        DpfTable {
            gamma,
            config,
            values,
        }
    }

    /// (θo, θi, Δφ) of cell (o, i, p), radians.
    pub fn cell_centre(config: DpfConfig, o: usize, i: usize, p: usize) -> (f64, f64, f64) {
        let st = FRAC_PI_2 / config.n_theta as f64;
        let sp = PI / config.n_dphi as f64;
        (
            (o as f64 + 0.5) * st,
            (i as f64 + 0.5) * st,
            (p as f64 + 0.5) * sp,
        )
    }

    /// Trilinear lookup between cell centres.
    pub fn lookup(&self, theta_o: f64, theta_i: f64, dphi: f64) -> f64 {
        let (nt, np) = (self.config.n_theta, self.config.n_dphi);
        let st = FRAC_PI_2 / nt as f64;
        let sp = PI / np as f64;
        let fold = {
            let d = dphi.rem_euclid(2.0 * PI);
            if d > PI { 2.0 * PI - d } else { d }
        };
        // Continuous index with centres at integers: x = value / step − ½.
        let axis = |v: f64, step: f64, n: usize| {
            let x = (v / step - 0.5).clamp(0.0, (n - 1) as f64);
            let k = (x as usize).min(n.saturating_sub(2));
            (k, (k + 1).min(n - 1), x - k as f64)
        };
        let (o0, o1, to) = axis(theta_o, st, nt);
        let (i0, i1, ti) = axis(theta_i, st, nt);
        let (p0, p1, tp) = axis(fold, sp, np);
        let at = |o: usize, i: usize, p: usize| self.values[(o * nt + i) * np + p] as f64;
        let lerp = |a: f64, b: f64, t: f64| a + t * (b - a);
        let plane = |o: usize| {
            lerp(
                lerp(at(o, i0, p0), at(o, i0, p1), tp),
                lerp(at(o, i1, p0), at(o, i1, p1), tp),
                ti,
            )
        };
        lerp(plane(o0), plane(o1), to)
    }
}

/// The nine levels, γ ∈ [`LEVELS_DEG`]; any γ between levels interpolates P/σ(γ) (the mean
/// density over the cone, smooth in γ) linearly and multiplies by σ(γ). A pyramid may hold
/// only some levels ([`DpfPyramid::levels_for`] says which a γ needs).
#[derive(Clone, Debug)]
pub struct DpfPyramid {
    /// One table per level of [`LEVELS_DEG`]; `None` for a level not built.
    pub levels: Vec<Option<DpfTable>>,
}

impl DpfPyramid {
    /// All nine levels (CPU reference).
    pub fn build(ndf: &Ndf, config: DpfConfig) -> Self {
        Self::build_levels(ndf, config, &[0, 1, 2, 3, 4, 5, 6, 7, 8])
    }

    /// Only the levels listed (indices into [`LEVELS_DEG`]).
    pub fn build_levels(ndf: &Ndf, config: DpfConfig, which: &[usize]) -> Self {
        Self::build_levels_with(ndf, config, which, &ConeRule::fast())
    }

    /// Only the levels listed, with the cone rule `rule`.
    pub fn build_levels_with(
        ndf: &Ndf,
        config: DpfConfig,
        which: &[usize],
        rule: &ConeRule,
    ) -> Self {
        let levels = (0..LEVELS_DEG.len())
            .map(|k| {
                which
                    .contains(&k)
                    .then(|| DpfTable::build_with(ndf, LEVELS_DEG[k].to_radians(), config, rule))
            })
            .collect();
        DpfPyramid { levels }
    }

    /// The levels a lookup at γ reads, and the weight of the second.
    pub fn levels_for(gamma: f64) -> ([usize; 2], f64) {
        let g = gamma.to_degrees().clamp(0.0, 90.0);
        let k = LEVELS_DEG.partition_point(|&l| l <= g);
        if k == 0 {
            ([0, 0], 0.0)
        } else if k == LEVELS_DEG.len() {
            ([k - 1, k - 1], 0.0)
        } else {
            (
                [k - 1, k],
                (g - LEVELS_DEG[k - 1]) / (LEVELS_DEG[k] - LEVELS_DEG[k - 1]),
            )
        }
    }

    /// P(θo, θi, Δφ, γ); γ below 1° scales the 1° level by σ(γ)/σ(1°), above 90° clamps.
    pub fn lookup(&self, theta_o: f64, theta_i: f64, dphi: f64, gamma: f64) -> f64 {
        let density = |k: usize| {
            let t = self.levels[k].as_ref().unwrap_or_else(|| {
                panic!(
                    "level {}° was not built: build it with DpfPyramid::build_levels",
                    LEVELS_DEG[k]
                )
            });
            t.lookup(theta_o, theta_i, dphi) / cone_solid_angle(t.gamma)
        };
        let ([k0, k1], t) = Self::levels_for(gamma);
        let mean = density(k0) * (1.0 - t) + if t > 0.0 { density(k1) * t } else { 0.0 };
        mean * cone_solid_angle(gamma.clamp(0.0, FRAC_PI_2))
    }
}

impl DpfPyramid {
    /// The levels the way the paper builds them: the finest (1°) level blurred over ωo with a
    /// Gaussian of standard deviation γ/2 (the per-axis spread of a cone of half-angle γ), in
    /// the table's (θo, Δφ) cells (an arc of Δφ is sin θo · Δφ on the sphere), normalised and
    /// scaled by σ(γ)/σ(1°). For comparison with the exact levels; needs level 0.
    pub fn blurred_from_finest(&self) -> DpfPyramid {
        let fine = self.levels[0]
            .as_ref()
            .expect("level 1° is needed: build it with DpfPyramid::build_levels");
        let cfg = fine.config;
        let (nt, np) = (cfg.n_theta, cfg.n_dphi);
        let (st, sp) = (FRAC_PI_2 / nt as f64, PI / np as f64);
        let levels = LEVELS_DEG
            .iter()
            .enumerate()
            .map(|(k, &deg)| {
                let gamma = deg.to_radians();
                if k == 0 {
                    return Some(fine.clone());
                }
                let sigma = gamma / 2.0;
                let scale = cone_solid_angle(gamma) / cone_solid_angle(fine.gamma);
                let values = (0..nt * nt * np)
                    .into_par_iter()
                    .map(|c| {
                        let (o, i, p) = (c / (nt * np), c / np % nt, c % np);
                        let theta_o = (o as f64 + 0.5) * st;
                        let (mut sum, mut wsum) = (0.0, 0.0);
                        for o2 in 0..nt {
                            let t2 = (o2 as f64 + 0.5) * st;
                            let dt = (t2 - theta_o) / sigma;
                            if dt.abs() > 3.0 {
                                continue;
                            }
                            let arc = (0.5 * (theta_o + t2)).sin().max(st);
                            for p2 in 0..np {
                                let dp = ((p2 as f64 - p as f64) * sp * arc) / sigma;
                                let w = (-0.5 * (dt * dt + dp * dp)).exp();
                                sum += w * fine.values[(o2 * nt + i) * np + p2] as f64;
                                wsum += w;
                            }
                        }
                        (sum / wsum * scale) as f32
                    })
                    .collect();
                Some(DpfTable {
                    gamma,
                    config: cfg,
                    values,
                })
            })
            .collect();
        DpfPyramid { levels }
    }
}
