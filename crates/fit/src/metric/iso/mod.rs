//! An isotropic source's samples on the MERL grid in compact form, and the two passes over
//! them: the Fresnel average and the error metric of an isotropic microfacet model.
//!
//! The samples are stored row by row ([`crate::metric::merl_geometry`]): ln(1 + x) per channel for
//! each of the 180 φd bins, padded with zeros to 184 (23 chunks of eight lanes), a validity
//! flag per bin, Σ x per channel and the valid count per row. x itself is kept only in copies
//! of a few rows (a search's subsample, the coarse rows), recovered from ln(1 + x): a fresh
//! page costs this machine's kernel about 1 ms per MB to hand out, more than the passes spend
//! reading it, so the grid is kept small. A pass runs over rows
//! (rayon over θh bins): per row D is one number (θh alone), F one RGB value (θd alone), Λ is
//! read from a table uniform in cos θ at the row's 181 cosines, and G2 / (4 cos θo) is formed
//! for the 180 bins in loops of fixed length the compiler vectorises; the sums run in eight
//! f32 lanes per row and in f64 across rows. The logs dominate: the metric's loops run chunk
//! by chunk with the lanes in registers (`error::row_error`, `solve::l1_channel`).
//!
//! The files, by pass: [`build`] fills the grid from a MERL table, [`samples`] takes sets of
//! its rows, [`rows`] runs a pass over a set (rayon, and the AVX2 / AVX-512 paths), [`ideal`]
//! forms G2 / (4 cos θo) per row, [`lanes`] holds the fixed-order sums, and the passes are
//! [`fresnel`] (the Fresnel average), [`solve`] (the F / ρd solves), [`medians`] (the
//! refinement's bin medians) and [`error`] (the metric).

mod build;
mod error;
mod fresnel;
mod ideal;
mod lanes;
mod medians;
mod rows;
mod samples;
mod solve;

pub(crate) use build::median_x;
pub(crate) use medians::MEDIAN_BUCKETS;

use crate::metric::fast_log::exp_m1;
use crate::metric::merl_geometry::{COARSE_MU_ROW, COARSE_ROW, MU_ROW, ROW, row_geometry};
use std::sync::Arc;

/// Bins per row rounded up to the sums' eight lanes.
pub(crate) const PADDED: usize = ROW.div_ceil(8) * 8;
/// [`PADDED`] for the coarse rows ([`CoarseSamples`]).
const COARSE_PADDED: usize = COARSE_ROW.div_ceil(8) * 8;

/// The rows of [`IsoSamples::coarse`]: every [`COARSE_STRIDE`]-th φd bin of a row.
///
/// [`COARSE_STRIDE`]: crate::metric::merl_geometry::COARSE_STRIDE
pub(crate) type CoarseSamples = IsoSamples<COARSE_ROW, COARSE_MU_ROW, COARSE_PADDED>;

/// The samples of one isotropic source over the whole grid: rows of `N` φd bins (all 180, or
/// every [`COARSE_STRIDE`]-th), `M` = `N` + 1 cosines per row and `P` lanes, `N` padded to
/// eight.
///
/// [`COARSE_STRIDE`]: crate::metric::merl_geometry::COARSE_STRIDE
pub(crate) struct IsoData<const N: usize = ROW, const M: usize = MU_ROW, const P: usize = PADDED> {
    /// Where each row is stored: slot `slot[r]` (`u32::MAX` for a row not stored); empty
    /// where every row of the grid is, in order (slot r). A copy of some rows
    /// ([`IsoSamples::coarse`], [`IsoSamples::subsample`]) stores those alone: fresh memory
    /// costs a fit more to fill (the kernel zeroes every new page) than to read.
    slot: Vec<u32>,
    /// ln(1 + x/ε) per bin (the metric's space: ε = 1/`scale`), slot s channel c at
    /// `(3 s + c) · P`; 0 where invalid and on the padding.
    log_x: Vec<f32>,
    /// 1/ε, the metric's scale ([`crate::metric::Metric`]): every pass forms
    /// ln(1 + `scale` x_model) against `log_x`. x and its sums are stored unscaled.
    pub scale: f32,
    /// x itself, laid out as `log_x`, on copies of some rows, where the diffuse solves'
    /// weighted sums read it in every pass; empty on the whole grid, whose x is recovered from
    /// ln(1 + x) where a pass needs it ([`exp_m1`], to 3e-6 relative), so that the grid's
    /// memory is halved.
    x: Vec<f32>,
    /// Whether the bin holds a valid sample (both directions above the horizon, a value), slot
    /// s at `s · P`.
    valid: Vec<bool>,
    /// Σ x per channel over the row's valid bins (x as stored, f32, summed in f64), per row.
    sum_x: Vec<[f64; 3]>,
    /// Σ x likewise over every `COARSE_STRIDE`-th bin, per row, from the exact x (the
    /// coarse rows' x is recovered from ln(1 + x)); empty on coarse rows.
    sum_coarse_x: Vec<[f64; 3]>,
    /// Valid bins per row (0 for a row not stored).
    count: Vec<u16>,
    /// The first sample with |x| beyond [`MAX_X`] or not finite: (flat bin, x).
    ///
    /// [`MAX_X`]: crate::metric::iso_tables::MAX_X
    pub out_of_range: Option<(usize, [f32; 3])>,
}

impl<const N: usize, const M: usize, const P: usize> IsoData<N, M, P> {
    /// Where row `r` is stored.
    #[inline(always)]
    fn slot(&self, r: usize) -> usize {
        match self.slot.is_empty() {
            true => r,
            false => self.slot[r] as usize,
        }
    }

    /// ln(1 + x) of row `r`, channel `c` (0 on the padding).
    #[inline(always)]
    fn log_x(&self, r: usize, c: usize) -> &[f32; P] {
        let at = (3 * self.slot(r) + c) * P;
        self.log_x[at..at + P].try_into().unwrap()
    }

    /// x of row `r`, channel `c` (0 where invalid and on the padding): stored, or recovered
    /// from ln(1 + x/ε).
    #[inline(always)]
    fn x(&self, r: usize, c: usize) -> [f32; P] {
        if self.x.is_empty() {
            let log_x = self.log_x(r, c);
            let eps = 1.0 / self.scale;
            let mut x = [0.0f32; P];
            for k in 0..P {
                x[k] = exp_m1(log_x[k]) * eps;
            }
            return x;
        }
        let at = (3 * self.slot(r) + c) * P;
        self.x[at..at + P].try_into().unwrap()
    }

    /// Whether each bin of row `r` holds a valid sample (false on the padding).
    #[inline(always)]
    fn valid(&self, r: usize) -> &[bool; P] {
        let at = self.slot(r) * P;
        self.valid[at..at + P].try_into().unwrap()
    }

    /// cos θi of row `r`'s bins where they hold a valid sample, 0 elsewhere and on the padding.
    #[inline(always)]
    fn mu_i(&self, r: usize) -> [f32; P] {
        let mu: &[f32; M] = row_geometry::<N>().mu_row(r).try_into().unwrap();
        let valid = self.valid(r);
        let mut out = [0.0f32; P];
        // Bin k's cos θi is the row's cosine at N − k (180 − k on the full grid): the cosines
        // 1..=N reversed (an iterator, which the compiler reverses in vectors).
        for ((o, &m), &v) in out.iter_mut().zip(mu[1..].iter().rev()).zip(valid) {
            *o = if v { m } else { 0.0 };
        }
        out
    }
}

/// A set of rows of an [`IsoData`]: the whole grid, or a subsample for searches.
#[derive(Clone)]
pub(crate) struct IsoSamples<const N: usize = ROW, const M: usize = MU_ROW, const P: usize = PADDED>
{
    pub data: Arc<IsoData<N, M, P>>,
    /// The rows in the set that hold a valid sample, increasing.
    pub rows: Vec<u16>,
    /// Valid samples in those rows.
    pub count: usize,
}

/// G2 / (4 cos θo) of a set's rows for one model's G, `PADDED` values per row in the set's row
/// order ([`IsoSamples::ideals`]).
pub(crate) struct RowIdeals<const P: usize = PADDED>(Vec<[f32; P]>);

impl<const P: usize> RowIdeals<P> {
    /// The `p`-th row's values.
    #[inline(always)]
    fn row(&self, p: usize) -> &[f32; P] {
        &self.0[p]
    }
}

/// The plain weighted sums of a set's rows for one model's G with D factored out, per row and
/// channel [Σ w ι², Σ w ι μ, Σ w ι x, Σ w μ², Σ w μ x] (`solve::weighted_row`;
/// ι = G2 / (4 cos θo)) in the set's row order ([`IsoSamples::row_sums`]).
pub(crate) struct RowSums(Vec<[[f64; 5]; 3]>);
