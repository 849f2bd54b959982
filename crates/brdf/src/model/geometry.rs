//! Shading-frame geometry: spherical angles and the Rusinkiewicz half/difference
//! parameterisation used by MERL (Rusinkiewicz 1998).
//!
//! Convention: z is the normal, x the tangent, directions point away from the surface.

use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// Direction from spherical angles.
pub fn spherical(theta: f64, phi: f64) -> DVec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    DVec3::new(st * cp, st * sp, ct)
}

/// Polar angle of a unit vector, robust near the poles.
pub fn theta_of(w: DVec3) -> f64 {
    w.z.clamp(-1.0, 1.0).acos()
}

/// Azimuth of a vector in [0, 2π).
pub fn phi_of(w: DVec3) -> f64 {
    let p = w.y.atan2(w.x);
    if p < 0.0 { p + 2.0 * PI } else { p }
}

/// Rusinkiewicz coordinates of a pair of directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HalfDiff {
    /// Polar angle of the half vector, radians.
    pub theta_h: f64,
    /// Azimuth of the half vector, radians.
    pub phi_h: f64,
    /// Polar angle of the difference vector, radians.
    pub theta_d: f64,
    /// Azimuth of the difference vector, radians.
    pub phi_d: f64,
}

/// (wi, wo) → (θh, φh, θd, φd): h = normalize(wi + wo), d = wi expressed in the frame of h
/// (rotate by −φh about z, then by −θh about y).
pub fn to_half_diff(wi: DVec3, wo: DVec3) -> HalfDiff {
    let h = (wi + wo).normalize();
    let theta_h = theta_of(h);
    let phi_h = h.y.atan2(h.x);
    let d = rotate_y(rotate_z(wi, -phi_h), -theta_h);
    HalfDiff {
        theta_h,
        phi_h,
        theta_d: theta_of(d),
        phi_d: d.y.atan2(d.x),
    }
}

/// (θh, φh, θd, φd) → (wi, wo): the inverse of [`to_half_diff`].
pub fn from_half_diff(c: HalfDiff) -> (DVec3, DVec3) {
    let h = spherical(c.theta_h, c.phi_h);
    let d = spherical(c.theta_d, c.phi_d);
    let wi = rotate_z(rotate_y(d, c.theta_h), c.phi_h);
    let wo = 2.0 * wi.dot(h) * h - wi; // mirror wi about h
    (wi, wo)
}

fn rotate_z(v: DVec3, a: f64) -> DVec3 {
    let (s, c) = a.sin_cos();
    DVec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

fn rotate_y(v: DVec3, a: f64) -> DVec3 {
    let (s, c) = a.sin_cos();
    DVec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
}

/// Azimuthal angle between the projections of wi and wo on the surface, in [0, π]
/// (0 when either is the normal).
pub fn azimuth_between(wi: DVec3, wo: DVec3) -> f64 {
    let (a, b) = (wi.truncate(), wo.truncate());
    let (la, lb) = (a.length(), b.length());
    if la < 1e-12 || lb < 1e-12 {
        return 0.0;
    }
    (a.dot(b) / (la * lb)).clamp(-1.0, 1.0).acos()
}

/// The sqrt mapping of θh used by MERL and by Facet's NDF tables: u = sqrt(θ / (π/2)) ∈ [0, 1].
pub fn theta_to_u(theta: f64) -> f64 {
    (theta.max(0.0) / FRAC_PI_2).sqrt()
}

/// Inverse of [`theta_to_u`]: θ = u² π/2.
pub fn u_to_theta(u: f64) -> f64 {
    u * u * FRAC_PI_2
}

/// acos x, x clamped to [−1, 1], to 2e-8 absolute (Abramowitz & Stegun 4.4.46:
/// acos |x| = √(1 − |x|) P(|x|), P of degree 7): cheaper than libm's acos, and branch-free
/// but for a select, so loops over it vectorise (the MERL grid's 737 000 angles, the
/// extraction's azimuthal integrals).
pub fn acos_poly(x: f64) -> f64 {
    const P: [f64; 8] = [
        1.570_796_305_0,
        -0.214_598_801_6,
        0.088_978_987_4,
        -0.050_174_304_6,
        0.030_891_881_0,
        -0.017_088_125_6,
        0.006_670_090_1,
        -0.001_262_491_1,
    ];
    let a = x.abs().min(1.0);
    let p = P.iter().rev().fold(0.0, |acc, &c| acc * a + c);
    let r = (1.0 - a).sqrt() * p;
    if x < 0.0 { std::f64::consts::PI - r } else { r }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomial_acos_is_within_its_bound() {
        let worst = (0..=200_000)
            .map(|n| -1.0 + n as f64 / 100_000.0)
            .map(|x: f64| (acos_poly(x) - x.acos()).abs())
            .fold(0.0, f64::max);
        assert!(worst < 2.5e-8, "{worst:e}");
        assert_eq!(acos_poly(1.5), 0.0);
        assert!((acos_poly(-1.5) - std::f64::consts::PI).abs() < 2.5e-8);
    }

    #[test]
    fn half_diff_round_trip() {
        for &(th, ph, td, pd) in &[
            (0.3, 0.0, 0.5, 1.0),
            (1.2, 0.7, 0.1, -2.0),
            (0.01, -1.0, 1.4, 3.0),
        ] {
            let c = HalfDiff {
                theta_h: th,
                phi_h: ph,
                theta_d: td,
                phi_d: pd,
            };
            let (wi, wo) = from_half_diff(c);
            let b = to_half_diff(wi, wo);
            assert!((b.theta_h - th).abs() < 1e-12 && (b.phi_h - ph).abs() < 1e-12);
            assert!((b.theta_d - td).abs() < 1e-12 && (b.phi_d - pd).abs() < 1e-12);
            assert!((wi.length() - 1.0).abs() < 1e-12 && (wo.length() - 1.0).abs() < 1e-12);
        }
    }
}
