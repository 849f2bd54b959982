//! The Fresnel average: F per θd bin = Σ x / Σ x_ideal over the bin's samples, x_ideal =
//! D G2 / (4 cos θo), and the error sum of the model with it.

use super::error::ErrorSum;
use super::ideal::formed_ideal;
use super::lanes::valid_sum;
use super::rows::RowPass;
use super::{IsoSamples, RowIdeals};
use crate::metric::iso_tables::{IsoTables, fresnel_from_sums};
use crate::model::merl_grid::THETA_D_RES;
use crate::model::rgb::Rgb;

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
    /// Σ x per channel over the valid samples of each θd bin, counting the rows whose D is
    /// positive: the numerators of the Fresnel average.
    pub fn fresnel_numerators(&self, tables: &IsoTables) -> Vec<[f64; 3]> {
        let mut num = vec![[0.0; 3]; THETA_D_RES];
        for &r in &self.rows {
            let r = r as usize;
            if tables.d32[r / THETA_D_RES] > 0.0 {
                let s = self.data.sum_x[r];
                (0..3).for_each(|c| num[r % THETA_D_RES][c] += s[c]);
            }
        }
        num
    }

    /// Σ over valid samples of x_ideal = D G2 / (4 cos θo) per θd bin (rows with D > 0).
    pub fn ideal_sums(&self, tables: &IsoTables) -> Vec<f64> {
        self.run(&IdealSums {
            set: self,
            tables,
            cached: None,
        })
    }

    /// The Fresnel average of a model and the error sum of the model with it, G2 / (4 cos θo)
    /// formed once ([`Self::ideals`]) for both passes.
    pub fn fresnel_and_error_sum(&self, tables: &IsoTables) -> (Vec<Rgb>, f64) {
        let ideals = self.ideals(tables);
        let den = self.run(&IdealSums {
            set: self,
            tables,
            cached: Some(&ideals),
        });
        let num = self.fresnel_numerators(tables);
        let fresnel = fresnel_from_sums(&num.into_iter().zip(den).collect::<Vec<_>>());
        let tables = IsoTables {
            fresnel: std::array::from_fn(|j| fresnel[j]),
            ..tables.clone()
        };
        let e = self.run(&ErrorSum {
            set: self,
            tables: &tables,
            cached: Some(&ideals),
        });
        (fresnel, e)
    }
}

/// Σ x_ideal per θd bin.
struct IdealSums<'a, const N: usize, const M: usize, const P: usize> {
    set: &'a IsoSamples<N, M, P>,
    tables: &'a IsoTables,
    cached: Option<&'a RowIdeals<P>>,
}

impl<const N: usize, const M: usize, const P: usize> RowPass for IdealSums<'_, N, M, P> {
    type Acc = Vec<f64>;

    fn init() -> Vec<f64> {
        vec![0.0; THETA_D_RES]
    }

    #[inline(always)]
    fn row(&self, acc: &mut Vec<f64>, r: usize, p: usize) {
        let d = self.tables.d32[r / THETA_D_RES];
        if !(d > 0.0) {
            return;
        }
        let valid = self.set.data.valid(r);
        // (A function, not a closure: a closure may be called out of line, outside the vector
        // code.)
        let sum = match self.cached {
            Some(c) => valid_sum(valid, c.row(p)),
            None => valid_sum(valid, &formed_ideal::<N, M, P>(self.tables, r)),
        };
        acc[r % THETA_D_RES] += d as f64 * sum;
    }

    fn merge(a: &mut Vec<f64>, b: Vec<f64>) {
        a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
    }
}
