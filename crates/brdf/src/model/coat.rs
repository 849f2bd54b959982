//! A clear dielectric coat over a base BRDF, in the manner of Weidlich & Wilkie 2007 (one
//! crossing each way, no scattering between the coat and the base):
//!
//! ```text
//! f(ωi, ωo) = w F(η, ωi·h) D_c(h) G2_c(ωi, ωo) / (4 cos θi cos θo)     the coat's own lobe
//!           + T(θi) T(θo) f_base(ωi', ωo') / η²                         the base through it
//! ```
//!
//! The coat's lobe is a colourless GGX dielectric of roughness α_c and index η, scaled by the
//! weight w ∈ [0, 1]. ωi' and ωo' are ωi and ωo refracted into a smooth interface of index η
//! (sin θ' = sin θ / η), so the base sees angles that depend on θh as well as θd — which one
//! NDF × F(θd) cannot do. T(θ) = 1 − w E_c(θ), where E_c is the directional albedo of the coat's
//! lobe at w = 1: what the coat does not reflect enters it. The 1/η² is the radiance's change
//! of solid angle across the interface (η² cos θ' dω' = cos θ dω).
//!
//! **Energy.** Light arriving from ωi leaves the coat's lobe with w E_c(θi), and T(θi) =
//! 1 − w E_c(θi) of it enters. Of that the base returns ∫ f_base cos θo' dωo' ≤ its albedo ≤ 1
//! (only the directions inside the critical angle leave; the others are lost), each times
//! T(θo) ≤ 1 on the way out: ∫ f cos θo dωo = w E_c(θi) + T(θi) ∫ T f_base cos θo' dωo' ≤ 1.
//! A white furnace of a coated model is therefore at most 1 wherever the base's is.

use crate::model::albedo::directional_albedo;
use crate::model::brdf::Brdf;
use crate::model::fresnel::Fresnel;
use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use crate::model::rgb::Rgb;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A clear coat: index of refraction, GGX roughness, and weight of its reflection.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Coat {
    /// The coat's index of refraction relative to the outside (> 1).
    pub eta: f64,
    /// The GGX roughness α of the coat's surface.
    pub alpha: f64,
    /// The weight w ∈ [0, 1] of the coat's reflection (its transmission is 1 − w E_c).
    pub weight: f64,
}

/// The directional albedo table's number of cos θ nodes.
const ALBEDO_NODES: usize = 32;
/// The quadrature grid (n × n) of each albedo node.
const ALBEDO_QUADRATURE: usize = 32;

impl Coat {
    /// A coat of index `eta`, roughness `alpha` and weight `weight`.
    pub const fn new(eta: f64, alpha: f64, weight: f64) -> Self {
        Coat { eta, alpha, weight }
    }

    /// Checks the parameters: η in (1, 3], α in [1e-4, 1], w in [0, 1].
    pub fn validate(&self) -> Result<(), String> {
        if !(self.eta > 1.0 && self.eta <= 3.0) {
            return Err(format!("coat.eta {} is not in (1, 3]", self.eta));
        }
        if !(self.alpha >= 1e-4 && self.alpha <= 1.0) {
            return Err(format!("coat.alpha {} is not in [1e-4, 1]", self.alpha));
        }
        if !(0.0..=1.0).contains(&self.weight) {
            return Err(format!("coat.weight {} is not in [0, 1]", self.weight));
        }
        Ok(())
    }

    /// The coat's lobe at weight 1: GGX of roughness α with the dielectric Fresnel of η.
    pub fn lobe(&self) -> MicrofacetBrdf {
        MicrofacetBrdf {
            name: "coat".into(),
            ndf: Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, self.alpha)),
            fresnel: Fresnel::Dielectric { eta: self.eta },
            diffuse: [0.0; 3],
        }
    }

    /// Into the coat: sin θ' = sin θ / η, the azimuth kept.
    pub fn refract_in(&self, w: DVec3) -> DVec3 {
        let s = w.truncate() / self.eta;
        DVec3::new(s.x, s.y, (1.0 - s.length_squared()).max(0.0).sqrt())
    }

    /// Out of the coat: sin θ = η sin θ'; `None` at or past the critical angle.
    pub fn refract_out(&self, w: DVec3) -> Option<DVec3> {
        let s = w.truncate() * self.eta;
        let c2 = 1.0 - s.length_squared();
        (c2 > 0.0 && w.z > 0.0).then(|| DVec3::new(s.x, s.y, c2.sqrt()))
    }

    /// The fold of an inside direction past the critical angle into the cone that leaves the
    /// coat, by which the renderer loses none of the base's samples: on the projected disc,
    /// sin θ = r > s = 1/η goes to r'² = k (r² − s²) with k = s² / (1 − s²), its azimuth kept
    /// (the annulus onto the disc of radius s, projected areas times k); a direction inside the
    /// cone, or below the surface, is returned as it is.
    pub fn fold_in(&self, w: DVec3) -> DVec3 {
        let (s2, k) = self.fold_constants();
        let r2 = w.truncate().length_squared();
        if w.z <= 0.0 || r2 <= s2 {
            return w;
        }
        let r2_in = k * (r2 - s2);
        let xy = w.truncate() * (r2_in / r2).sqrt();
        DVec3::new(xy.x, xy.y, (1.0 - r2_in).max(0.0).sqrt())
    }

    /// The direction past the critical angle that [`Coat::fold_in`] takes to `w` (inside the
    /// cone): r² = s² + r'² / k. At the normal the azimuth is arbitrary (+x).
    pub fn unfold(&self, w: DVec3) -> DVec3 {
        let (s2, k) = self.fold_constants();
        let r2_in = w.truncate().length_squared();
        let r2 = (s2 + r2_in / k).min(1.0);
        let dir = if r2_in > 0.0 {
            w.truncate() / r2_in.sqrt()
        } else {
            glam::DVec2::X
        };
        let xy = dir * r2.sqrt();
        DVec3::new(xy.x, xy.y, (1.0 - r2).sqrt())
    }

    /// What a density p over the directions past the critical angle becomes at `w` inside the
    /// cone once folded ([`Coat::fold_in`]): p(unfold(w)) times this, cos θ' / (k cos θ) with θ
    /// the unfolded direction's angle.
    pub fn fold_density(&self, w: DVec3) -> f64 {
        let (_, k) = self.fold_constants();
        w.z / (k * self.unfold(w).z.max(1e-12))
    }

    /// (s², k) of the fold: s = 1/η, k = s² / (1 − s²).
    fn fold_constants(&self) -> (f64, f64) {
        let s2 = 1.0 / (self.eta * self.eta);
        (s2, s2 / (1.0 - s2))
    }
}

/// A coat ready to evaluate: its lobe and the lobe's directional albedo tabulated over cos θ.
#[derive(Clone, Debug)]
pub struct CoatLayer {
    /// The parameters.
    pub coat: Coat,
    lobe: MicrofacetBrdf,
    /// E_c at cos θ = (k + ½) / n (weight 1).
    albedo: Vec<f64>,
}

impl CoatLayer {
    /// Builds the lobe and tabulates its albedo (about 33 000 evaluations).
    pub fn new(coat: Coat) -> Result<Self, String> {
        coat.validate()?;
        let lobe = coat.lobe();
        let albedo = (0..ALBEDO_NODES)
            .map(|k| {
                let c = (k as f64 + 0.5) / ALBEDO_NODES as f64;
                let w = DVec3::new((1.0 - c * c).sqrt(), 0.0, c);
                directional_albedo(&lobe, w, ALBEDO_QUADRATURE)[0]
            })
            .collect();
        Ok(CoatLayer { coat, lobe, albedo })
    }

    /// E_c at cos θ = (k + ½) / n, k < n: the table [`CoatLayer::lobe_albedo`] interpolates.
    pub fn albedo_nodes(&self) -> &[f64] {
        &self.albedo
    }

    /// The coat's own reflection: w F D G2 / (4 cos θi cos θo).
    pub fn reflection(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.coat.weight * self.lobe.eval(wi, wo).map_or(0.0, |f| f[0])
    }

    /// The lobe's directional albedo E_c(θ) at weight 1, linear in cos θ between the nodes.
    pub fn lobe_albedo(&self, cos_theta: f64) -> f64 {
        let x = (cos_theta.clamp(0.0, 1.0) * ALBEDO_NODES as f64 - 0.5).max(0.0);
        let k = (x as usize).min(ALBEDO_NODES - 2);
        let t = (x - k as f64).min(1.0);
        self.albedo[k] * (1.0 - t) + self.albedo[k + 1] * t
    }

    /// The coated f of `base` under this layer at (ωi, ωo): the model's formula, with the base
    /// borrowed ([`Coated`] owns its base).
    pub fn over(&self, base: &dyn Brdf, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let coat = &self.coat;
        let b = base.eval(coat.refract_in(wi), coat.refract_in(wo))?;
        let (r, t) = (self.reflection(wi, wo), self.base_factor(wi, wo));
        Some(b.map(|b| r + t * b))
    }

    /// T(θ) = 1 − w E_c(θ): what enters (or leaves) the coat.
    pub fn transmission(&self, cos_theta: f64) -> f64 {
        1.0 - self.coat.weight * self.lobe_albedo(cos_theta)
    }

    /// T(θi) T(θo) / η²: what multiplies the base at the refracted directions.
    pub fn base_factor(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.transmission(wi.z) * self.transmission(wo.z) / (self.coat.eta * self.coat.eta)
    }
}

/// A base BRDF under a coat.
#[derive(Clone, Debug)]
pub struct Coated<B> {
    /// The coat.
    pub layer: CoatLayer,
    /// The base, evaluated at the refracted directions.
    pub base: B,
}

impl<B: Brdf> Brdf for Coated<B> {
    fn name(&self) -> &str {
        self.base.name()
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        self.layer.over(&self.base, wi, wo)
    }
}

#[cfg(test)]
mod tests {
    /// The fold round-trips, takes every direction past the critical angle inside the cone and
    /// keeps what is inside. Cosine-weighted directions past the critical angle (a uniform
    /// density on the projected annulus) fold into a uniform density on the projected disc of
    /// radius s = 1/η: a quarter of them inside r < s/2 (2·10⁵ samples: 4σ ≈ 0.004), and
    /// their density, cos θ'/π times [`Coat::fold_density`]'s factor, integrates to the
    /// annulus's mass 1 − s².
    #[test]
    fn the_fold_maps_the_annulus_onto_the_cone() {
        use std::f64::consts::PI;
        let coat = Coat::new(1.5, 0.1, 1.0);
        let s = 1.0 / coat.eta;
        let inside = DVec3::new(0.3, 0.2, (1.0f64 - 0.13).sqrt());
        assert_eq!(coat.fold_in(inside), inside);
        let mut state = 7u64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut folded, mut near) = (0usize, 0usize);
        for _ in 0..200_000 {
            let (r, phi) = (next().sqrt(), 2.0 * PI * next());
            let w = DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r * r).sqrt());
            if r <= s {
                continue;
            }
            let f = coat.fold_in(w);
            assert!(f.truncate().length() <= s + 1e-12 && (f.length() - 1.0).abs() < 1e-12);
            assert!((coat.unfold(f) - w).length() < 1e-9, "{w} → {f}");
            folded += 1;
            near += usize::from(f.truncate().length() < 0.5 * s);
        }
        let q = near as f64 / folded as f64;
        assert!((q - 0.25).abs() < 0.004, "{q}");
        // ∫ over the cone of (cos θ_pre / π) × fold_density, midpoint rule in r'.
        let n = 4000;
        let mass: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) / n as f64 * s;
                let w = DVec3::new(r, 0.0, (1.0 - r * r).sqrt());
                let pre = coat.unfold(w);
                let p = pre.z / PI * coat.fold_density(w);
                // dω = r dr dφ / cos θ'
                p * 2.0 * PI * r / w.z * (s / n as f64)
            })
            .sum();
        assert!(
            (mass - (1.0 - s * s)).abs() < 1e-6,
            "{mass} against {}",
            1.0 - s * s
        );
    }

    use super::*;

    /// Refraction in then out returns the direction, and Snell's law holds.
    #[test]
    fn refraction_round_trips() {
        let coat = Coat::new(1.5, 0.05, 1.0);
        for deg in [0.0f64, 10.0, 45.0, 80.0, 89.9] {
            let t = deg.to_radians();
            let w = DVec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos());
            let inside = coat.refract_in(w);
            assert!((inside.truncate().length() * 1.5 - t.sin()).abs() < 1e-12);
            let back = coat.refract_out(inside).unwrap();
            assert!((back - w).length() < 1e-9, "{deg}: {back:?}");
        }
        let critical = (1.0f64 / 1.5).asin();
        let past = DVec3::new((critical + 1e-3).sin(), 0.0, (critical + 1e-3).cos());
        assert!(coat.refract_out(past).is_none());
    }

    /// A smooth coat's lobe albedo is the Fresnel reflectance at the angle (the lobe is a
    /// mirror): 0.04 at normal incidence for η 1.5.
    #[test]
    fn smooth_lobe_albedo_is_fresnel() {
        let layer = CoatLayer::new(Coat::new(1.5, 0.002, 1.0)).unwrap();
        for c in [0.3, 0.6, 0.95] {
            let f = crate::model::fresnel::dielectric(c, 1.5);
            assert!((layer.lobe_albedo(c) - f).abs() < 0.01 * f + 1e-4, "{c}");
        }
    }

    /// ∫ f cos θo dωo over the outside hemisphere by a uniform grid in (cos θo, φo).
    fn albedo_outside(f: &dyn Brdf, wi: DVec3) -> f64 {
        let (nt, np) = (800, 400);
        let mut sum = 0.0;
        for i in 0..nt {
            let c = (i as f64 + 0.5) / nt as f64;
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                let s = (1.0 - c * c).sqrt();
                let wo = DVec3::new(s * phi.cos(), s * phi.sin(), c);
                sum += f.eval(wi, wo).map_or(0.0, |v| v[0]) * c;
            }
        }
        sum * std::f64::consts::TAU / (nt * np) as f64
    }

    /// A white Lambertian under a rough coat, integrated outside, equals the energy balance
    /// of the module's documentation integrated inside: w E_c(θi) + T(θi) ∫ T(θo) cos θo' dωo'
    /// / π over the inside directions that leave (θo' below the critical angle). The 1/η² and
    /// the refraction's change of solid angle must both be right for the two to agree; the
    /// total stays below 1 (the white furnace).
    #[test]
    fn white_lambertian_under_a_coat_balances() {
        let layer = CoatLayer::new(Coat::new(1.5, 0.3, 1.0)).unwrap();
        let white = MicrofacetBrdf {
            name: "white".into(),
            ndf: Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.5)),
            fresnel: Fresnel::Schlick { f0: [0.0; 3] },
            diffuse: [1.0; 3],
        };
        let coated = Coated {
            layer: layer.clone(),
            base: white,
        };
        let critical = (1.0f64 / 1.5).asin();
        for deg in [0.0f64, 30.0, 60.0, 80.0] {
            let t = deg.to_radians();
            let wi = DVec3::new(t.sin(), 0.0, t.cos());
            let outside = albedo_outside(&coated, wi);
            let coat = directional_albedo(&layer.coat.lobe(), wi, 128)[0];
            let n = 4000;
            let inside: f64 = (0..n)
                .map(|k| {
                    let tp = (k as f64 + 0.5) / n as f64 * critical;
                    let out = layer.coat.refract_out(DVec3::new(tp.sin(), 0.0, tp.cos()));
                    let t_o = layer.transmission(out.unwrap().z);
                    // ∫ cos θ' dω' / π = ∫ 2 sin θ' cos θ' dθ'
                    t_o * 2.0 * tp.sin() * tp.cos() * critical / n as f64
                })
                .sum();
            let expected = coat + layer.transmission(wi.z) * inside;
            assert!(
                (outside - expected).abs() < 3e-3 * expected,
                "{deg}°: {outside} outside, {expected} inside"
            );
            assert!(outside < 1.0, "{deg}°: {outside}");
        }
    }

    #[test]
    fn bad_coats_are_refused() {
        for coat in [
            Coat::new(1.0, 0.1, 1.0),
            Coat::new(1.5, 0.0, 1.0),
            Coat::new(1.5, 0.1, 1.5),
            Coat::new(f64::NAN, 0.1, 1.0),
        ] {
            assert!(CoatLayer::new(coat).is_err(), "{coat:?}");
        }
    }
}
