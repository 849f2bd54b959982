//! G2 / (4 cos θo) of a model's G at a row's bins: formed from the Λ table at the row's
//! cosines ([`row_ideal`]), or formed once per set for the passes that hold G
//! ([`IsoSamples::ideals`]).

use super::rows::RowFill;
use super::{IsoSamples, RowIdeals};
use crate::metric::iso_tables::IsoTables;
use crate::metric::lambda_table::LAMBDA_TABLE;
use crate::metric::merl_geometry::row_geometry;

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
    /// G2 / (4 cos θo) of every row of this set for the G of `tables` (D, F and ρd play no
    /// part): formed once in an exactly sized buffer and read by the passes that hold G.
    pub fn ideals(&self, tables: &IsoTables) -> RowIdeals<P> {
        let mut values = vec![[0.0f32; P]; self.rows.len()];
        self.fill_rows(&mut values, &IdealFill::<N, M, P>(tables));
        RowIdeals(values)
    }
}

/// G2 / (4 cos θo) of a row for the G of the tables.
struct IdealFill<'a, const N: usize, const M: usize, const P: usize>(&'a IsoTables);

impl<const N: usize, const M: usize, const P: usize> RowFill for IdealFill<'_, N, M, P> {
    type Out = [f32; P];

    #[inline(always)]
    fn fill(&self, r: usize, _: usize, out: &mut Self::Out) {
        row_ideal::<N, M, P>(self.0, r, out);
    }
}

/// G2 / (4 cos θo) of row `r` for the G of `t`, formed (the passes without a cached row).
#[inline(always)]
pub(super) fn formed_ideal<const N: usize, const M: usize, const P: usize>(
    t: &IsoTables,
    r: usize,
) -> [f32; P] {
    let mut ideal = [0.0f32; P];
    row_ideal::<N, M, P>(t, r, &mut ideal);
    ideal
}

/// G2 / (4 cos θo) of a model at the 180 bins of row `r`: Λ(μ) = (Λ cos θ)(μ) / μ at the
/// row's 181 cosines, then G2 = 1 / (1 + max(Λi, Λo) + λ(φ) min(Λi, Λo)). Bins below the
/// horizon get meaningless values: callers mask them.
#[inline(always)]
fn row_ideal<const N: usize, const M: usize, const P: usize>(
    t: &IsoTables,
    r: usize,
    out: &mut [f32; P],
) {
    let table: &[f32; LAMBDA_TABLE] = &t.lambda_cos;
    let scale = (LAMBDA_TABLE - 1) as f32;
    let geo = row_geometry::<N>();
    let mu: &[f32; M] = geo.mu_row(r).try_into().unwrap();
    let corr: &[f32; N] = geo.corr_row(r).try_into().unwrap();
    let mut lambda = [0.0f32; M];
    for k in 0..M {
        let m = mu[k];
        // max before min: a NaN would become 0, so x is a finite number in [0, scale].
        let x = (m * scale).max(0.0).min(scale);
        // SAFETY: x is finite and in [0, 4095], well inside u32 (`as` would saturate, and its
        // checks keep the loop from vectorising). Unsigned, so that the bound below is all the
        // compiler needs to drop the table's bounds checks and gather in vectors.
        let at = unsafe { x.to_int_unchecked::<u32>() }.min(LAMBDA_TABLE as u32 - 2) as usize;
        let w = x - at as f32;
        let (a, b) = (table[at], table[at + 1]);
        lambda[k] = (a + w * (b - a)) / m;
    }
    // Λi of bin k is Λ at μ_(N−k) (μ_(180−k) on the full grid).
    let mut lambda_i = [0.0f32; N];
    for k in 0..N {
        lambda_i[k] = lambda[N - k];
    }
    for k in 0..N {
        let (li, lo) = (lambda_i[k], lambda[k]);
        let (hi, lo) = if li > lo { (li, lo) } else { (lo, li) };
        // G2 / (4 cos θo) = 1 / (4 cos θo (1 + max + λ(φ) min)): one division
        out[k] = 0.25 / (mu[k] * (1.0 + hi + corr[k] * lo));
    }
}
