//! The refinement's per-bin L1 minimiser: per θh bin, the histogram of the scales of D at which
//! each sample's model meets its data, weighted by the slope there ([`BinMedians`]).

use super::rows::RowPass;
use super::{IsoSamples, RowIdeals};
use crate::metric::fast_log::ln_positive_fused;
use crate::metric::iso_tables::IsoTables;
use crate::model::merl_grid::{THETA_D_RES, THETA_H_RES};

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
    /// Per θh bin, the histogram of the scales of D at which each sample's model meets its
    /// data, weighted by the slope there ([`BinMedians`]): the refinement's per-bin L1
    /// minimiser, `span` the histogram's half width in ln s.
    pub fn bin_medians(
        &self,
        tables: &IsoTables,
        ideals: &RowIdeals<P>,
        span: f32,
    ) -> Vec<[f64; MEDIAN_BUCKETS + 2]> {
        let parts = self.run(&BinMedians {
            set: self,
            tables,
            ideals,
            span,
        });
        let mut out = vec![[0.0; MEDIAN_BUCKETS + 2]; THETA_H_RES];
        for (i, h) in parts {
            for (b, o) in out[i].iter_mut().enumerate() {
                *o += (h[0][b] + h[1][b]) + (h[2][b] + h[3][b]);
            }
        }
        out
    }
}

/// Buckets of [`BinMedians`]' histograms in ln s over [−span, span]; index 0 gathers what
/// lies below, the last index what lies above. Odd, so that ln s = 0 is a bucket's centre: a
/// bin whose samples all meet their data at s = 1 stays where it is.
pub(crate) const MEDIAN_BUCKETS: usize = 129;

/// A θh bin's histograms of [`BinMedians`], four interleaved (bin k of a row in histogram
/// k mod 4): consecutive bins often share a bucket, and one histogram would chain every
/// addition on the one before.
pub(super) type Histograms = [[f64; MEDIAN_BUCKETS + 2]; 4];

/// The weighted median of the scales at which a θh bin's samples are matched. With D of bin i
/// scaled by s, a sample's model is x(s) = s a + b (a = F D G2 / (4 cos θo), b = ρd/π cos θi)
/// and its error |ln(1 + (s a + b)/ε) − ln(1 + x/ε)| (ε = 1/`scale` of the set), whose slope
/// in s is ±w, w = a / (ε + s a + b),
/// changing sign at s* = (x − b) / a. The bin's error is least where the weight of the samples
/// with s* below s equals that of those above: the weighted median of the s*, with w taken at
/// the current s = 1. The pass gathers per bin the histogram of ln s* weighted by w.
pub(super) struct BinMedians<'a, const N: usize, const M: usize, const P: usize> {
    pub(super) set: &'a IsoSamples<N, M, P>,
    pub(super) tables: &'a IsoTables,
    pub(super) ideals: &'a RowIdeals<P>,
    pub(super) span: f32,
}

impl<const N: usize, const M: usize, const P: usize> RowPass for BinMedians<'_, N, M, P> {
    /// The histograms of the θh bins met, in order: a fold's rows come a bin at a time, and a
    /// dense accumulator per fold (90 bins of 4 KB) cost more to clear and merge than the
    /// samples themselves.
    type Acc = Vec<(usize, Box<Histograms>)>;

    fn init() -> Self::Acc {
        Vec::new()
    }

    #[inline(always)]
    fn row(&self, acc: &mut Self::Acc, r: usize, p: usize) {
        let (t, data) = (self.tables, &self.set.data);
        let (i, j) = (r / THETA_D_RES, r % THETA_D_RES);
        let d = t.d32[i];
        if !(d > 0.0) {
            return;
        }
        let ideal = self.ideals.row(p);
        let (valid, mu_i) = (data.valid(r), data.mu_i(r));
        let per_bucket = MEDIAN_BUCKETS as f32 / (2.0 * self.span);
        let eps = 1.0 / data.scale;
        let mut at = [0i32; P];
        let mut w = [0.0f32; P];
        for c in 0..3 {
            let x = data.x(r, c);
            let (fd, kd) = (t.fresnel[j][c] as f32 * d, t.diffuse[c] as f32);
            for k in 0..P {
                let (a, b) = (fd * ideal[k], kd * mu_i[k]);
                // s* = (x − b) / a, nothing below 2⁻⁶⁴ (nor a NaN, which `max` drops)
                let s = ((x[k] - b) / a).max(5.4e-20);
                let ln_s = ln_positive_fused(s.min(f32::MAX));
                // bucket 1 + ⌊(ln s* + span) · B / (2 span)⌋, clamped to [0, B + 1]
                let y = ((ln_s + self.span) * per_bucket + 1.0)
                    .max(0.0)
                    .min((MEDIAN_BUCKETS + 1) as f32);
                // SAFETY: y is in [0, B + 1] (a NaN became 0 in `max`). Signed: AVX2 converts
                // f32 to i32 in vectors, not to u32.
                at[k] = unsafe { y.to_int_unchecked::<i32>() };
                // w = a / (ε + a + b) (∝ a / (1 + (a + b)/ε)), masked bins and a ≤ 0 weigh
                // nothing
                let wk = a / (eps + a + b);
                w[k] = if valid[k] && a > 0.0 { wk } else { 0.0 };
            }
            if acc.last().is_none_or(|(b, _)| *b != i) {
                acc.push((i, Box::new([[0.0; MEDIAN_BUCKETS + 2]; 4])));
            }
            let h = &mut acc.last_mut().expect("pushed").1;
            for k in 0..P {
                h[k % 4][at[k] as usize] += w[k] as f64;
            }
        }
    }

    fn merge(a: &mut Self::Acc, b: Self::Acc) {
        a.extend(b);
    }
}
