//! Quadrature rules over θ ∈ [0, π/2] for the extraction's integral equation.

use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI};

/// How the N polar nodes of the extraction are placed.
///
/// Measured on MERL files made from GGX and Beckmann (`tests/quadrature.rs`, table in
/// docs/fitting.md): both rules in u = sqrt(θ/(π/2)) recover α 10–50× better than the paper's
/// uniform θ nodes at N ≤ 64, because they put nodes where specular NDFs are peaked (small θ).
/// Gauss–Legendre is best at N = 16; from N = 32 both sit on a ~0.3 % floor set by the MERL bins.
/// It is the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quadrature {
    /// Midpoint rule, uniform in θ (the paper's discretisation).
    UniformTheta,
    /// Midpoint rule, uniform in u = sqrt(θ/(π/2)) (MERL's θh mapping).
    SqrtMidpoint,
    /// Gauss–Legendre in u = sqrt(θ/(π/2)).
    #[default]
    GaussLegendreSqrt,
}

impl Quadrature {
    /// Every quadrature.
    pub const ALL: [Quadrature; 3] = [
        Quadrature::UniformTheta,
        Quadrature::SqrtMidpoint,
        Quadrature::GaussLegendreSqrt,
    ];

    /// N nodes θ_j and weights w_j with ∫₀^{π/2} g(θ) dθ ≈ Σ_j w_j g(θ_j).
    pub fn nodes(self, n: usize) -> Vec<(f64, f64)> {
        match self {
            Quadrature::UniformTheta => (0..n)
                .map(|j| {
                    (
                        (j as f64 + 0.5) / n as f64 * FRAC_PI_2,
                        FRAC_PI_2 / n as f64,
                    )
                })
                .collect(),
            // θ = u² π/2, dθ = π u du
            Quadrature::SqrtMidpoint => (0..n)
                .map(|j| {
                    let u = (j as f64 + 0.5) / n as f64;
                    (u * u * FRAC_PI_2, PI * u / n as f64)
                })
                .collect(),
            Quadrature::GaussLegendreSqrt => gauss_legendre(n)
                .into_iter()
                .map(|(u, w)| (u * u * FRAC_PI_2, PI * u * w))
                .collect(),
        }
    }
}

/// Gauss–Legendre nodes and weights on [0, 1], by Newton iteration on P_n (ascending nodes).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0, 0.0); n];
    for i in 0..n.div_ceil(2) {
        // Initial guess: the Chebyshev-like estimate of the i-th root of P_n on [−1, 1].
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // Recurrence (k+1) P_{k+1} = (2k+1) x P_k − k P_{k−1}
            let (mut p0, mut p1) = (1.0, x);
            for k in 1..n {
                let p2 = ((2 * k + 1) as f64 * x * p1 - k as f64 * p0) / (k + 1) as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 1 { x } else { p1 };
            let pm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * p - pm1) / (x * x - 1.0); // P_n'(x)
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        // Map [−1, 1] → [0, 1]: ascending order, symmetric pairs.
        out[i] = ((1.0 - x) / 2.0, w / 2.0);
        out[n - 1 - i] = ((1.0 + x) / 2.0, w / 2.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_and_sin() {
        // Gauss–Legendre with n nodes is exact for degree 2n − 1.
        let gl = gauss_legendre(7);
        for deg in 0..14 {
            let s: f64 = gl.iter().map(|(x, w)| w * x.powi(deg)).sum();
            assert!(
                (s - 1.0 / (deg + 1) as f64).abs() < 1e-13,
                "degree {deg}: {s}"
            );
        }
        // ∫₀^{π/2} sin θ dθ = 1 for every rule.
        for q in Quadrature::ALL {
            let s: f64 = q.nodes(200).iter().map(|(t, w)| w * t.sin()).sum();
            assert!((s - 1.0).abs() < 1e-4, "{q:?}: {s}");
        }
    }
}
