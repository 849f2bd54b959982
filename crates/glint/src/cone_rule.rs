//! The quadrature over a cone of half-angle γ that the DPF integral uses, shared by the CPU
//! ([`crate::dpf::dpf`]) and the GPU (`shaders/glint/dpf_build.wgsl` reads the rings as they
//! are built here): Gauss–Legendre in the cone's polar angle ψ (weight sin ψ), and on each ring
//! a midpoint rule in its azimuth χ (spectrally accurate for a smooth periodic integrand).
//!
//! The integrand p(h)/(4 ωi·h) varies over the angular width of the reflected lobe,
//! w ≈ 2α (a normal tilted by δ turns the reflection by 2δ; see [`lobe_width`]). The
//! [`ConeRule::fast`] rule spaces its nodes in proportion to w: a cone much narrower than the
//! lobe gets a handful of nodes (the integrand is nearly linear over it), a wide cone gets about
//! (γ/w) rings and (2π sin ψ / w) nodes per ring (small rings need fewer). The
//! [`ConeRule::direct`] rule is the previous, fixed one (12 + 0.75·γ° rings of 24 + 1.5·γ°
//! nodes, sized for α ≈ 0.05 at every γ): the reference the fast rule is measured against.
//!
//! A cone much wider than the lobe is better integrated about the lobe than about the cone's
//! axis: [`ConeRule::fast`] switches a level to [`LobeRule`] where that needs fewer nodes
//! ([`ConeRule::level`]).

use crate::lobe_rule::LobeRule;
use bytemuck::{Pod, Zeroable};
use facet_brdf::model::microfacet::Ndf;
use facet_brdf::numerics::quadrature::gauss_legendre;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// How many nodes a cone gets; the counts are
/// `n_psi = psi_base + ⌊psi_per_deg·γ° + psi_per_width·γ/w⌋` rings and, on the ring at ψ,
/// `n_chi = chi_base + ⌊chi_per_deg·γ° + chi_per_width·2π sin ψ / w⌋` nodes,
/// with w the lobe width, floored at `min_width`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConeRule {
    /// Rings of the narrowest cone.
    pub psi_base: usize,
    /// Rings added per degree of γ, whatever the NDF.
    pub psi_per_deg: f64,
    /// Rings added per lobe width across the cone's radius γ.
    pub psi_per_width: f64,
    /// Nodes on a ring of the narrowest cone.
    pub chi_base: usize,
    /// Nodes added per degree of γ, whatever the NDF.
    pub chi_per_deg: f64,
    /// Nodes added per lobe width along the ring's circumference 2π sin ψ.
    pub chi_per_width: f64,
    /// The narrowest lobe resolved (radians): below it the rule stops growing.
    pub min_width: f64,
    /// The rule about the lobe, taken at a level where it needs fewer nodes than the rings.
    pub lobe: Option<LobeRule>,
}

/// What one node of the rule about the lobe's bound ([`LobeRule::max_evaluations`]) costs in
/// ring nodes: its arcs, its walk over the intervals and neighbouring cells that take different
/// intervals, against the cells that need fewer intervals than the bound. Chosen from single
/// levels of the standard tables on lavapipe (ms about the lobe / on rings): GGX α = 0.05 at
/// 30° 133 / 252, 90° 228 / 1262; Beckmann α = 0.1 at 60° 188 / 234; GGX α = 0.15 at 60°
/// 182 / 124 (rings), at 90° a tie (210 / 212). Two levels sit near the switch and take the
/// slower rule by a little: GGX α = 0.05 at 20° (rings, 137 / 107) and Beckmann α = 0.1 at 45°
/// (the lobe, 164 / 157).
pub const LOBE_NODE_COST: f64 = 1.25;

/// How one level is integrated: rings about ωo, or the rule about the lobe.
#[derive(Clone, Debug, PartialEq)]
pub enum LevelRule {
    /// The rings of the cone rule.
    Rings(Vec<Ring>),
    /// The rule about the lobe, for a lobe of width `width`.
    Lobe {
        /// Its node counts.
        rule: LobeRule,
        /// The lobe width it is sized to (floored as the rings are).
        width: f64,
    },
}

impl LevelRule {
    /// The D evaluations per cell (the rule about the lobe: at most).
    pub fn evaluations(&self) -> usize {
        match self {
            LevelRule::Rings(rings) => rings.iter().map(|r| r.n_chi as usize).sum(),
            LevelRule::Lobe { rule, width } => rule.max_evaluations(*width),
        }
    }
}

impl ConeRule {
    /// The fixed rule the tables were first built with: (12 + 0.75·γ°) rings of (24 + 1.5·γ°)
    /// nodes whatever the NDF and ψ, enough for α ≈ 0.05 at any γ; ~28.8k D evaluations per
    /// cell over the nine levels. The "direct integral" the fast rule is checked against.
    pub const fn direct() -> Self {
        ConeRule {
            psi_base: 12,
            psi_per_deg: 0.75,
            psi_per_width: 0.0,
            chi_base: 24,
            chi_per_deg: 1.5,
            chi_per_width: 0.0,
            min_width: 0.0,
            lobe: None,
        }
    }

    /// Nodes in proportion to the lobe: 3 + 2.5·γ/w rings, 4 + 2·(2π sin ψ)/w nodes on a ring
    /// (a node every ~w/2 across the lobe at both sizes), growing down to α = 0.05 (w = 0.1) as
    /// the direct rule did; [`LobeRule::standard`] on the wide cones where it is cheaper.
    /// Measured against [`ConeRule::direct`] in `tests/glint.rs`.
    pub const fn fast() -> Self {
        ConeRule {
            psi_base: 3,
            psi_per_deg: 0.0,
            psi_per_width: 2.5,
            chi_base: 4,
            chi_per_deg: 0.0,
            chi_per_width: 2.0,
            min_width: 0.1,
            lobe: Some(LobeRule::standard()),
        }
    }

    /// The rings of a cone of half-angle `gamma` for a lobe of width `width` (radians).
    pub fn rings(&self, gamma: f64, width: f64) -> Vec<Ring> {
        let deg = gamma.to_degrees();
        let w = width.max(self.min_width);
        let n_psi =
            self.psi_base + (self.psi_per_deg * deg + self.psi_per_width * gamma / w) as usize;
        gauss_legendre(n_psi)
            .into_iter()
            .map(|(x, wt)| {
                let psi = x * gamma;
                let (sp, cp) = psi.sin_cos();
                let n_chi = self.chi_base
                    + (self.chi_per_deg * deg + self.chi_per_width * 2.0 * PI * sp / w) as usize;
                Ring {
                    cos_psi: cp as f32,
                    sin_psi: sp as f32,
                    // ∫₀^γ sin ψ dψ ∫₀^{2π} dχ ≈ Σ (w_gl γ) sin ψ (2π / n_chi) Σ_χ
                    weight: (wt * gamma * sp * 2.0 * PI / n_chi as f64) as f32,
                    n_chi: n_chi as u32,
                }
            })
            .collect()
    }

    /// How the level of half-angle `gamma` is integrated for a lobe of width `width`: the rings,
    /// or the rule about the lobe where its most evaluations, at [`LOBE_NODE_COST`], cost less.
    pub fn level(&self, gamma: f64, width: f64) -> LevelRule {
        let rings = LevelRule::Rings(self.rings(gamma, width));
        match self.lobe {
            Some(rule) => {
                let lobe = LevelRule::Lobe {
                    rule,
                    width: width.max(self.min_width),
                };
                if (lobe.evaluations() as f64 * LOBE_NODE_COST) < rings.evaluations() as f64 {
                    lobe
                } else {
                    rings
                }
            }
            None => rings,
        }
    }

    /// The D evaluations per cell of a cone (at most, where the rule about the lobe is taken).
    pub fn evaluations(&self, gamma: f64, width: f64) -> usize {
        self.level(gamma, width).evaluations()
    }
}

/// One ring of a cone rule (WGSL `Ring` of `shaders/glint/dpf_build.wgsl`): the directions
/// cos ψ ωo + sin ψ (cos χ t + sin χ b) at χ = (k + ½) 2π / n_chi, each of weight `weight`.
/// Stored in f32 as the GPU reads it; the CPU sums with the same values.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Ring {
    /// cos ψ.
    pub cos_psi: f32,
    /// sin ψ.
    pub sin_psi: f32,
    /// The weight of each of its nodes: w_gl γ sin ψ 2π / n_chi.
    pub weight: f32,
    /// Its nodes in χ.
    pub n_chi: u32,
}

/// The angular width w of the reflected lobe, radians: 2α for an analytic NDF (α = min(αx, αy),
/// the sharper axis). For a table, α is read off D: the smallest angle θ½ at which D falls to
/// half of D(normal), over 16 azimuths, gives α = tan θ½ / √ln 2 (exact for Beckmann, whose
/// D ∝ exp(−tan²θ/α²); GGX's half-maximum sits at 0.64α, so a GGX-shaped table reads a
/// narrower lobe and gets more nodes, never fewer).
pub fn lobe_width(ndf: &Ndf) -> f64 {
    match ndf {
        Ndf::Analytic(a) => 2.0 * a.alpha_x.min(a.alpha_y),
        Ndf::Tabulated(_) => {
            let d0 = ndf.d(DVec3::Z);
            let steps = 1024;
            let half_angle = |phi: f64| {
                (1..=steps)
                    .map(|k| (k as f64 / steps as f64).powi(2) * FRAC_PI_2 * 0.99)
                    .find(|&theta| {
                        let h = DVec3::new(
                            theta.sin() * phi.cos(),
                            theta.sin() * phi.sin(),
                            theta.cos(),
                        );
                        ndf.d(h) <= 0.5 * d0
                    })
                    .unwrap_or(FRAC_PI_2 * 0.99)
            };
            let theta = (0..16)
                .map(|l| half_angle(l as f64 / 16.0 * 2.0 * PI))
                .fold(f64::INFINITY, f64::min);
            2.0 * theta.tan() / std::f64::consts::LN_2.sqrt()
        }
    }
}
