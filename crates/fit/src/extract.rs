//! NDF extraction by power iterations (Dupuy, Heitz, Poulin, Ostromoukhov, EGSR 2015).
//!
//! In backscattering a microfacet BRDF is f(o,o) = F0 D(o) G1(o) / (4 cos²θo), and with
//! G1(o) = cos θo / ∫ <o,h>+ D(h) dω_h the NDF is the dominant eigenvector of
//! `λ D(o) = 4 f(o,o) cos θo ∫ <o,h>+ D(h) dω_h` (λ = F0). Discretised on quadrature nodes this
//! is a non-negative matrix: power iterations from a vector of ones converge to it
//! (Perron–Frobenius). We iterate on D (the paper iterates on P = D cos⁴θ: the same eigenvector
//! up to a diagonal scaling) and normalise ∫ D cos θ dω = 1 (∫ P dh~ = 1) at every step.
//! The result is interpolated by the Nyström formula (the integral equation evaluated at any θ
//! from the node values), which also gives G1 = cos θ / ∫ <o,h>+ D dω on a fine table.

use crate::brdf::{Brdf, mean};
use crate::error::FitError;
use crate::geometry::spherical;
use crate::quadrature::Quadrature;
use crate::tabulated::{NdfTables, Stretch, TabulatedNdf, phi_node, theta_node, u_node_theta};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// When the power iteration stops.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stopping {
    /// Until the L1 change of the normalised NDF (in the measure cos θ dω, so 2 is the
    /// largest possible) falls below `tolerance`, at most `max_iterations`.
    Converge {
        tolerance: f64,
        max_iterations: usize,
    },
    /// Exactly this many iterations (the paper uses 4).
    Fixed(usize),
}

/// Extraction settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExtractConfig {
    /// Polar quadrature nodes N (isotropic: the size of the N×N problem).
    pub resolution: usize,
    /// Azimuthal nodes of an anisotropic extraction (N = resolution × phi_resolution unknowns).
    pub phi_resolution: usize,
    pub quadrature: Quadrature,
    pub stopping: Stopping,
}

impl ExtractConfig {
    /// The default: 90 Gauss–Legendre nodes in sqrt θ, iterated to 1e-9.
    pub const fn isotropic() -> Self {
        ExtractConfig {
            resolution: 90,
            phi_resolution: 1,
            quadrature: Quadrature::GaussLegendreSqrt,
            stopping: Stopping::Converge {
                tolerance: 1e-9,
                max_iterations: 1000,
            },
        }
    }

    /// A 64 × 64 direction grid.
    pub const fn anisotropic() -> Self {
        ExtractConfig {
            resolution: 64,
            phi_resolution: 64,
            ..Self::isotropic()
        }
    }

    /// The paper's settings: uniform θ nodes and 4 iterations.
    pub const fn paper(resolution: usize) -> Self {
        ExtractConfig {
            resolution,
            phi_resolution: 1,
            quadrature: Quadrature::UniformTheta,
            stopping: Stopping::Fixed(4),
        }
    }
}

impl Default for ExtractConfig {
    fn default() -> Self {
        Self::isotropic()
    }
}

/// What an extraction produced.
#[derive(Clone, Debug)]
pub struct Extraction {
    pub ndf: TabulatedNdf,
    /// λ: the normal-incidence Fresnel of the backscattering slice (mean of RGB).
    pub eigenvalue: f64,
    pub iterations: usize,
    /// L1 change of the normalised NDF in the last iteration.
    pub residual: f64,
}

/// Sizes of the output tables of an isotropic extraction.
const ISO_TABLE_U: usize = 256;
const ISO_TABLE_G: usize = 512;

/// ∫₀^{2π} max(0, cos θo cos θh + sin θo sin θh cos φ) dφ, in closed form:
/// 2πa if a ≥ b, 0 if a ≤ −b, else 2(a φ₀ + b sin φ₀) with φ₀ = acos(−a/b).
pub fn azimuthal_integral(theta_o: f64, theta_h: f64) -> f64 {
    let a = theta_o.cos() * theta_h.cos();
    let b = theta_o.sin() * theta_h.sin();
    if a >= b {
        2.0 * PI * a
    } else if a <= -b {
        0.0
    } else {
        let c = -a / b;
        2.0 * (a * c.acos() + b * (1.0 - c * c).sqrt())
    }
}

fn backscatter_slice(src: &dyn Brdf, dirs: &[(f64, f64)]) -> Result<Vec<f64>, FitError> {
    let values: Vec<Option<f64>> = dirs
        .par_iter()
        .map(|&(t, p)| src.backscatter(t, p).map(mean))
        .collect();
    let fail = |problem: String| FitError::Extraction {
        name: src.name().to_owned(),
        problem,
    };
    if let Some(v) = values.iter().flatten().find(|v| !v.is_finite()) {
        return Err(fail(format!("the backscattering slice holds {v}")));
    }
    // Missing directions take the value of their nearest valid neighbour in the list.
    let filled =
        crate::merl::fill_missing(&values.iter().map(|v| v.map(|x| [x; 3])).collect::<Vec<_>>())
            .ok_or_else(|| fail("no valid backscattering sample".into()))?;
    let out: Vec<f64> = filled.iter().map(|v| v[0].max(0.0)).collect();
    if out.iter().all(|&v| v == 0.0) {
        return Err(fail("the backscattering slice is zero everywhere".into()));
    }
    Ok(out)
}

/// Power iteration `v ← normalise(K v)` with `normalise` making Σ c_j v_j = 1.
/// Returns (v, λ, iterations, residual).
fn power_iterate(
    n: usize,
    c: &[f64],
    stopping: Stopping,
    matvec: impl Fn(&[f64], &mut [f64]),
) -> (Vec<f64>, f64, usize, f64) {
    let norm = |v: &[f64]| v.iter().zip(c).map(|(v, c)| v * c).sum::<f64>();
    let mut v = vec![1.0; n];
    let s = norm(&v);
    v.iter_mut().for_each(|x| *x /= s);
    let mut next = vec![0.0; n];
    let (max_it, tol) = match stopping {
        Stopping::Converge {
            tolerance,
            max_iterations,
        } => (max_iterations, tolerance),
        Stopping::Fixed(k) => (k, -1.0),
    };
    let (mut lambda, mut residual, mut it) = (0.0, f64::INFINITY, 0);
    while it < max_it {
        matvec(&v, &mut next);
        lambda = norm(&next);
        next.iter_mut().for_each(|x| *x /= lambda);
        residual = v
            .iter()
            .zip(&next)
            .zip(c)
            .map(|((a, b), c)| (a - b).abs() * c)
            .sum();
        std::mem::swap(&mut v, &mut next);
        it += 1;
        if residual < tol {
            break;
        }
    }
    (v, lambda, it, residual)
}

/// Isotropic extraction: N polar nodes, the azimuth integrated in closed form.
pub fn extract_isotropic(src: &dyn Brdf, cfg: &ExtractConfig) -> Result<Extraction, FitError> {
    let nodes = cfg.quadrature.nodes(cfg.resolution.max(2));
    let n = nodes.len();
    let b = backscatter_slice(
        src,
        &nodes.iter().map(|&(t, _)| (t, 0.0)).collect::<Vec<_>>(),
    )?;
    // Column weights w_j sin θj; normalisation weights 2π w_j sin θj cos θj.
    let wj: Vec<f64> = nodes.iter().map(|&(t, w)| w * t.sin()).collect();
    let c: Vec<f64> = nodes
        .iter()
        .zip(&wj)
        .map(|(&(t, _), w)| 2.0 * PI * w * t.cos())
        .collect();
    // K_ij = 4 f(θi) cos θi · w_j sin θj · A(θi, θj), stored: N×N is small for a 1-D problem.
    let k: Vec<f64> = (0..n * n)
        .into_par_iter()
        .map(|ij| {
            let (i, j) = (ij / n, ij % n);
            4.0 * b[i] * nodes[i].0.cos() * wj[j] * azimuthal_integral(nodes[i].0, nodes[j].0)
        })
        .collect();
    let (v, lambda, iterations, residual) = power_iterate(n, &c, cfg.stopping, |v, out| {
        for (i, o) in out.iter_mut().enumerate() {
            *o = k[i * n..(i + 1) * n]
                .iter()
                .zip(v)
                .map(|(k, v)| k * v)
                .sum();
        }
    });
    // Nyström: I(θ) = Σ_j w_j sin θj A(θ, θj) v_j; D(θ) = 4 f(θ) cos θ I(θ) / λ; G1 = cos θ / I(θ).
    let integral = |theta: f64| -> f64 {
        (0..n)
            .map(|j| wj[j] * azimuthal_integral(theta, nodes[j].0) * v[j])
            .sum()
    };
    let d_thetas: Vec<(f64, f64)> = (0..ISO_TABLE_U)
        .map(|k| (u_node_theta(k, ISO_TABLE_U), 0.0))
        .collect();
    let bd = backscatter_slice(src, &d_thetas)?;
    let d: Vec<f64> = d_thetas
        .par_iter()
        .zip(&bd)
        .map(|(&(t, _), &f)| 4.0 * f * t.cos().max(0.0) * integral(t) / lambda)
        .collect();
    let g1: Vec<f64> = (0..ISO_TABLE_G)
        .into_par_iter()
        .map(|k| {
            let t = theta_node(k, ISO_TABLE_G);
            let i = integral(t);
            if i > 0.0 {
                (t.cos().max(0.0) / i).min(1.0)
            } else {
                0.0
            }
        })
        .collect();
    finish(
        src,
        NdfTables {
            nu: ISO_TABLE_U,
            nphi: 1,
            d,
            ng: ISO_TABLE_G,
            g1,
        },
        lambda,
        iterations,
        residual,
    )
}

/// Anisotropic extraction on a (θ, φ) grid of directions, matrix-free: each iteration computes
/// the kernel `4 f(o,o) cos θo <o,h>+ W_h` on the fly, rows in parallel.
pub fn extract_anisotropic(src: &dyn Brdf, cfg: &ExtractConfig) -> Result<Extraction, FitError> {
    let polar = cfg.quadrature.nodes(cfg.resolution.max(2));
    let nphi = cfg.phi_resolution.max(1);
    let dphi = 2.0 * PI / nphi as f64;
    // Node (i, l): θ_i, φ_l = (l + ½) Δφ, weight W = w_i sin θ_i Δφ.
    let dirs: Vec<(f64, f64)> = polar
        .iter()
        .flat_map(|&(t, _)| (0..nphi).map(move |l| (t, (l as f64 + 0.5) * dphi)))
        .collect();
    let n = dirs.len();
    let weight: Vec<f64> = polar
        .iter()
        .flat_map(|&(t, w)| std::iter::repeat_n(w * t.sin() * dphi, nphi))
        .collect();
    let xyz: Vec<[f64; 3]> = dirs
        .iter()
        .map(|&(t, p)| spherical(t, p).to_array())
        .collect();
    let b = backscatter_slice(src, &dirs)?;
    let c: Vec<f64> = weight.iter().zip(&xyz).map(|(w, d)| w * d[2]).collect();
    // Σ_h W_h <o,h>+ v_h for one direction o, the inner loop of the kernel–vector product.
    let project = |o: [f64; 3], wv: &[f64]| -> f64 {
        xyz.iter()
            .zip(wv)
            .map(|(h, wv)| (o[0] * h[0] + o[1] * h[1] + o[2] * h[2]).max(0.0) * wv)
            .sum::<f64>()
    };
    let (v, lambda, iterations, residual) = power_iterate(n, &c, cfg.stopping, |v, out| {
        let wv: Vec<f64> = v.iter().zip(&weight).map(|(v, w)| v * w).collect();
        out.par_iter_mut()
            .enumerate()
            .for_each(|(a, o)| *o = 4.0 * b[a] * xyz[a][2] * project(xyz[a], &wv));
    });
    let wv: Vec<f64> = v.iter().zip(&weight).map(|(v, w)| v * w).collect();
    let nu = 2 * cfg.resolution.max(2) + 1;
    let d_dirs: Vec<(f64, f64)> = (0..nu)
        .flat_map(|k| (0..nphi).map(move |l| (u_node_theta(k, nu), phi_node(l, nphi))))
        .collect();
    let bd = backscatter_slice(src, &d_dirs)?;
    let d: Vec<f64> = d_dirs
        .par_iter()
        .zip(&bd)
        .map(|(&(t, p), &f)| {
            4.0 * f * t.cos().max(0.0) * project(spherical(t, p).to_array(), &wv) / lambda
        })
        .collect();
    let ng = nu;
    let g1: Vec<f64> = (0..ng * nphi)
        .into_par_iter()
        .map(|kl| {
            let (t, p) = (theta_node(kl / nphi, ng), phi_node(kl % nphi, nphi));
            let i = project(spherical(t, p).to_array(), &wv);
            if i > 0.0 {
                (t.cos().max(0.0) / i).min(1.0)
            } else {
                0.0
            }
        })
        .collect();
    finish(
        src,
        NdfTables {
            nu,
            nphi,
            d,
            ng,
            g1,
        },
        lambda,
        iterations,
        residual,
    )
}

fn finish(
    src: &dyn Brdf,
    tables: NdfTables,
    eigenvalue: f64,
    iterations: usize,
    residual: f64,
) -> Result<Extraction, FitError> {
    let ndf =
        TabulatedNdf::new(tables, Stretch::IDENTITY).map_err(|problem| FitError::Extraction {
            name: src.name().to_owned(),
            problem,
        })?;
    Ok(Extraction {
        ndf,
        eigenvalue,
        iterations,
        residual,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuthal_integral_matches_quadrature() {
        for &(to, th) in &[(0.0, 0.5), (0.3, 0.2), (1.2, 0.9), (1.5, 1.4), (0.7, 1.5)] {
            let n = 200_000;
            let q: f64 = (0..n)
                .map(|k| {
                    let p = (k as f64 + 0.5) / n as f64 * 2.0 * PI;
                    (f64::cos(to) * f64::cos(th) + f64::sin(to) * f64::sin(th) * p.cos()).max(0.0)
                })
                .sum::<f64>()
                * 2.0
                * PI
                / n as f64;
            assert!((azimuthal_integral(to, th) - q).abs() < 1e-8, "{to} {th}");
        }
    }
}
