//! Sampling the distribution of visible normals (Heitz 2018): for a view direction ωo,
//!
//!   D_ωo(h) = G1(ωo) max(0, ωo·h) D(h) / cos θo,   G1 = 1 / (1 + Λ(ωo)),
//!
//! the normals weighted by how much of them ωo sees. Reflecting ωo about such a normal gives
//! ωi with pdf D_ωo(h) / (4 ωo·h) = G1(ωo) D(h) / (4 cos θo), so the estimator f cos θi / pdf is
//! F G2 / G1 ≤ F: bounded, unlike D cos θh sampling's, which grows as 1/cos θo at grazing views.
//! GGX by the spherical caps of Dupuy & Benyoub (2023), Beckmann by inverting the visible-slope
//! CDF in the erf domain with Newton's method (Jakob 2014); both in the NDF's stretched, rotated
//! frame. WGSL twins: `shaders/common/microfacet.inc.wgsl`.

use crate::model::microfacet::{AnalyticNdf, Ndf, NdfKind};
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

/// Inverse error function on (−1, 1): Giles' (2010) single-precision approximation refined by
/// two Newton steps on erf(x) − y (f64 accuracy).
pub fn erfinv(y: f64) -> f64 {
    if y <= -1.0 {
        return f64::NEG_INFINITY;
    }
    if y >= 1.0 {
        return f64::INFINITY;
    }
    let mut x = erfinv_giles(y);
    for _ in 0..2 {
        // d erf / dx = 2/√π exp(−x²)
        let slope = 2.0 / PI.sqrt() * (-x * x).exp();
        if slope > 0.0 {
            x -= (libm::erf(x) - y) / slope;
        }
    }
    x
}

/// Giles, "Approximating the erfinv function" (GPU Computing Gems, 2010), the f32 version the
/// WGSL uses (relative error ≈ 1e-7 in f32).
pub fn erfinv_giles(y: f64) -> f64 {
    let mut w = -((1.0 - y) * (1.0 + y)).ln();
    let p = if w < 5.0 {
        w -= 2.5;
        [
            2.810_226_36e-08,
            3.432_739_39e-07,
            -3.523_387_7e-06,
            -4.391_506_54e-06,
            0.000_218_580_87,
            -0.001_253_725_03,
            -0.004_177_681_64,
            0.246_640_727,
            1.501_409_41,
        ]
        .iter()
        .fold(0.0, |p, c| c + p * w)
    } else {
        w = w.sqrt() - 3.0;
        [
            -0.000_200_214_257,
            0.000_100_950_558,
            0.001_349_343_22,
            -0.003_673_428_44,
            0.005_739_507_73,
            -0.007_622_461_3,
            0.009_438_870_47,
            1.001_674_06,
            2.832_976_82,
        ]
        .iter()
        .fold(0.0, |p, c| c + p * w)
    };
    p * y
}

fn rotate(v: DVec3, angle: f64) -> DVec3 {
    let (s, c) = angle.sin_cos();
    DVec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

/// Visible slopes of the unit Beckmann distribution seen from polar angle θ (cos θ given) in
/// the x–z plane: x̃ by Newton's method on the CDF in the erf domain, ỹ ∝ exp(−ỹ²).
fn beckmann_visible_slopes_11(cos_theta: f64, u: [f64; 2]) -> DVec2 {
    let tan_theta = ((1.0 - cos_theta * cos_theta).max(0.0)).sqrt() / cos_theta;
    let tan_theta = tan_theta.max(1e-8);
    let cot_theta = 1.0 / tan_theta;
    // x = erf(x̃) ∈ (−1, erf(cot θ)): CDF(x) ∝ 1 + x + tan θ exp(−x̃²)/√π.
    let max_x = libm::erf(cot_theta);
    let u = [u[0].clamp(1e-9, 1.0 - 1e-9), u[1].clamp(1e-9, 1.0 - 1e-9)];
    // A start from the θ = π/2 solution, the most curved case.
    let mut x = max_x - (max_x + 1.0) * libm::erf((-u[0].ln()).sqrt());
    let target = u[0] * (1.0 + max_x + tan_theta * (-cot_theta * cot_theta).exp() / PI.sqrt());
    for _ in 0..6 {
        let slope = erfinv(x);
        let value = 1.0 + x + tan_theta * (-slope * slope).exp() / PI.sqrt() - target;
        let derivative = 1.0 - slope * tan_theta;
        x = (x - value / derivative).clamp(-1.0 + 1e-15, max_x.min(1.0 - 1e-15));
    }
    DVec2::new(erfinv(x), erfinv(2.0 * u[1] - 1.0))
}

impl AnalyticNdf {
    /// Smith G1(w) = 1 / (1 + Λ(w)).
    pub fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// A normal from the distribution of normals visible from `wo` (wo.z > 0); its density over
    /// solid angle is [`AnalyticNdf::pdf_visible`].
    pub fn sample_visible(&self, wo: DVec3, u: [f64; 2]) -> DVec3 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let o = rotate(wo, -self.rotation);
        // The view in the stretched space where the NDF is the unit one.
        let v = DVec3::new(ax * o.x, ay * o.y, o.z.max(1e-12)).normalize();
        let h = match self.kind {
            NdfKind::Ggx => {
                // Dupuy & Benyoub 2023: a uniform point on the spherical cap z ≥ −v.z, plus v.
                let phi = 2.0 * PI * u[0];
                let z = (1.0 - u[1]) * (1.0 + v.z) - v.z;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let hs = DVec3::new(r * phi.cos(), r * phi.sin(), z) + v;
                DVec3::new(ax * hs.x, ay * hs.y, hs.z.max(0.0))
            }
            NdfKind::Beckmann => {
                let s = beckmann_visible_slopes_11(v.z, u);
                let l = v.truncate().length();
                let (sin_phi, cos_phi) = if l > 1e-12 {
                    (v.y / l, v.x / l)
                } else {
                    (0.0, 1.0)
                };
                let slope = DVec2::new(
                    (cos_phi * s.x - sin_phi * s.y) * ax,
                    (sin_phi * s.x + cos_phi * s.y) * ay,
                );
                DVec3::new(-slope.x, -slope.y, 1.0)
            }
        };
        rotate(h.normalize(), self.rotation)
    }

    /// D_wo(h) = G1(wo) max(0, wo·h) D(h) / wo.z, the density of
    /// [`AnalyticNdf::sample_visible`] over solid angle of h.
    pub fn pdf_visible(&self, wo: DVec3, h: DVec3) -> f64 {
        if wo.z <= 0.0 || h.z <= 0.0 {
            return 0.0;
        }
        self.g1(wo) * wo.dot(h).max(0.0) * self.d(h) / wo.z
    }
}

impl Ndf {
    /// A normal for reflecting `wo`: visible-normal sampling for analytic NDFs, the table's own
    /// sampling (D cos θh) for tabulated ones; its density is [`Ndf::pdf_visible`].
    pub fn sample_visible(&self, wo: DVec3, u: [f64; 2]) -> DVec3 {
        match self {
            Ndf::Analytic(n) => n.sample_visible(wo, u),
            Ndf::Tabulated(t) => t.sample_visible(wo, u),
        }
    }

    /// The density of [`Ndf::sample_visible`] over solid angle of h.
    pub fn pdf_visible(&self, wo: DVec3, h: DVec3) -> f64 {
        match self {
            Ndf::Analytic(n) => n.pdf_visible(wo, h),
            Ndf::Tabulated(t) => t.pdf_visible(wo, h),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfinv_inverts_erf() {
        for k in 1..2000 {
            let y = -1.0 + 2.0 * k as f64 / 2000.0;
            let x = erfinv(y);
            assert!(
                (libm::erf(x) - y).abs() < 1e-14,
                "y {y}: erf(erfinv) = {}",
                libm::erf(x)
            );
            assert!(
                (erfinv_giles(y) / x - 1.0).abs() < 2e-6 || x.abs() < 1e-9,
                "Giles at {y}"
            );
        }
    }

    /// χ² of visible-normal samples against pdf_visible over cells uniform in (√(θ / (π/2)), φ)
    /// (finer near the pole, where narrow lobes live), for both families, isotropic and
    /// anisotropic rotated, from normal to grazing (85°) views.
    #[test]
    fn visible_normal_samples_follow_their_pdf() {
        for kind in [NdfKind::Ggx, NdfKind::Beckmann] {
            for (ax, ay, rot) in [(0.3, 0.3, 0.0), (0.1, 0.5, 0.7), (0.8, 0.2, -1.1)] {
                for theta_deg in [0.0f64, 40.0, 85.0] {
                    let ndf = AnalyticNdf {
                        kind,
                        alpha_x: ax,
                        alpha_y: ay,
                        rotation: rot,
                    };
                    let name = format!("{kind:?} α ({ax}, {ay}) rot {rot} θo {theta_deg}°");
                    let wo = view(theta_deg);
                    chi2_check(
                        &name,
                        |u| ndf.sample_visible(wo, u),
                        |h| ndf.pdf_visible(wo, h),
                        8,
                        2e-3,
                    );
                }
            }
        }
    }

    /// The same χ² for the tabulated NDF's visible sampling (its slices' mixture): an
    /// isotropic table (GGX 0.2 on 33 u nodes), stretched and rotated, and an anisotropic one
    /// (Beckmann 0.15 × 0.4 on 17 × 24 nodes). The pdf is piecewise constant on cells that do
    /// not align with the test's, so the expected counts use a finer rule.
    #[test]
    fn tabulated_visible_samples_follow_their_pdf() {
        use crate::model::geometry::spherical;
        use crate::model::tabulated::{NdfTables, Stretch, TabulatedNdf, phi_node, u_node_theta};
        let table = |d: &AnalyticNdf, nu: usize, nphi: usize| {
            let mut v = Vec::new();
            for k in 0..nu {
                for l in 0..nphi {
                    v.push(d.d(spherical(u_node_theta(k, nu), phi_node(l, nphi))));
                }
            }
            NdfTables {
                nu,
                nphi,
                d: v,
                ng: 2,
                g1: vec![1.0; 2 * nphi],
            }
        };
        let ggx = AnalyticNdf {
            kind: NdfKind::Ggx,
            alpha_x: 0.2,
            alpha_y: 0.2,
            rotation: 0.0,
        };
        let beckmann = AnalyticNdf {
            kind: NdfKind::Beckmann,
            alpha_x: 0.15,
            alpha_y: 0.4,
            rotation: 0.0,
        };
        let cases = [
            ("isotropic", table(&ggx, 33, 1), Stretch::IDENTITY),
            (
                "isotropic stretched",
                table(&ggx, 33, 1),
                Stretch {
                    alpha_x: 0.6,
                    alpha_y: 2.0,
                    rotation: 0.4,
                },
            ),
            ("anisotropic", table(&beckmann, 17, 24), Stretch::IDENTITY),
            (
                "anisotropic rotated",
                table(&beckmann, 17, 24),
                Stretch {
                    alpha_x: 1.5,
                    alpha_y: 1.0,
                    rotation: -0.9,
                },
            ),
        ];
        for (what, tables, stretch) in cases {
            let ndf = TabulatedNdf::new(tables, stretch).unwrap();
            for theta_deg in [0.0f64, 33.0, 61.0, 85.0] {
                let wo = view(theta_deg);
                chi2_check(
                    &format!("tabulated {what} θo {theta_deg}°"),
                    |u| ndf.sample_visible(wo, u),
                    |h| ndf.pdf_visible(wo, h),
                    48,
                    1e-3,
                );
            }
        }
    }

    /// 2·10⁵ samples against the pdf: ∫ pdf within `tol` of 1 (the midpoint rule's own error on
    /// the steepest cells) and z below 5.
    fn chi2_check(
        name: &str,
        mut sample: impl FnMut([f64; 2]) -> DVec3,
        pdf: impl Fn(DVec3) -> f64,
        sub: usize,
        tol: f64,
    ) {
        let mut next =
            crate::numerics::chi2::uniforms(0x9e37_79b9_7f4a_7c15 ^ (name.len() as u64) << 7);
        let samples: Vec<DVec3> = (0..200_000)
            .map(|_| {
                let h = sample([next(), next()]);
                assert!(
                    h.is_finite() && (h.length() - 1.0).abs() < 1e-9,
                    "{name}: {h}"
                );
                h
            })
            .collect();
        let r = crate::numerics::chi2::chi2_hemisphere(&samples, pdf, sub);
        println!(
            "{name}: ∫pdf {:.4}, χ² {:.0} on {} dof, z {:.2}",
            r.integral, r.chi2, r.dof, r.z
        );
        assert!(
            (r.integral - 1.0).abs() < tol,
            "{name}: ∫ pdf = {}",
            r.integral
        );
        assert!(r.z < 5.0, "{name}: χ² z = {}", r.z);
    }

    fn view(theta_deg: f64) -> DVec3 {
        let t = theta_deg.to_radians();
        DVec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos()).normalize()
    }
}
