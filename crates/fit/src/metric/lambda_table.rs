//! Λ cos θ tables uniform in cos θ: the G of an isotropic model on the fast path
//! ([`crate::metric::iso_tables::IsoTables`]).
//!
//! A fit builds one table for every model its searches try, some fifty per analytic family,
//! so their cost counts. Evaluated entry by entry through the general Λ, a table of 4096
//! cosines took 28 µs for GGX, 143 µs for Beckmann (an erf and an exp per entry) and
//! 160–250 µs for a tabulated NDF (an arctangent per entry), serially inside the searches.
//! Here the cosines' sines and angles, the same for every table, are computed once per
//! process, GGX's closed form runs in a loop the compiler vectorises, and Beckmann reads a
//! universal function from a table of its own (below), built on first use: 14.5, 29 and
//! 50–75 µs per [`crate::metric::iso_tables::IsoTables`], which also evaluates D and F per bin. The fits'
//! results are unchanged to the last digit on the five files of `examples/fit_timing.rs`.
//!
//! Beckmann: Λ = (erf a − 1) / 2 + e^(−a²) / (2 a √π), a = cot θ / α, so that
//! Λ cos θ = α sin θ B(a) with B(a) = e^(−a²) / (2√π) − a erfc(a) / 2, whose derivative is
//! B′(a) = −erfc(a) / 2. B and B′ are tabulated on [0, [`B_MAX`]] and read by cubic Hermite
//! interpolation: its error is below h⁴ max|B⁗| / 384 with B⁗ = (4a² − 2) e^(−a²) / √π,
//! 2e-14 absolute and at most 3e-10 relative (at a = 6, where B ≈ e^(−a²) / (4a²√π)), far
//! below the f32 entries' rounding.

use crate::model::microfacet::{Ndf, NdfKind};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Entries of a table, uniform in cos θ over [0, 1].
pub(crate) const LAMBDA_TABLE: usize = 4096;

/// Above a = 6 Beckmann's Λ is taken as 0: erf(6) = 1 − 2e-17, below f64 resolution.
const B_MAX: f64 = 6.0;
/// Cells of the B table over [0, `B_MAX`].
const B_CELLS: usize = 4096;

/// The tables' cosines μ_k = k / (n − 1), with sin θ_k, cot θ_k and θ_k (arrays of the
/// tables' length, so that the loops over them need no bounds checks and vectorise).
struct Nodes {
    mu: [f64; LAMBDA_TABLE],
    sin: [f64; LAMBDA_TABLE],
    cot: [f64; LAMBDA_TABLE],
    theta: [f64; LAMBDA_TABLE],
}

fn nodes() -> &'static Nodes {
    static NODES: OnceLock<Box<Nodes>> = OnceLock::new();
    NODES.get_or_init(|| {
        let last = (LAMBDA_TABLE - 1) as f64;
        let mu: [f64; LAMBDA_TABLE] = std::array::from_fn(|k| k as f64 / last);
        let sin = mu.map(|m| (1.0 - m * m).max(0.0).sqrt());
        Box::new(Nodes {
            mu,
            sin,
            cot: std::array::from_fn(|k| mu[k] / sin[k]),
            theta: std::array::from_fn(|k| sin[k].atan2(mu[k])),
        })
    })
}

/// B(a_j) and h B′(a_j) at a_j = j h, h = `B_MAX` / `B_CELLS`.
fn beckmann_b() -> &'static [[f64; 2]] {
    static B: OnceLock<Vec<[f64; 2]>> = OnceLock::new();
    B.get_or_init(|| {
        let h = B_MAX / B_CELLS as f64;
        (0..=B_CELLS)
            .map(|j| {
                let a = j as f64 * h;
                let erfc = libm::erfc(a);
                // B = e^(−a²) / (2√π) − a erfc(a) / 2, B′ = −erfc(a) / 2
                let b = (-a * a).exp() / (2.0 * PI.sqrt()) - 0.5 * a * erfc;
                [b, -0.5 * h * erfc]
            })
            .collect()
    })
}

/// B(a) by cubic Hermite interpolation of [`beckmann_b`], 0 from `B_MAX` on.
#[inline(always)]
fn beckmann_b_at(table: &[[f64; 2]], a: f64) -> f64 {
    if !(a < B_MAX) {
        return 0.0;
    }
    let x = a * (B_CELLS as f64 / B_MAX);
    let j = (x as usize).min(B_CELLS - 1);
    let t = x - j as f64;
    let ([b0, d0], [b1, d1]) = (table[j], table[j + 1]);
    // Hermite basis: h00 = 2t³ − 3t² + 1, h10 = t³ − 2t² + t, h01 = 3t² − 2t³, h11 = t³ − t²
    let (t2, t3) = (t * t, t * t * t);
    let h01 = 3.0 * t2 - 2.0 * t3;
    b0 + h01 * (b1 - b0) + (t3 - 2.0 * t2 + t) * d0 + (t3 - t2) * d1
}

/// Λ(θ) cos θ of an isotropic NDF at the cosines μ_k = k / (n − 1); at μ = 0, where Λ is
/// infinite and Λ cos θ finite, extrapolated linearly from the next two entries.
pub(crate) fn lambda_cos_table(ndf: &Ndf) -> Box<[f32; LAMBDA_TABLE]> {
    debug_assert!(ndf.is_isotropic());
    let n = nodes();
    let mut out = Box::new([0.0f32; LAMBDA_TABLE]);
    match ndf {
        Ndf::Analytic(a) if a.kind == NdfKind::Ggx => {
            let a2 = a.alpha_x * a.alpha_x;
            for k in 1..LAMBDA_TABLE {
                // Λ cos θ = (sqrt(μ² + α² sin²θ) − μ) / 2, written without the cancellation
                let (mu, m) = (n.mu[k], a2 * n.sin[k] * n.sin[k]);
                out[k] = (0.5 * m / ((mu * mu + m).sqrt() + mu)) as f32;
            }
        }
        Ndf::Analytic(a) => {
            let (alpha, b) = (a.alpha_x, beckmann_b());
            for k in 1..LAMBDA_TABLE {
                // Λ cos θ = α sin θ B(cot θ / α)
                out[k] = (alpha * n.sin[k] * beckmann_b_at(b, n.cot[k] / alpha)) as f32;
            }
        }
        Ndf::Tabulated(t) => {
            let alpha = t.stretch.alpha_x;
            for (k, o) in out.iter_mut().enumerate().skip(1) {
                // The stretch maps the polar angle: tan θ₀ = α tan θ.
                let theta0 = match alpha == 1.0 {
                    true => n.theta[k],
                    false => (alpha * n.sin[k]).atan2(n.mu[k]),
                };
                *o = (t.lambda_of_theta0(theta0) * n.mu[k]) as f32;
            }
        }
    }
    out[0] = (2.0 * out[1] - out[2]).max(0.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::microfacet::{AnalyticNdf, lambda_from_alpha_tan};
    use glam::DVec3;

    /// Each table is the general Λ(ω) cos θ at its cosines: GGX to f64 rounding (relative
    /// 1e-6 of an f32 entry at most, 2 ulp), Beckmann within the Hermite bound (3e-10
    /// relative) plus f32 rounding, from α = 10⁻³ to 3, near the normal and at grazing
    /// cosines; a tabulated NDF's entries are its own Λ's, stretched or not.
    #[test]
    fn tables_are_the_general_lambda() {
        for kind in [NdfKind::Ggx, NdfKind::Beckmann] {
            for alpha in [1e-3, 0.013, 0.1, 0.37, 1.0, 3.0] {
                let ndf = Ndf::Analytic(AnalyticNdf::isotropic(kind, alpha));
                let table = lambda_cos_table(&ndf);
                for k in 1..LAMBDA_TABLE {
                    let mu = k as f64 / (LAMBDA_TABLE - 1) as f64;
                    let a2t2 = alpha * alpha * (1.0 - mu * mu) / (mu * mu);
                    let want = lambda_from_alpha_tan(kind, a2t2) * mu;
                    let got = table[k] as f64;
                    // f32 rounding (6e-8 relative) and, for Beckmann, the reference's own
                    // erf(a) − 1, whose absolute error (1e-16) is large next to Λ ≈ 1e-14
                    // at a = 5.
                    let tol = 2.5e-7 * want + 1e-15;
                    assert!(
                        (got - want).abs() <= tol,
                        "{kind:?} α {alpha} μ {mu}: {got} vs {want}"
                    );
                }
                // μ = 0: extrapolated, α / (2√π) for Beckmann and α / 2 for GGX in the limit
                // (where α is well above the first cosine, 1/4095, and Λ cos θ near linear).
                let limit = alpha
                    * if kind == NdfKind::Ggx {
                        0.5
                    } else {
                        0.5 / PI.sqrt()
                    };
                if alpha >= 0.1 {
                    assert!((table[0] as f64 - limit).abs() < 1e-3 * limit);
                }
            }
        }
        let base = crate::fitting::refine::tabulate(
            AnalyticNdf::isotropic(NdfKind::Beckmann, 0.3),
            128,
            64,
        )
        .unwrap();
        for alpha in [1.0, 0.6] {
            let stretch = crate::model::tabulated::Stretch {
                alpha_x: alpha,
                alpha_y: alpha,
                rotation: 0.0,
            };
            let t =
                crate::model::tabulated::TabulatedNdf::new(base.tables().clone(), stretch).unwrap();
            let table = lambda_cos_table(&Ndf::Tabulated(std::sync::Arc::new(t.clone())));
            for k in 1..LAMBDA_TABLE {
                let mu = k as f64 / (LAMBDA_TABLE - 1) as f64;
                let w = DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                let want = (t.lambda(w) * mu) as f32;
                assert!(
                    (table[k] - want).abs() <= 1e-6 * want,
                    "stretch {alpha} μ {mu}: {} vs {want}",
                    table[k]
                );
            }
        }
    }

    /// The B table's Hermite interpolation against B computed directly between its nodes:
    /// within 3e-10 relative (the bound in the module's docs) up to a = 6.
    #[test]
    fn beckmann_b_interpolates_to_its_bound() {
        let b = beckmann_b();
        let mut worst: f64 = 0.0;
        for k in 0..60_000 {
            let a = (k as f64 + 0.37) * B_MAX / 60_000.0;
            let want = (-a * a).exp() / (2.0 * PI.sqrt()) - 0.5 * a * libm::erfc(a);
            let got = beckmann_b_at(b, a);
            worst = worst.max((got - want).abs() / want.max(1e-300));
        }
        println!("B worst {worst:e}");
        assert!(worst < 3e-10, "worst relative error {worst}");
        assert_eq!(beckmann_b_at(b, B_MAX), 0.0);
        assert_eq!(beckmann_b_at(b, f64::INFINITY), 0.0);
    }
}
