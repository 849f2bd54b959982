//! The error metric's pass: Σ over samples and channels of
//! |ln(1 + x_model/ε) − ln(1 + x_data/ε)| (ε = 1/`scale` of the set, [`crate::metric::Metric`]),
//! for a model or for one model with several F tables.

use super::ideal::formed_ideal;
use super::lanes::{lanes_total, valid_chunks};
use super::rows::RowPass;
use super::{IsoData, IsoSamples, RowIdeals};
use crate::metric::fast_log::ln_1p_fused;
use crate::metric::iso_tables::IsoTables;
use crate::model::merl_grid::THETA_D_RES;
use crate::model::rgb::Rgb;

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
    /// Σ over samples of Σ_c |ln(1 + x_model) − ln(1 + x_data)|, x_model = F D G2 / (4 cos θo)
    /// + ρd/π cos θi.
    pub fn log_error_sum(&self, tables: &IsoTables) -> f64 {
        self.run(&ErrorSum {
            set: self,
            tables,
            cached: None,
        })
    }

    /// The error sums of a model's D, G and ρd/π with each of `fresnels` (F per θd bin) in
    /// place of its own F: one pass, each row's G2 / (4 cos θo) formed once for all of them.
    /// One sum per table, zero on a set without rows.
    pub fn log_error_sums(&self, tables: &IsoTables, fresnels: &[[Rgb; THETA_D_RES]]) -> Vec<f64> {
        let mut sums = self.run(&ErrorSums {
            set: self,
            tables,
            fresnels,
        });
        sums.resize(fresnels.len(), 0.0);
        sums
    }
}

/// Σ of the error over samples and channels.
pub(super) struct ErrorSum<'a, const N: usize, const M: usize, const P: usize> {
    pub(super) set: &'a IsoSamples<N, M, P>,
    pub(super) tables: &'a IsoTables,
    /// G2 / (4 cos θo) of the set's rows already formed.
    pub(super) cached: Option<&'a RowIdeals<P>>,
}

impl<const N: usize, const M: usize, const P: usize> RowPass for ErrorSum<'_, N, M, P> {
    type Acc = f64;

    fn init() -> f64 {
        0.0
    }

    #[inline(always)]
    fn row(&self, acc: &mut f64, r: usize, p: usize) {
        let (t, data) = (self.tables, &self.set.data);
        let (i, j) = (r / THETA_D_RES, r % THETA_D_RES);
        // F D and ρd/π in the metric's space (x/ε)
        let s = data.scale;
        let f = t.fresnel[j].map(|f| f as f32 * t.d32[i] * s);
        let kd = t.diffuse.map(|k| k as f32 * s);
        *acc += match self.cached {
            Some(c) => row_error(data, r, f, kd, c.row(p)),
            None => row_error(data, r, f, kd, &formed_ideal::<N, M, P>(t, r)),
        };
    }

    fn merge(a: &mut f64, b: f64) {
        *a += b;
    }
}

/// Σ of the error over samples and channels for each of several F tables.
struct ErrorSums<'a, const N: usize, const M: usize, const P: usize> {
    set: &'a IsoSamples<N, M, P>,
    tables: &'a IsoTables,
    fresnels: &'a [[Rgb; THETA_D_RES]],
}

impl<const N: usize, const M: usize, const P: usize> RowPass for ErrorSums<'_, N, M, P> {
    type Acc = Vec<f64>;

    fn init() -> Vec<f64> {
        Vec::new()
    }

    #[inline(always)]
    fn row(&self, acc: &mut Vec<f64>, r: usize, _: usize) {
        let t = self.tables;
        let (i, j) = (r / THETA_D_RES, r % THETA_D_RES);
        let ideal = formed_ideal::<N, M, P>(t, r);
        acc.resize(self.fresnels.len(), 0.0);
        let s = self.set.data.scale;
        let kd = t.diffuse.map(|k| k as f32 * s);
        for (a, fresnel) in acc.iter_mut().zip(self.fresnels) {
            let f = fresnel[j].map(|f| f as f32 * t.d32[i] * s);
            *a += row_error(&self.set.data, r, f, kd, &ideal);
        }
    }

    fn merge(a: &mut Vec<f64>, b: Vec<f64>) {
        if a.len() < b.len() {
            a.resize(b.len(), 0.0);
        }
        a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
    }
}

/// Σ over a row's valid bins and channels of |ln(1 + x_model/ε) − ln(1 + x_data/ε)|, with
/// x_model/ε = fd_c (G2 / (4 cos θo)) + kd_c cos θi: `fd` is F D / ε of the row, `kd` ρd/(π ε).
#[inline(always)]
fn row_error<const N: usize, const M: usize, const P: usize>(
    data: &IsoData<N, M, P>,
    r: usize,
    fd: [f32; 3],
    kd: [f32; 3],
    ideal: &[f32; P],
) -> f64 {
    let valid = data.valid(r);
    // Without a diffuse lobe cos θi plays no part (and is not read).
    let mu_i = match kd == [0.0; 3] {
        true => [0.0; P],
        false => data.mu_i(r),
    };
    let log_x = [data.log_x(r, 0), data.log_x(r, 1), data.log_x(r, 2)];
    let mut acc = [0.0f32; 8];
    let chunks = valid_chunks(valid);
    for (n, valid) in valid.chunks_exact(8).enumerate() {
        if !chunks.contains(&n) {
            continue;
        }
        let mut e = [0.0f32; 8];
        for c in 0..3 {
            for (l, e) in e.iter_mut().enumerate() {
                let k = 8 * n + l;
                // x = F D (G2 / (4 cos θo)) + ρd/π cos θi
                let x = fd[c].mul_add(ideal[k], kd[c] * mu_i[k]);
                *e += (ln_1p_fused(x) - log_x[c][k]).abs();
            }
        }
        for l in 0..8 {
            acc[l] += if valid[l] { e[l] } else { 0.0 };
        }
    }
    lanes_total(&acc)
}
