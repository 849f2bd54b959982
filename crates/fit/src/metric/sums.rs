//! The weighted normal equations of the diffuse lobe's linear unknowns, F per θd bin and
//! q = ρd/π, summed over the grid by the metric's passes and solved here.
//!
//! With x_ideal = D G2 / (4 cos θo) and μ = cos θi, the model is x = F_j x_ideal + q μ on the
//! samples of θd bin j (x = f cos θi). F and q minimise Σ w (x_data − F_j x_ideal − q μ)²,
//! w = 1 / (1 + x_data)²: the squared difference of ln(1 + x) to first order, the metric's own
//! space. The normal equations form an arrowhead (one row per F_j, all coupled through q);
//! eliminating the F_j gives q in closed form. F is then clipped to [0, 1] and q to [0, 1/π],
//! and the two blocks are solved in turn until they agree: block coordinate descent on a
//! convex quadratic with box constraints, which converges to its constrained minimum.

use crate::model::merl_grid::THETA_D_RES;
use crate::model::rgb::Rgb;
use crate::numerics::interp::fill_missing;
use std::f64::consts::FRAC_1_PI;

/// The weighted normal equations of F (per θd bin) and q = ρd/π for one model, per channel.
#[derive(Clone, Debug)]
pub(crate) struct LinearSums {
    /// Per θd bin and channel: [Σ w m², Σ w m μ, Σ w m x], m = x_ideal, μ = cos θi.
    pub bins: Vec<[[f64; 3]; 3]>,
    /// Per channel: [Σ w μ², Σ w μ x] over every sample.
    pub diffuse: [[f64; 2]; 3],
    /// The error sum of the model the weights came from (IRLS passes only).
    pub error: f64,
}

impl LinearSums {
    /// No samples yet.
    pub fn zero() -> Self {
        LinearSums {
            bins: vec![[[0.0; 3]; 3]; THETA_D_RES],
            diffuse: [[0.0; 2]; 3],
            error: 0.0,
        }
    }

    /// Adds another set's sums.
    pub fn add(&mut self, other: &LinearSums) {
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            (0..3).for_each(|c| (0..3).for_each(|n| a[c][n] += b[c][n]));
        }
        (0..3).for_each(|c| (0..2).for_each(|n| self.diffuse[c][n] += other.diffuse[c][n]));
        self.error += other.error;
    }

    /// F per θd bin in [0, 1] (bins without specular samples interpolated) and q = ρd/π in
    /// [0, 1/π], minimising the weighted squares.
    pub fn solve(&self) -> (Vec<Rgb>, Rgb) {
        const ROUNDS: usize = 64;
        let mut fresnel: Vec<Option<Rgb>> = self
            .bins
            .iter()
            .map(|b| (b.iter().all(|c| c[0] > 0.0)).then_some([0.0; 3]))
            .collect();
        let mut q = [0.0; 3];
        for c in 0..3 {
            let [e, h] = self.diffuse[c];
            let bins = || self.bins.iter().map(move |b| b[c]).filter(|b| b[0] > 0.0);
            // Unconstrained: F_j = (C_j − B_j q) / A_j, so q (E − Σ B²/A) = H − Σ B C / A.
            let num = h - bins().map(|[a, b, cc]| b * cc / a).sum::<f64>();
            let den = e - bins().map(|[a, b, _]| b * b / a).sum::<f64>();
            let mut qc = if den > 0.0 { num / den } else { 0.0 };
            qc = qc.clamp(0.0, FRAC_1_PI);
            for _ in 0..ROUNDS {
                // F given q (clipped), then q given F (clipped).
                let fb = bins().map(|[a, b, cc]| b * ((cc - b * qc) / a).clamp(0.0, 1.0));
                let next = if e > 0.0 {
                    ((h - fb.sum::<f64>()) / e).clamp(0.0, FRAC_1_PI)
                } else {
                    0.0
                };
                let done = (next - qc).abs() <= 1e-12 * qc.max(1e-6);
                qc = next;
                if done {
                    break;
                }
            }
            q[c] = qc;
            for (f, b) in fresnel.iter_mut().zip(&self.bins) {
                if let Some(f) = f {
                    let [a, b, cc] = b[c];
                    f[c] = ((cc - b * qc) / a).clamp(0.0, 1.0);
                }
            }
        }
        let fresnel = fill_missing(&fresnel).unwrap_or_else(|| vec![[0.0; 3]; THETA_D_RES]);
        (fresnel, q)
    }
}
