//! Microfacet models: GGX and Beckmann NDFs (isotropic and anisotropic) with their exact Smith
//! Λ, the tabulated NDF of an extraction, the shadowing-masking model, and the microfacet BRDF
//! `f = F(wi·h) D(h) G2(wi, wo) / (4 cos θi cos θo) + ρd/π`.

use crate::model::brdf::Brdf;
use crate::model::fresnel::Fresnel;
use crate::model::geometry::azimuth_between;
use crate::model::rgb::Rgb;
use crate::model::tabulated::TabulatedNdf;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::sync::Arc;

/// The two analytic NDF families.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NdfKind {
    /// Trowbridge–Reitz (GGX).
    Ggx,
    /// Beckmann.
    Beckmann,
}

impl NdfKind {
    /// Both kinds.
    pub const ALL: [NdfKind; 2] = [NdfKind::Ggx, NdfKind::Beckmann];

    /// `ggx` or `beckmann`.
    pub fn name(self) -> &'static str {
        match self {
            NdfKind::Ggx => "ggx",
            NdfKind::Beckmann => "beckmann",
        }
    }

    /// α from the first absolute slope moment E|x~| along one axis:
    /// GGX E|x~| = α, Beckmann E|x~| = α/√π.
    pub fn alpha_from_abs_slope_moment(self, m: f64) -> f64 {
        match self {
            NdfKind::Ggx => m,
            NdfKind::Beckmann => m * PI.sqrt(),
        }
    }
}

/// An analytic NDF with roughness αx along the tangent rotated by `rotation` about the normal
/// and αy across it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalyticNdf {
    /// GGX or Beckmann.
    pub kind: NdfKind,
    /// α along the rotated x axis.
    pub alpha_x: f64,
    /// α along the rotated y axis.
    pub alpha_y: f64,
    /// Radians, counter-clockwise from the tangent.
    pub rotation: f64,
}

impl AnalyticNdf {
    /// An isotropic NDF of roughness `alpha`.
    pub const fn isotropic(kind: NdfKind, alpha: f64) -> Self {
        AnalyticNdf {
            kind,
            alpha_x: alpha,
            alpha_y: alpha,
            rotation: 0.0,
        }
    }

    /// Whether αx = αy.
    pub fn is_isotropic(&self) -> bool {
        self.alpha_x == self.alpha_y
    }

    /// D(h), normalised so that ∫ D(h) cos θh dω = 1.
    pub fn d(&self, h: DVec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let h = to_local(h, self.rotation);
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let e = (h.x / ax).powi(2) + (h.y / ay).powi(2); // tan²θ (cos²φ/αx² + sin²φ/αy²) cos²θ
        match self.kind {
            // D = 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)
            NdfKind::Ggx => 1.0 / (PI * ax * ay * (e + h.z * h.z).powi(2)),
            // D = exp(−(hx²/αx² + hy²/αy²)/hz²) / (π αx αy hz⁴)
            NdfKind::Beckmann => (-e / (h.z * h.z)).exp() / (PI * ax * ay * h.z.powi(4)),
        }
    }

    /// Samples a normal with density D(h) cos θh over solid angle: a slope of the unit
    /// distribution (GGX: tan θ = sqrt(u/(1 − u)); Beckmann: tan θ = sqrt(−ln(1 − u))),
    /// stretched by (αx, αy) and rotated.
    pub fn sample(&self, u: [f64; 2]) -> DVec3 {
        let r = match self.kind {
            NdfKind::Ggx => (u[0] / (1.0 - u[0]).max(1e-300)).sqrt(),
            NdfKind::Beckmann => (-(1.0 - u[0]).max(1e-300).ln()).sqrt(),
        };
        let phi = 2.0 * PI * u[1];
        let (sx, sy) = (r * phi.cos() * self.alpha_x, r * phi.sin() * self.alpha_y);
        let h = DVec3::new(sx, sy, 1.0).normalize();
        let (sn, c) = self.rotation.sin_cos();
        DVec3::new(c * h.x - sn * h.y, sn * h.x + c * h.y, h.z)
    }

    /// Smith Λ(w), exact for both families.
    pub fn lambda(&self, w: DVec3) -> f64 {
        let w = to_local(w, self.rotation);
        if w.z <= 0.0 {
            return f64::INFINITY;
        }
        // α(φ)² tan²θ = (wx² αx² + wy² αy²) / wz²
        let a2t2 = ((w.x * self.alpha_x).powi(2) + (w.y * self.alpha_y).powi(2)) / (w.z * w.z);
        lambda_from_alpha_tan(self.kind, a2t2)
    }
}

/// Smith Λ of an isotropic family as a function of α² tan²θ.
pub fn lambda_from_alpha_tan(kind: NdfKind, a2t2: f64) -> f64 {
    if a2t2 <= 0.0 {
        return 0.0;
    }
    match kind {
        // Λ = (−1 + sqrt(1 + α² tan²θ)) / 2
        NdfKind::Ggx => 0.5 * ((1.0 + a2t2).sqrt() - 1.0),
        // Λ = (erf(a) − 1)/2 + exp(−a²)/(2a√π), a = 1/(α tanθ)
        NdfKind::Beckmann => {
            let a = 1.0 / a2t2.sqrt();
            if a > 6.0 {
                return 0.0; // erf(6) = 1 − 2e−17: below f64 resolution
            }
            0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * PI.sqrt())
        }
    }
}

fn to_local(w: DVec3, rotation: f64) -> DVec3 {
    if rotation == 0.0 {
        return w;
    }
    let (s, c) = rotation.sin_cos();
    DVec3::new(c * w.x + s * w.y, -s * w.x + c * w.y, w.z)
}

/// An NDF: analytic or tabulated from an extraction (possibly stretched).
#[derive(Clone, Debug)]
pub enum Ndf {
    /// GGX or Beckmann with its parameters.
    Analytic(AnalyticNdf),
    /// An extracted table.
    Tabulated(Arc<TabulatedNdf>),
}

impl Ndf {
    /// D(h).
    pub fn d(&self, h: DVec3) -> f64 {
        match self {
            Ndf::Analytic(n) => n.d(h),
            Ndf::Tabulated(t) => t.d(h),
        }
    }

    /// Λ(ω), Smith's auxiliary function: G1(ω) = 1 / (1 + Λ(ω)).
    pub fn lambda(&self, w: DVec3) -> f64 {
        match self {
            Ndf::Analytic(n) => n.lambda(w),
            Ndf::Tabulated(t) => t.lambda(w),
        }
    }

    /// Whether D is invariant under rotation about the normal.
    pub fn is_isotropic(&self) -> bool {
        match self {
            Ndf::Analytic(n) => n.is_isotropic(),
            Ndf::Tabulated(t) => t.is_isotropic(),
        }
    }

    /// Samples a microfacet normal; its density over solid angle is [`Ndf::pdf`].
    pub fn sample(&self, u: [f64; 2]) -> DVec3 {
        match self {
            Ndf::Analytic(n) => n.sample(u),
            Ndf::Tabulated(t) => t.sample(u),
        }
    }

    /// The density of [`Ndf::sample`]: D(h) cos θh (analytic), the table's sampling density
    /// (tabulated).
    pub fn pdf(&self, h: DVec3) -> f64 {
        match self {
            Ndf::Analytic(n) => n.d(h) * h.z.max(0.0),
            Ndf::Tabulated(t) => t.pdf(h),
        }
    }
}

/// λ(φ) = 4.41φ / (4.41φ + 1) of the height-direction-correlated Smith G2 (Ashikhmin et al.).
pub fn correlation(phi: f64) -> f64 {
    4.41 * phi / (4.41 * phi + 1.0)
}

/// Height-direction-correlated Smith shadowing-masking, the one model of Facet:
/// G2 = 1 / (1 + max(Λi, Λo) + λ(φ) min(Λi, Λo)). G2(o, o) = G1(o) since λ(0) = 0, which is
/// what the backscattering inversion assumes.
pub fn g2(lambda_i: f64, lambda_o: f64, correlation: f64) -> f64 {
    let (hi, lo) = (lambda_i.max(lambda_o), lambda_i.min(lambda_o));
    // Both directions on the horizon: Λ = ∞ twice, and λ(φ) · ∞ would be NaN for λ = 0.
    if hi == f64::INFINITY {
        return 0.0;
    }
    1.0 / (1.0 + hi + correlation * lo)
}

/// A microfacet BRDF with an optional Lambertian term.
#[derive(Clone, Debug)]
pub struct MicrofacetBrdf {
    /// The model's name (in messages and plots).
    pub name: String,
    /// The normal distribution.
    pub ndf: Ndf,
    /// The Fresnel term.
    pub fresnel: Fresnel,
    /// Lambertian albedo ρd (f = ρd/π), zero for none.
    pub diffuse: Rgb,
}

impl MicrofacetBrdf {
    /// The model of `ndf` with F = 1 and no diffuse term: the start of a Fresnel (and ρd)
    /// solve for its D and G.
    pub fn ideal(name: &str, ndf: Ndf) -> Self {
        MicrofacetBrdf {
            name: name.to_owned(),
            ndf,
            fresnel: crate::model::fresnel::Fresnel::Schlick { f0: [1.0; 3] },
            diffuse: [0.0; 3],
        }
    }

    /// D(h) G2(wi, wo) / (4 cos θi cos θo): the BRDF with F = 1 and no diffuse term.
    pub fn eval_ideal(&self, wi: DVec3, wo: DVec3) -> f64 {
        let h = (wi + wo).normalize();
        let g = g2(
            self.ndf.lambda(wi),
            self.ndf.lambda(wo),
            correlation(azimuth_between(wi, wo)),
        );
        self.ndf.d(h) * g / (4.0 * wi.z * wo.z)
    }
}

impl Brdf for MicrofacetBrdf {
    fn name(&self) -> &str {
        &self.name
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let h = (wi + wo).normalize();
        let spec = self.eval_ideal(wi, wo);
        let f = self.fresnel.eval(wi.dot(h));
        Some(std::array::from_fn(|c| f[c] * spec + self.diffuse[c] / PI))
    }

    fn is_isotropic(&self) -> bool {
        self.ndf.is_isotropic()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::geometry::spherical;

    /// Sampled slopes have the first absolute moments of the NDF along its own axes:
    /// E|x~| = αx (GGX) or αx/√π (Beckmann), likewise for y.
    #[test]
    fn sampling_reproduces_slope_moments() {
        for kind in NdfKind::ALL {
            let ndf = AnalyticNdf {
                kind,
                alpha_x: 0.2,
                alpha_y: 0.5,
                rotation: 0.6,
            };
            let n = 200_000;
            let (mut mx, mut my) = (0.0, 0.0);
            for k in 0..n {
                // A (0.5, golden-ratio) low-discrepancy sequence.
                let u = [
                    (k as f64 + 0.5) / n as f64,
                    (k as f64 * 0.618_033_988_749_895).fract(),
                ];
                let h = to_local(ndf.sample(u), ndf.rotation);
                mx += (h.x / h.z).abs();
                my += (h.y / h.z).abs();
            }
            let c = match kind {
                NdfKind::Ggx => 1.0,
                NdfKind::Beckmann => 1.0 / PI.sqrt(),
            };
            let (ex, ey) = (mx / n as f64 / (0.2 * c), my / n as f64 / (0.5 * c));
            assert!(
                (ex - 1.0).abs() < 0.01 && (ey - 1.0).abs() < 0.01,
                "{kind:?}: {ex} {ey}"
            );
        }
    }

    /// ∫ D cos θ dω = 1 and ∫ <k,h>+ D dω = cos θk (1 + Λ(k)), by brute-force quadrature.
    #[test]
    fn ndf_normalised_and_lambda_consistent() {
        for kind in NdfKind::ALL {
            for &(ax, ay, rot) in &[(0.3, 0.3, 0.0), (0.2, 0.5, 0.4), (0.8, 0.8, 0.0)] {
                let ndf = AnalyticNdf {
                    kind,
                    alpha_x: ax,
                    alpha_y: ay,
                    rotation: rot,
                };
                let k = spherical(1.1, 0.3);
                let (nt, np) = (2000, 256);
                let (mut norm, mut proj) = (0.0, 0.0);
                for it in 0..nt {
                    // θ = u² π/2 concentrates nodes where D is peaked
                    let u = (it as f64 + 0.5) / nt as f64;
                    let theta = u * u * PI / 2.0;
                    let dtheta = PI * u / nt as f64;
                    for ip in 0..np {
                        let phi = (ip as f64 + 0.5) / np as f64 * 2.0 * PI;
                        let h = spherical(theta, phi);
                        let w = ndf.d(h) * theta.sin() * dtheta * 2.0 * PI / np as f64;
                        norm += w * h.z;
                        proj += w * k.dot(h).max(0.0);
                    }
                }
                assert!(
                    (norm - 1.0).abs() < 2e-3,
                    "{kind:?} {ax} {ay}: ∫D cos = {norm}"
                );
                let expect = k.z * (1.0 + ndf.lambda(k));
                assert!(
                    (proj / expect - 1.0).abs() < 2e-3,
                    "{kind:?}: {proj} vs {expect}"
                );
            }
        }
    }
}
