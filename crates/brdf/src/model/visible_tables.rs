//! Visible-normal sampling of a tabulated NDF (the measured-NDF case of Dupuy & Jakob 2018).
//!
//! The visible distribution D_v(h) ∝ max(0, v·h) D₀(h) of the base (unstretched) table depends
//! on the view v; it is tabulated on view slices — θv on [`N_THETA_V`] nodes evenly over
//! [0, π/2], and when the table is anisotropic φv on [`N_PHI_V`] nodes — each slice a piecewise-
//! constant density over cells: rows uniform in u = √(θh / (π/2)), columns uniform in φh
//! (relative to φv when isotropic, absolute otherwise). A cell's mass is the projected-area
//! integral ∫ max(0, v·h) D₀(h) dω (midpoint rule, 3 × 3 points). A query between nodes picks
//! a neighbouring slice with its interpolation weight, so the density of a sample is the same
//! mixture of the slices' cell densities: exact, whatever the slices' resolution.
//!
//! Stretch and rotation act outside: [`crate::model::tabulated::TabulatedNdf`] maps v to the base view
//! w₀ ∝ (αx vx, αy vy, vz) and the sampled h₀ back (Heitz 2018, stretch invariance).

use crate::model::geometry::{phi_of, spherical, theta_of, theta_to_u};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// θv nodes of the view slices, evenly over [0, π/2] inclusive.
pub const N_THETA_V: usize = 16;
/// φv nodes of an anisotropic table's view slices, evenly over [0, 2π).
pub const N_PHI_V: usize = 16;
/// Azimuth columns of every slice.
pub const COLUMNS: usize = 32;
/// Rows of an anisotropic table's slices (an isotropic one uses its own nu − 1 rows).
pub const ANISO_ROWS: usize = 32;
/// Midpoint-rule points per cell side for the cell masses.
const QUAD: usize = 3;

/// The sampling tables of the visible distribution of a base NDF table.
#[derive(Clone, Debug)]
pub struct VisibleTables {
    /// View slices in θv.
    pub n_theta_v: usize,
    /// View slices in φv (1 when isotropic: columns are then relative to φv).
    pub n_phi_v: usize,
    /// Rows of a slice's cells, uniform in u = √(θh / (π/2)).
    pub rows: usize,
    /// Columns of a slice's cells, uniform in φh.
    pub columns: usize,
    /// Per slice (index j · n_phi_v + p), per cell (index r · columns + c): cumulative mass
    /// normalised to 1 at the slice's end.
    pub cdf: Vec<f64>,
    /// Per slice and cell: mass / (slice total · the cell's solid angle), the density inside it.
    pub cell_pdf: Vec<f64>,
}

/// A slice node and its mixture weight.
type Pick = (usize, f64);

/// The view slices around a view: two θv nodes and two φv nodes with their weights, and the
/// azimuth the slices' columns start from (φv when isotropic, else 0).
struct Slices {
    theta: (Pick, Pick),
    phi: (Pick, Pick),
    phi_ref: f64,
}

impl VisibleTables {
    /// Tabulates the visible distribution of `d0` (D₀(θ, φ) of the base table); `isotropic` when
    /// D₀ ignores φ, `rows` the u rows of a slice.
    pub fn new(d0: impl Fn(f64, f64) -> f64 + Sync, isotropic: bool, rows: usize) -> Self {
        let n_phi_v = if isotropic { 1 } else { N_PHI_V };
        let (n_theta_v, columns) = (N_THETA_V, COLUMNS);
        let cells = rows * columns;
        let per_slice: Vec<(Vec<f64>, Vec<f64>)> = (0..n_theta_v * n_phi_v)
            .into_par_iter()
            .map(|s| {
                let (j, p) = (s / n_phi_v, s % n_phi_v);
                let phi_v = if isotropic { 0.0 } else { phi_v_node(p) };
                let v = spherical(theta_v_node(j), phi_v);
                let mut mass = Vec::with_capacity(cells);
                for r in 0..rows {
                    let (ca, cb) = row_cos(r, rows);
                    for c in 0..columns {
                        let mut m = 0.0;
                        for a in 0..QUAD {
                            let cos_t = ca + (a as f64 + 0.5) / QUAD as f64 * (cb - ca);
                            let theta = cos_t.clamp(-1.0, 1.0).acos();
                            for b in 0..QUAD {
                                let phi = (c as f64 + (b as f64 + 0.5) / QUAD as f64)
                                    * column_width(columns);
                                let h = spherical(theta, phi);
                                // Isotropic: D₀ ignores φ, relative to φv = 0 here.
                                m += v.dot(h).max(0.0) * d0(theta, phi);
                            }
                        }
                        let omega = cell_solid_angle(r, rows, columns);
                        mass.push(m / (QUAD * QUAD) as f64 * omega);
                    }
                }
                normalise(&mass, rows, columns)
            })
            .collect();
        let (mut cdf, mut cell_pdf) = (Vec::new(), Vec::new());
        for (c, p) in per_slice {
            cdf.extend(c);
            cell_pdf.extend(p);
        }
        VisibleTables {
            n_theta_v,
            n_phi_v,
            rows,
            columns,
            cdf,
            cell_pdf,
        }
    }

    /// Samples h₀ visible from the base view `v` (unit, v.z ≥ 0) from two uniform numbers.
    pub fn sample(&self, v: DVec3, u: [f64; 2]) -> DVec3 {
        let q = self.slices(v);
        let (s, u0) = choose(q.theta, u[0]);
        let (p, u1) = choose(q.phi, u[1]);
        let slice = s * self.n_phi_v + p;
        let cells = self.rows * self.columns;
        let cdf = &self.cdf[slice * cells..(slice + 1) * cells];
        let c = cdf.partition_point(|&x| x <= u0).min(cells - 1);
        let lo = if c == 0 { 0.0 } else { cdf[c - 1] };
        let rest = ((u0 - lo) / (cdf[c] - lo)).clamp(0.0, 1.0); // reuse the remainder of u0
        let (r, col) = (c / self.columns, c % self.columns);
        let (ca, cb) = row_cos(r, self.rows);
        let cos_t = (ca + rest * (cb - ca)).clamp(-1.0, 1.0);
        let phi = q.phi_ref + (col as f64 + u1) * column_width(self.columns);
        spherical(cos_t.acos(), phi)
    }

    /// The density over solid angle of [`Self::sample`] at h₀ for the base view `v`.
    pub fn pdf(&self, v: DVec3, h: DVec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        let q = self.slices(v);
        let r = ((theta_to_u(theta_of(h)) * self.rows as f64) as usize).min(self.rows - 1);
        let dphi = (phi_of(h) - q.phi_ref).rem_euclid(2.0 * PI);
        let col = ((dphi / column_width(self.columns)) as usize).min(self.columns - 1);
        let cell = r * self.columns + col;
        let cells = self.rows * self.columns;
        let mut pdf = 0.0;
        for (s, ws) in [q.theta.0, q.theta.1] {
            for (p, wp) in [q.phi.0, q.phi.1] {
                let w = ws * wp;
                if w > 0.0 {
                    pdf += w * self.cell_pdf[(s * self.n_phi_v + p) * cells + cell];
                }
            }
        }
        pdf
    }

    /// The slices around `v` in θv and φv with their weights.
    fn slices(&self, v: DVec3) -> Slices {
        let x = (theta_of(v) / FRAC_PI_2).clamp(0.0, 1.0) * (self.n_theta_v - 1) as f64;
        let j = (x as usize).min(self.n_theta_v - 2);
        let t = x - j as f64;
        let theta = ((j, 1.0 - t), (j + 1, t));
        if self.n_phi_v == 1 {
            let phi = ((0, 1.0), (0, 0.0));
            return Slices {
                theta,
                phi,
                phi_ref: phi_of(v),
            };
        }
        let y = phi_of(v) / (2.0 * PI) * self.n_phi_v as f64;
        let p = (y as usize).min(self.n_phi_v - 1);
        let s = y - p as f64;
        Slices {
            theta,
            phi: ((p, 1.0 - s), ((p + 1) % self.n_phi_v, s)),
            phi_ref: 0.0,
        }
    }
}

/// Picks the first of two weighted slices with its weight's probability, and returns the
/// uniform number rescaled to [0, 1) for the next choice.
fn choose(picks: (Pick, Pick), u: f64) -> (usize, f64) {
    let ((a, wa), (b, _)) = picks;
    if u < wa {
        (a, (u / wa).min(1.0))
    } else {
        (b, ((u - wa) / (1.0 - wa)).clamp(0.0, 1.0))
    }
}

fn normalise(mass: &[f64], rows: usize, columns: usize) -> (Vec<f64>, Vec<f64>) {
    let total: f64 = mass.iter().sum();
    // A slice that sees no mass (not for a valid table) samples uniformly in solid angle.
    let uniform = !(total > 0.0);
    let mut acc = 0.0;
    let mut cdf = Vec::with_capacity(mass.len());
    let mut pdf = Vec::with_capacity(mass.len());
    for (i, m) in mass.iter().enumerate() {
        let omega = cell_solid_angle(i / columns, rows, columns);
        let m = if uniform {
            omega / (2.0 * PI)
        } else {
            m / total
        };
        acc += m;
        cdf.push(acc);
        pdf.push(m / omega);
    }
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    (cdf, pdf)
}

/// θv of slice node j.
pub fn theta_v_node(j: usize) -> f64 {
    j as f64 / (N_THETA_V - 1) as f64 * FRAC_PI_2
}

/// φv of slice node p.
pub fn phi_v_node(p: usize) -> f64 {
    p as f64 / N_PHI_V as f64 * 2.0 * PI
}

fn column_width(columns: usize) -> f64 {
    2.0 * PI / columns as f64
}

/// cos θ at the top and bottom of row r: rows uniform in u, θ = u² π/2.
fn row_cos(r: usize, rows: usize) -> (f64, f64) {
    let theta = |k: usize| {
        let u = k as f64 / rows as f64;
        u * u * FRAC_PI_2
    };
    (theta(r).cos(), theta(r + 1).cos())
}

fn cell_solid_angle(r: usize, rows: usize, columns: usize) -> f64 {
    let (ca, cb) = row_cos(r, rows);
    (ca - cb) * column_width(columns)
}
