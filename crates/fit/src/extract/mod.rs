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

use crate::error::FitError;
use crate::model::brdf::Brdf;
use crate::model::geometry::{acos_poly, spherical};
use crate::model::rgb::mean;
use crate::model::tabulated::{
    NdfTables, Stretch, TabulatedNdf, phi_node, theta_node, u_node_theta,
};
use crate::numerics::quadrature::Quadrature;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

/// When the power iteration stops.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stopping {
    /// Until the L1 change of the normalised NDF (in the measure cos θ dω, so 2 is the
    /// largest possible) falls below `tolerance`, at most `max_iterations`.
    Converge {
        /// Stop when the L1 change falls below this.
        tolerance: f64,
        /// Stop after this many iterations in any case.
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
    /// How the polar nodes are placed and weighted.
    pub quadrature: Quadrature,
    /// When the power iteration stops.
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
    /// The extracted NDF with its G1 table.
    pub ndf: TabulatedNdf,
    /// λ: the normal-incidence Fresnel of the backscattering slice (mean of RGB).
    pub eigenvalue: f64,
    /// Power iterations run.
    pub iterations: usize,
    /// L1 change of the normalised NDF in the last iteration.
    pub residual: f64,
}

/// Sizes of the output tables of an isotropic extraction.
const ISO_TABLE_U: usize = 256;
const ISO_TABLE_G: usize = 512;

/// ∫₀^{2π} max(0, cos θo cos θh + sin θo sin θh cos φ) dφ, in closed form:
/// 2πa if a ≥ b, 0 if a ≤ −b, else 2(a φ₀ + b sin φ₀) with φ₀ = acos(−a/b) (by a polynomial,
/// to 2e-8 in φ₀).
pub fn azimuthal_integral(theta_o: f64, theta_h: f64) -> f64 {
    azimuthal_ab(theta_o.cos() * theta_h.cos(), theta_o.sin() * theta_h.sin())
}

/// ∫₀^{2π} max(0, a + b cos φ) dφ for b ≥ 0 ([`azimuthal_integral`] is a = cos θo cos θh,
/// b = sin θo sin θh).
#[inline]
pub(crate) fn azimuthal_ab(a: f64, b: f64) -> f64 {
    if a >= b {
        2.0 * PI * a
    } else if a <= -b {
        0.0
    } else {
        let c = -a / b;
        2.0 * (a * acos_poly(c) + b * (1.0 - c * c).sqrt())
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
    // f(o, o) grows as 1/cos²θo towards grazing: only non-finite values are refused here.
    if let Some(v) = values.iter().flatten().find(|v| !v.is_finite()) {
        return Err(fail(format!("the backscattering slice holds {v}")));
    }
    // Missing directions take the value of their nearest valid neighbour in the list.
    let filled = crate::numerics::interp::fill_missing(
        &values.iter().map(|v| v.map(|x| [x; 3])).collect::<Vec<_>>(),
    )
    .ok_or_else(|| fail("no valid backscattering sample".into()))?;
    let out: Vec<f64> = filled.iter().map(|v| v[0].max(0.0)).collect();
    if out.iter().all(|&v| v == 0.0) {
        return Err(fail("the backscattering slice is zero everywhere".into()));
    }
    Ok(out)
}

/// The discretised eigenproblem: nodes (directions), row scales 4 f(o,o) cos θo, column
/// weights, normalisation weights, and the kernel shape.
pub struct Problem {
    /// Isotropic: the azimuth of `<o,h>+` integrated in closed form, nodes at φ = 0.
    pub isotropic: bool,
    /// The unit direction of each node.
    pub dirs: Vec<[f64; 3]>,
    /// 4 f(o,o) cos θo of each node (the mean of RGB).
    pub row: Vec<f64>,
    /// Quadrature weight of each node: w sin θ (isotropic), w sin θ Δφ (anisotropic).
    pub col: Vec<f64>,
    /// c with Σ c_j D_j = ∫ D cos θ dω.
    pub norm: Vec<f64>,
}

impl Problem {
    /// k(q, h): ∫ <q,h>+ dφ over the azimuth of h (isotropic) or <q,h>+.
    #[inline]
    pub fn kernel(&self, q: &[f64; 3], h: &[f64; 3]) -> f64 {
        if self.isotropic {
            azimuthal(q, h)
        } else {
            (q[0] * h[0] + q[1] * h[1] + q[2] * h[2]).max(0.0)
        }
    }
}

/// [`azimuthal_integral`] from directions at φ = 0 (θ from their z and length in xy).
#[inline]
fn azimuthal(q: &[f64; 3], h: &[f64; 3]) -> f64 {
    azimuthal_ab(q[2] * h[2], q[0].hypot(q[1]) * h[0].hypot(h[1]))
}

/// Result of the power iteration.
pub struct Eigen {
    /// The normalised eigenvector (D at the nodes).
    pub v: Vec<f64>,
    /// The eigenvalue λ.
    pub lambda: f64,
    /// Iterations run.
    pub iterations: usize,
    /// L1 change of the normalised vector in the last iteration.
    pub residual: f64,
}

/// What runs the iteration and the table integrals: the CPU here, the GPU in `crate::gpu`.
pub trait Solver {
    /// Power iterations `v ← K v / λ` from ones, λ making Σ c v = 1.
    fn iterate(&self, p: &Problem, stopping: Stopping) -> Result<Eigen, FitError>;
    /// I(q) = Σ_j col_j k(q, h_j) v_j for each query direction.
    fn integrals(&self, p: &Problem, v: &[f64], queries: &[[f64; 3]])
    -> Result<Vec<f64>, FitError>;
    /// Name recorded as the fit's backend.
    fn name(&self) -> String;
}

/// The f64 reference, parallel with rayon. Isotropic: the N×N kernel is small and stored;
/// anisotropic: matrix-free, each row's kernel computed on the fly.
pub struct CpuSolver;

/// The isotropic kernel k(q, h) between query directions and a problem's nodes, `n` nodes per
/// query: the last ones computed are kept, for the next problem on the same nodes. A diffuse
/// separation extracts a dozen times on the same nodes, and the kernel, which depends on the
/// directions alone, was most of each extraction's work.
fn isotropic_kernel(queries: &[[f64; 3]], nodes: &[[f64; 3]]) -> Arc<Vec<f64>> {
    type Kept = Vec<(Vec<[f64; 3]>, Vec<[f64; 3]>, Arc<Vec<f64>>)>;
    /// The node × node kernel of the iteration and the query × node one of the tables.
    const KEEP: usize = 2;
    static KEPT: Mutex<Kept> = Mutex::new(Vec::new());
    let found = KEPT.lock().ok().and_then(|kept| {
        let hit = kept.iter().find(|(q, h, _)| q == queries && h == nodes);
        hit.map(|(_, _, k)| k.clone())
    });
    if let Some(k) = found {
        return k;
    }
    // The nodes' sin θ once, not once per query.
    let sin: Vec<f64> = nodes.iter().map(|h| h[0].hypot(h[1])).collect();
    let k: Vec<f64> = queries
        .par_iter()
        .flat_map_iter(|q| {
            let sin_q = q[0].hypot(q[1]);
            nodes
                .iter()
                .zip(&sin)
                .map(move |(h, s)| azimuthal_ab(q[2] * h[2], sin_q * s))
        })
        .collect();
    let k = Arc::new(k);
    if let Ok(mut kept) = KEPT.lock() {
        if kept.len() == KEEP {
            kept.remove(0);
        }
        kept.push((queries.to_vec(), nodes.to_vec(), k.clone()));
    }
    k
}

impl Solver for CpuSolver {
    fn iterate(&self, p: &Problem, stopping: Stopping) -> Result<Eigen, FitError> {
        let n = p.dirs.len();
        let dense: Option<Vec<f64>> = p.isotropic.then(|| {
            let k = isotropic_kernel(&p.dirs, &p.dirs);
            (0..n * n)
                .into_par_iter()
                .map(|ij| p.row[ij / n] * p.col[ij % n] * k[ij])
                .collect()
        });
        Ok(power_iterate(n, &p.norm, stopping, |v, out| match &dense {
            Some(k) => out.par_iter_mut().enumerate().for_each(|(i, o)| {
                *o = k[i * n..(i + 1) * n]
                    .iter()
                    .zip(v)
                    .map(|(k, v)| k * v)
                    .sum()
            }),
            None => {
                let wv: Vec<f64> = v.iter().zip(&p.col).map(|(v, w)| v * w).collect();
                out.par_iter_mut()
                    .enumerate()
                    .for_each(|(a, o)| *o = p.row[a] * project(p, &p.dirs[a], &wv));
            }
        }))
    }

    fn integrals(
        &self,
        p: &Problem,
        v: &[f64],
        queries: &[[f64; 3]],
    ) -> Result<Vec<f64>, FitError> {
        let wv: Vec<f64> = v.iter().zip(&p.col).map(|(v, w)| v * w).collect();
        if p.isotropic {
            let (k, n) = (isotropic_kernel(queries, &p.dirs), p.dirs.len());
            return Ok(k
                .par_chunks(n)
                .map(|k| k.iter().zip(&wv).map(|(k, wv)| k * wv).sum())
                .collect());
        }
        Ok(queries.par_iter().map(|q| project(p, q, &wv)).collect())
    }

    fn name(&self) -> String {
        "cpu".into()
    }
}

/// Σ_h wv_h k(q, h).
fn project(p: &Problem, q: &[f64; 3], wv: &[f64]) -> f64 {
    if p.isotropic {
        p.dirs
            .iter()
            .zip(wv)
            .map(|(h, wv)| azimuthal(q, h) * wv)
            .sum()
    } else {
        p.dirs
            .iter()
            .zip(wv)
            .map(|(h, wv)| (q[0] * h[0] + q[1] * h[1] + q[2] * h[2]).max(0.0) * wv)
            .sum()
    }
}

/// Power iteration `v ← normalise(K v)` with `normalise` making Σ c_j v_j = 1.
fn power_iterate(
    n: usize,
    c: &[f64],
    stopping: Stopping,
    matvec: impl Fn(&[f64], &mut [f64]),
) -> Eigen {
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
    Eigen {
        v,
        lambda,
        iterations: it,
        residual,
    }
}

/// Isotropic extraction on the CPU.
pub fn extract_isotropic(src: &dyn Brdf, cfg: &ExtractConfig) -> Result<Extraction, FitError> {
    extract_with(src, cfg, false, &CpuSolver)
}

/// Anisotropic extraction on the CPU.
pub fn extract_anisotropic(src: &dyn Brdf, cfg: &ExtractConfig) -> Result<Extraction, FitError> {
    extract_with(src, cfg, true, &CpuSolver)
}

/// The discretised problem of a source: isotropic (N polar nodes, the azimuth integrated in
/// closed form) or anisotropic (a (θ, φ) grid of directions); rows 4 f(o,o) cos θo, weights.
pub fn build_problem(
    src: &dyn Brdf,
    cfg: &ExtractConfig,
    anisotropic: bool,
) -> Result<Problem, FitError> {
    let polar = cfg.quadrature.nodes(cfg.resolution.max(2));
    let nphi = if anisotropic {
        cfg.phi_resolution.max(1)
    } else {
        1
    };
    let dphi = 2.0 * PI / nphi as f64;
    // Node (i, l): θ_i, φ_l = (l + ½) Δφ (isotropic: φ = 0 and the azimuth integrated).
    let angles: Vec<(f64, f64)> = polar
        .iter()
        .flat_map(|&(t, _)| {
            (0..nphi).map(move |l| {
                (
                    t,
                    if anisotropic {
                        (l as f64 + 0.5) * dphi
                    } else {
                        0.0
                    },
                )
            })
        })
        .collect();
    let b = backscatter_slice(src, &angles)?;
    let dirs: Vec<[f64; 3]> = angles
        .iter()
        .map(|&(t, p)| spherical(t, p).to_array())
        .collect();
    // Column weights w sin θ (Δφ when anisotropic); c = w sin θ cos θ (· 2π when isotropic).
    let col: Vec<f64> = polar
        .iter()
        .flat_map(|&(t, w)| {
            std::iter::repeat_n(w * t.sin() * if anisotropic { dphi } else { 1.0 }, nphi)
        })
        .collect();
    let norm: Vec<f64> = col
        .iter()
        .zip(&dirs)
        .map(|(w, d)| w * d[2] * if anisotropic { 1.0 } else { 2.0 * PI })
        .collect();
    let row: Vec<f64> = b.iter().zip(&dirs).map(|(b, d)| 4.0 * b * d[2]).collect();
    Ok(Problem {
        isotropic: !anisotropic,
        dirs,
        row,
        col,
        norm,
    })
}

/// Extraction with any solver: the power iteration, then the D and G1 tables by Nyström.
pub fn extract_with(
    src: &dyn Brdf,
    cfg: &ExtractConfig,
    anisotropic: bool,
    solver: &dyn Solver,
) -> Result<Extraction, FitError> {
    let nphi = if anisotropic {
        cfg.phi_resolution.max(1)
    } else {
        1
    };
    let problem = build_problem(src, cfg, anisotropic)?;
    let eigen = solver.iterate(&problem, cfg.stopping)?;
    if !(eigen.lambda > 0.0 && eigen.lambda.is_finite()) || eigen.v.iter().any(|x| !x.is_finite()) {
        return Err(FitError::Extraction {
            name: src.name().to_owned(),
            problem: format!("the power iteration diverged (λ = {})", eigen.lambda),
        });
    }
    // Nyström: I(q) = Σ_j col_j k(q, h_j) v_j; D(q) = 4 f(q) cos θ I(q) / λ; G1 = cos θ / I(q).
    let (nu, ng) = if anisotropic {
        let n = 2 * cfg.resolution.max(2) + 1;
        (n, n)
    } else {
        (ISO_TABLE_U, ISO_TABLE_G)
    };
    let d_angles: Vec<(f64, f64)> = (0..nu)
        .flat_map(|k| (0..nphi).map(move |l| (u_node_theta(k, nu), phi_node(l, nphi))))
        .collect();
    let g_angles: Vec<(f64, f64)> = (0..ng)
        .flat_map(|k| (0..nphi).map(move |l| (theta_node(k, ng), phi_node(l, nphi))))
        .collect();
    let queries: Vec<[f64; 3]> = d_angles
        .iter()
        .chain(&g_angles)
        .map(|&(t, p)| spherical(t, p).to_array())
        .collect();
    let integrals = solver.integrals(&problem, &eigen.v, &queries)?;
    let (i_d, i_g) = integrals.split_at(d_angles.len());
    let bd = backscatter_slice(src, &d_angles)?;
    let d: Vec<f64> = d_angles
        .iter()
        .zip(&bd)
        .zip(i_d)
        .map(|((&(t, _), &f), &i)| (4.0 * f * t.cos().max(0.0) * i / eigen.lambda).max(0.0))
        .collect();
    let g1: Vec<f64> = g_angles
        .iter()
        .zip(i_g)
        .map(|(&(t, _), &i)| {
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
        eigen.lambda,
        eigen.iterations,
        eigen.residual,
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

    /// The kept kernels are the kernel: each entry is k(q, h) of its query and node, bit for
    /// bit, whichever sets of directions were asked for before (three sets here, one more than
    /// are kept, asked for twice in turn).
    #[test]
    fn kept_kernels_are_the_kernel() {
        let dirs = |n: usize, phi: f64| -> Vec<[f64; 3]> {
            (0..n)
                .map(|k| spherical(1.5 * k as f64 / n as f64, phi).to_array())
                .collect()
        };
        let sets = [dirs(7, 0.0), dirs(5, 0.3), dirs(9, 0.0)];
        for _ in 0..2 {
            for q in &sets {
                let k = isotropic_kernel(q, &sets[0]);
                for (m, q) in q.iter().enumerate() {
                    for (j, h) in sets[0].iter().enumerate() {
                        assert_eq!(
                            k[m * sets[0].len() + j].to_bits(),
                            azimuthal(q, h).to_bits()
                        );
                    }
                }
            }
        }
    }

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
