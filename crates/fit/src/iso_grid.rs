//! An isotropic source's samples on the MERL grid in compact form, and the two passes over
//! them: the Fresnel average and the error metric of an isotropic microfacet model.
//!
//! The samples are stored row by row ([`crate::merl_geometry`]): ln(1 + x) per channel for
//! each of the 180 φd bins, padded with zeros to 184 (23 chunks of eight lanes), a validity
//! flag per bin, Σ x per channel and the valid count per row. x itself is kept only in copies
//! of a few rows (a search's subsample, the coarse rows), recovered from ln(1 + x): a fresh
//! page costs this machine's kernel about 1 ms per MB to hand out, more than the passes spend
//! reading it, so the grid is kept small. A pass runs over rows
//! (rayon over θh bins): per row D is one number (θh alone), F one RGB value (θd alone), Λ is
//! read from a table uniform in cos θ at the row's 181 cosines, and G2 / (4 cos θo) is formed
//! for the 180 bins in loops of fixed length the compiler vectorises; the sums run in eight
//! f32 lanes per row and in f64 across rows. The logs dominate: the metric's loops run chunk
//! by chunk with the lanes in registers ([`row_error`], [`l1_channel`]).

use crate::brdf::Brdf;
use crate::brdf::Rgb;
use crate::diffuse::LinearSums;
use crate::grid::{
    IsoTables, LAMBDA_TABLE, MAX_X, exp_m1, fresnel_from_sums, ln_1p, ln_1p_fused,
    ln_positive_fused,
};
use crate::merl::{THETA_D_RES, THETA_H_RES};
use crate::merl_geometry::{
    COARSE_MU_ROW, COARSE_ROW, COARSE_STRIDE, MU_ROW, MerlGeometry, ROW, ROWS, merl_geometry,
    row_geometry,
};
use rayon::prelude::*;
use std::mem::MaybeUninit;
use std::sync::Arc;

/// Bins per row rounded up to the sums' eight lanes.
pub(crate) const PADDED: usize = ROW.div_ceil(8) * 8;
/// [`PADDED`] for the coarse rows ([`CoarseSamples`]).
const COARSE_PADDED: usize = COARSE_ROW.div_ceil(8) * 8;

/// The rows of [`IsoSamples::coarse`]: every [`COARSE_STRIDE`]-th φd bin of a row.
pub(crate) type CoarseSamples = IsoSamples<COARSE_ROW, COARSE_MU_ROW, COARSE_PADDED>;

/// The samples of one isotropic source over the whole grid: rows of `N` φd bins (all 180, or
/// every [`COARSE_STRIDE`]-th), `M` = `N` + 1 cosines per row and `P` lanes, `N` padded to
/// eight.
pub(crate) struct IsoData<const N: usize = ROW, const M: usize = MU_ROW, const P: usize = PADDED> {
    /// Where each row is stored: slot `slot[r]` (`u32::MAX` for a row not stored); empty
    /// where every row of the grid is, in order (slot r). A copy of some rows
    /// ([`IsoSamples::coarse`], [`IsoSamples::subsample`]) stores those alone: fresh memory
    /// costs a fit more to fill (the kernel zeroes every new page) than to read.
    slot: Vec<u32>,
    /// ln(1 + x) per bin, slot s channel c at `(3 s + c) · P`; 0 where invalid and on the
    /// padding.
    log_x: Vec<f32>,
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
    /// Σ x likewise over every [`COARSE_STRIDE`]-th bin, per row, from the exact x (the
    /// coarse rows' x is recovered from ln(1 + x)); empty on coarse rows.
    sum_coarse_x: Vec<[f64; 3]>,
    /// Valid bins per row (0 for a row not stored).
    count: Vec<u16>,
    /// The first sample with |x| beyond [`MAX_X`] or not finite: (flat bin, x).
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
    /// from ln(1 + x).
    #[inline(always)]
    fn x(&self, r: usize, c: usize) -> [f32; P] {
        if self.x.is_empty() {
            let log_x = self.log_x(r, c);
            let mut x = [0.0f32; P];
            for k in 0..P {
                x[k] = exp_m1(log_x[k]);
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

impl IsoSamples {
    /// The samples of an isotropic source from its MERL table.
    pub fn new(src: &dyn Brdf) -> Self {
        let table = src.merl_table();
        let geo = merl_geometry();
        let per_i = THETA_D_RES;
        // Allocated, not zeroed: the rows write every value, padding included (zeroing the
        // 19 MB first, which a reused allocation costs in full, took 1.6 ms serially).
        let (n_log, n_valid) = (3 * ROWS * PADDED, ROWS * PADDED);
        let mut log_x: Vec<f32> = Vec::with_capacity(n_log);
        let mut valid: Vec<bool> = Vec::with_capacity(n_valid);
        crate::huge_pages::advise(&mut log_x.spare_capacity_mut()[..n_log]);
        crate::huge_pages::advise(&mut valid.spare_capacity_mut()[..n_valid]);
        let mut sum_x = vec![[0.0f64; 3]; ROWS];
        let mut sum_coarse_x = vec![[0.0f64; 3]; ROWS];
        let mut count = vec![0u16; ROWS];
        let channels = [table.channel(0), table.channel(1), table.channel(2)];
        let out_of_range = log_x.spare_capacity_mut()[..n_log]
            .par_chunks_mut(3 * per_i * PADDED)
            .zip(valid.spare_capacity_mut()[..n_valid].par_chunks_mut(per_i * PADDED))
            .zip(sum_x.par_chunks_mut(per_i))
            .zip(sum_coarse_x.par_chunks_mut(per_i))
            .zip(count.par_chunks_mut(per_i))
            .enumerate()
            .map(|(i, ((((log_x, valid), sum_x), sum_coarse_x), count))| {
                let rows = RowsOut {
                    first: i * per_i,
                    log_x,
                    valid,
                    sum_x,
                    sum_coarse_x,
                    count,
                };
                build_rows(rows, channels, geo)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .next();
        // SAFETY: `build_rows` wrote every element of both, each row's bins and its padding
        // (a panic there unwinds before this line, leaving them empty).
        unsafe {
            log_x.set_len(n_log);
            valid.set_len(n_valid);
        }
        let data = IsoData {
            slot: Vec::new(),
            log_x,
            x: Vec::new(),
            valid,
            sum_x,
            sum_coarse_x,
            count,
            out_of_range,
        };
        Self::rows_of(Arc::new(data))
    }

    /// The rows of this set with every [`COARSE_STRIDE`]-th φd bin (bins 4j, j = 0..45, and
    /// their cosines μ_4j: the coarse rows keep the full ones' symmetry k ↔ 180 − k): a quarter
    /// of the samples, for the analytic fits' α bracket. Subsampling φd keeps every (θh, θd)
    /// row, so that D of every θh bin and F of every θd bin stay as determined as on this set;
    /// subsampling rows instead (a diagonal of stride 16) made sharp lobes' fits up to 2.9
    /// times worse on the 100 proxies, this at most 3 %.
    pub fn coarse(&self) -> CoarseSamples {
        self.gather(COARSE_STRIDE)
    }

    /// A copy of this set's rows with every `stride`-th φd bin (bins `stride` j, j < `N2`), x
    /// stored (recovered from ln(1 + x)).
    fn gather<const N2: usize, const M2: usize, const P2: usize>(
        &self,
        stride: usize,
    ) -> IsoSamples<N2, M2, P2> {
        debug_assert_eq!(N2 * stride, ROW);
        let (full, stored) = (&*self.data, self.rows.len());
        let mut log_x = vec![0.0f32; 3 * stored * P2];
        let mut x = vec![0.0f32; 3 * stored * P2];
        let mut valid = vec![false; stored * P2];
        // Each stored row's bins copied and its x recovered, rows side by side (rayon over
        // slots); its count and Σ x returned and placed by row after.
        let per_slot: Vec<(u16, [f64; 3])> = log_x
            .par_chunks_mut(3 * P2)
            .zip(x.par_chunks_mut(3 * P2))
            .zip(valid.par_chunks_mut(P2))
            .zip(&self.rows)
            .map(|(((log_x, x), valid), &r)| {
                let r = r as usize;
                let from = full.valid(r);
                for j in 0..N2 {
                    valid[j] = from[stride * j];
                }
                let count = valid[..N2].iter().filter(|&&v| v).count() as u16;
                let sums = std::array::from_fn(|c| {
                    let (from_log, to) = (full.log_x(r, c), c * P2);
                    for j in 0..N2 {
                        log_x[to + j] = from_log[stride * j];
                    }
                    for (x, &l) in x[to..to + N2].iter_mut().zip(&log_x[to..to + N2]) {
                        *x = exp_m1(l);
                    }
                    // The sums of the exact x where the rows hold them.
                    match (stride, full.sum_coarse_x.is_empty()) {
                        (1, _) => full.sum_x[r][c],
                        (COARSE_STRIDE, false) => full.sum_coarse_x[r][c],
                        _ => sum_f64(&x[to..to + N2]),
                    }
                });
                (count, sums)
            })
            .collect();
        let mut slot = vec![u32::MAX; ROWS];
        let (mut sum_x, mut count) = (vec![[0.0f64; 3]; ROWS], vec![0u16; ROWS]);
        // Whole rows keep the exact coarse sums, for their own coarse rows.
        let mut sum_coarse_x = match stride {
            1 => vec![[0.0f64; 3]; ROWS],
            _ => Vec::new(),
        };
        for (to_slot, (&r, &(n, sums))) in self.rows.iter().zip(&per_slot).enumerate() {
            let r = r as usize;
            (slot[r], count[r], sum_x[r]) = (to_slot as u32, n, sums);
            if let Some(s) = sum_coarse_x.get_mut(r) {
                *s = full.sum_coarse_x[r];
            }
        }
        let data = IsoData {
            slot,
            log_x,
            x,
            valid,
            sum_x,
            sum_coarse_x,
            count,
            out_of_range: None,
        };
        let rows: Vec<u16> = self
            .rows
            .iter()
            .copied()
            .filter(|&r| data.count[r as usize] > 0)
            .collect();
        let count = rows.iter().map(|&r| data.count[r as usize] as usize).sum();
        IsoSamples {
            data: Arc::new(data),
            rows,
            count,
        }
    }

    /// Every `stride`-th row of this set holding samples (all of their φd bins); above a stride
    /// of 1 a copy of those rows with x stored: the searches and the diffuse separation run
    /// their weighted passes on it many times.
    pub fn subsample(&self, stride: usize) -> Self {
        let rows = self.every(stride);
        match stride > 1 {
            true => rows.gather(1),
            false => rows,
        }
    }

    /// ln(1 + x) and the validity flags of every row of the grid as stored (row r, channel c
    /// at (3 r + c) · [`PADDED`], flags at r · [`PADDED`]); `None` for a copy of some rows.
    #[cfg(feature = "gpu")]
    pub fn whole_grid(&self) -> Option<(&[f32], &[bool])> {
        let d = &self.data;
        d.slot.is_empty().then_some((&d.log_x[..], &d.valid[..]))
    }

    /// The valid bins of row `r` with ln(1 + x) per channel: (flat bin, ln(1 + x)).
    pub fn row_samples(&self, r: usize) -> impl Iterator<Item = (usize, [f32; 3])> + '_ {
        let d = &self.data;
        (0..ROW).filter(move |&k| d.valid(r)[k]).map(move |k| {
            let l = std::array::from_fn(|c| d.log_x(r, c)[k]);
            (r * ROW + k, l)
        })
    }
}

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
    /// The rows of `data` that hold samples.
    fn rows_of(data: Arc<IsoData<N, M, P>>) -> Self {
        let rows: Vec<u16> = (0..ROWS)
            .filter(|&r| data.count[r] > 0)
            .map(|r| r as u16)
            .collect();
        let count = rows.iter().map(|&r| data.count[r as usize] as usize).sum();
        IsoSamples { data, rows, count }
    }

    /// Every `stride`-th row of this set holding samples (all of their φd bins), sharing its
    /// data.
    fn every(&self, stride: usize) -> Self {
        let rows: Vec<u16> = self.rows.iter().copied().step_by(stride.max(1)).collect();
        let count = rows
            .iter()
            .map(|&r| self.data.count[r as usize] as usize)
            .sum();
        IsoSamples {
            data: self.data.clone(),
            rows,
            count,
        }
    }

    /// The rows of this set with (θh bin + θd bin) ≡ 0 mod `stride` (all of their φd bins): a
    /// diagonal pattern, so that every θh bin and every θd bin keeps about 1/`stride` of its
    /// rows and the per-bin unknowns (D of a θh bin, F of a θd bin) all stay determined.
    /// ([`Self::subsample`] leaves the odd θd bins empty for an even stride, a row being
    /// θd bin + 90 θh bin; it suits the α searches, which need every θh bin near the peak.)
    pub fn diagonal(&self, stride: usize) -> Self {
        self.rows_where(|r| on_diagonal(r, stride))
    }

    /// The rows of this set for which `keep` holds.
    fn rows_where(&self, keep: impl Fn(usize) -> bool) -> Self {
        let rows: Vec<u16> = self
            .rows
            .iter()
            .copied()
            .filter(|&r| keep(r as usize))
            .collect();
        let count = rows
            .iter()
            .map(|&r| self.data.count[r as usize] as usize)
            .sum();
        IsoSamples {
            data: self.data.clone(),
            rows,
            count,
        }
    }

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

    /// F per θd bin and ρd/π solved for a model's D and G ([`LinearSums::solve`]), and the
    /// error sum of the model with them. The weighted least-squares solve (two passes) is
    /// followed by `irls` steps of iteratively reweighted least squares towards the metric's L1
    /// minimum (one pass each, which also measures the error of the step before); the best
    /// solution measured is returned.
    pub fn fresnel_diffuse_and_error_sum(
        &self,
        tables: &IsoTables,
        irls: usize,
    ) -> (Vec<Rgb>, Rgb, f64) {
        self.fresnel_diffuse_and_error_sum_with(tables, irls, &self.ideals(tables), None)
    }

    /// [`Self::fresnel_diffuse_and_error_sum`] with the rows' G2 / (4 cos θo) formed already
    /// ([`Self::ideals`] for the G of `tables`), and with `plain` their plain weighted sums
    /// ([`Self::row_sums`] of `ideals`), which spare the first pass.
    pub fn fresnel_diffuse_and_error_sum_with(
        &self,
        tables: &IsoTables,
        irls: usize,
        ideals: &RowIdeals<P>,
        plain: Option<&RowSums>,
    ) -> (Vec<Rgb>, Rgb, f64) {
        let start = match plain {
            Some(plain) => self.plain_sums(tables, plain).solve(),
            None => self.plain_solve(tables, ideals),
        };
        self.reweighted(tables, start, irls, ideals)
    }

    /// The plain weighted least-squares F per θd bin and ρd/π for the D of `tables` and the G
    /// of `ideals` (one pass).
    pub fn plain_solve(&self, tables: &IsoTables, ideals: &RowIdeals<P>) -> (Vec<Rgb>, Rgb) {
        self.run(&WeightedRows {
            set: self,
            tables,
            l1: false,
            ideals,
        })
        .solve()
    }

    /// The second half of [`Self::fresnel_diffuse_and_error_sum_with`]: from the plain solve's
    /// F per θd bin and ρd/π (`plain`), `irls` reweighted steps and the error sum; the best
    /// solution measured.
    pub fn reweighted(
        &self,
        tables: &IsoTables,
        plain: (Vec<Rgb>, Rgb),
        irls: usize,
        ideals: &RowIdeals<P>,
    ) -> (Vec<Rgb>, Rgb, f64) {
        let mut tables = tables.clone();
        let (mut fresnel, mut kd) = plain;
        let mut best: Option<(Vec<Rgb>, Rgb, f64)> = None;
        for _ in 0..irls {
            tables.set_fresnel(&fresnel);
            tables.diffuse = kd;
            let sums = self.run(&WeightedRows {
                set: self,
                tables: &tables,
                l1: true,
                ideals,
            });
            if best.as_ref().is_none_or(|b| sums.error < b.2) {
                best = Some((fresnel.clone(), kd, sums.error));
            }
            (fresnel, kd) = sums.solve();
        }
        tables.set_fresnel(&fresnel);
        tables.diffuse = kd;
        let e = self.run(&ErrorSum {
            set: self,
            tables: &tables,
            cached: Some(ideals),
        });
        match best {
            Some(b) if b.2 < e => b,
            _ => (fresnel, kd, e),
        }
    }

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

    /// G2 / (4 cos θo) of every row of this set for the G of `tables` (D, F and ρd play no
    /// part): formed once in an exactly sized buffer and read by the passes that hold G.
    pub fn ideals(&self, tables: &IsoTables) -> RowIdeals<P> {
        let mut values = vec![[0.0f32; P]; self.rows.len()];
        self.fill_rows(&mut values, &IdealFill::<N, M, P>(tables));
        RowIdeals(values)
    }

    /// The plain (unreweighted) weighted sums of every row of this set for the G of `ideals`,
    /// D factored out: with G held, the plain F / ρd solve of any D then costs O(rows)
    /// ([`Self::fresnel_diffuse_and_error_sum_with`]) instead of a pass.
    pub fn row_sums(&self, ideals: &RowIdeals<P>) -> RowSums {
        let mut values = vec![[[0.0f64; 5]; 3]; self.rows.len()];
        let fill = SumsFill {
            data: &self.data,
            ideals,
        };
        self.fill_rows(&mut values, &fill);
        RowSums(values)
    }

    /// The plain normal equations of the D of `tables` from the rows' sums (O(rows)); as the
    /// pass would give them, summed in another order.
    fn plain_sums(&self, tables: &IsoTables, plain: &RowSums) -> LinearSums {
        debug_assert_eq!(plain.0.len(), self.rows.len());
        let mut acc = LinearSums::zero();
        for (&r, sums) in self.rows.iter().zip(&plain.0) {
            let (i, j) = (r as usize / THETA_D_RES, r as usize % THETA_D_RES);
            let d = tables.d32[i];
            add_row(&mut acc, j, if d > 0.0 { d as f64 } else { 0.0 }, sums);
        }
        acc
    }

    /// `out[p]` = the value of the `p`-th row of this set: rayon over θh bins, each bin's rows
    /// vectorised as the passes are ([`run_rows`]).
    fn fill_rows<F: RowFill>(&self, out: &mut [F::Out], fill: &F) {
        // A pass whose accumulator is the output (run over given rows, never folded).
        struct Fill<'f, 'o, F: RowFill>(&'f F, usize, std::marker::PhantomData<fn(&'o mut F)>);
        impl<'o, F: RowFill> RowPass for Fill<'_, 'o, F> {
            type Acc = &'o mut [F::Out];
            fn init() -> Self::Acc {
                &mut []
            }
            #[inline(always)]
            fn row(&self, out: &mut Self::Acc, r: usize, p: usize) {
                self.0.fill(r, self.1 + p, &mut out[p]);
            }
            fn merge(_: &mut Self::Acc, _: Self::Acc) {}
        }
        let bounds = self.bin_bounds();
        let mut parts = Vec::with_capacity(THETA_H_RES);
        let mut rest = out;
        for i in 0..THETA_H_RES {
            let (part, tail) = rest.split_at_mut(bounds[i + 1] - bounds[i]);
            parts.push((i, part));
            rest = tail;
        }
        parts.into_par_iter().for_each(|(i, mut out)| {
            let rows = &self.rows[bounds[i]..bounds[i + 1]];
            run_rows(
                &Fill(fill, bounds[i], std::marker::PhantomData),
                &mut out,
                rows,
                0,
            );
        });
    }

    /// Where each θh bin's rows start in `rows` (which are increasing), and the end.
    fn bin_bounds(&self) -> [usize; THETA_H_RES + 1] {
        std::array::from_fn(|i| {
            self.rows
                .partition_point(|&r| (r as usize) < i * THETA_D_RES)
        })
    }

    /// A pass over this set's rows, a θh bin's rows per task.
    fn run<R: RowPass>(&self, pass: &R) -> R::Acc {
        let bounds = self.bin_bounds();
        (0..THETA_H_RES)
            .into_par_iter()
            .fold(R::init, |mut acc, i| {
                let rows = &self.rows[bounds[i]..bounds[i + 1]];
                run_rows(pass, &mut acc, rows, bounds[i]);
                acc
            })
            .reduce(R::init, |mut a, b| {
                R::merge(&mut a, b);
                a
            })
    }
}

/// A pass: an accumulator, what one row adds to it, how two merge.
trait RowPass: Sync {
    type Acc: Send;
    fn init() -> Self::Acc;
    /// Adds row `r`, the `p`-th row of the set.
    fn row(&self, acc: &mut Self::Acc, r: usize, p: usize);
    fn merge(a: &mut Self::Acc, b: Self::Acc);
}

/// A value per row that [`IsoSamples::fill_rows`] writes. `fill` is inlined into the
/// vectorised row loop ([`run_rows`]); a closure there would be called out of line, compiled
/// for the baseline target.
trait RowFill: Sync {
    type Out: Send;
    /// The value of row `r`, the `p`-th of the set.
    fn fill(&self, r: usize, p: usize, out: &mut Self::Out);
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

/// A row's plain weighted sums with D factored out, for the G of `ideals`.
struct SumsFill<'a, const N: usize, const M: usize, const P: usize> {
    data: &'a IsoData<N, M, P>,
    ideals: &'a RowIdeals<P>,
}

impl<const N: usize, const M: usize, const P: usize> RowFill for SumsFill<'_, N, M, P> {
    type Out = [[f64; 5]; 3];

    #[inline(always)]
    fn fill(&self, r: usize, p: usize, out: &mut Self::Out) {
        *out = weighted_row(self.data, r, self.ideals.row(p), None).0;
    }
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
/// channel [Σ w ι², Σ w ι μ, Σ w ι x, Σ w μ², Σ w μ x] ([`weighted_row`]; ι = G2 / (4 cos θo))
/// in the set's row order ([`IsoSamples::row_sums`]).
pub(crate) struct RowSums(Vec<[[f64; 5]; 3]>);

/// G2 / (4 cos θo) of row `r` for the G of `t`, formed (the passes without a cached row).
#[inline(always)]
fn formed_ideal<const N: usize, const M: usize, const P: usize>(
    t: &IsoTables,
    r: usize,
) -> [f32; P] {
    let mut ideal = [0.0f32; P];
    row_ideal::<N, M, P>(t, r, &mut ideal);
    ideal
}

/// Σ of a row's values over its valid bins, in eight lanes.
#[inline(always)]
fn valid_sum<const P: usize>(valid: &[bool; P], v: &[f32; P]) -> f64 {
    let mut masked = [0.0f32; P];
    for k in 0..P {
        masked[k] = if valid[k] { v[k] } else { 0.0 };
    }
    lanes_sum(&masked)
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

/// The weighted sums of the F / ρd solve (each row's G2 / (4 cos θo) given). Per bin
/// w = 1 / (1 + x)², m = D G2 / (4 cos θo) (0 where D ≤ 0), μ = cos θi. With `l1`, a step of
/// iteratively reweighted least squares for the metric's L1 norm: w is also divided by the
/// current model's |ln(1 + x_model) − ln(1 + x)| (at least `IRLS_FLOOR`; F and ρd/π from
/// `tables`), whose sum the pass gathers.
struct WeightedRows<'a, const N: usize, const M: usize, const P: usize> {
    set: &'a IsoSamples<N, M, P>,
    tables: &'a IsoTables,
    l1: bool,
    ideals: &'a RowIdeals<P>,
}

/// The smallest residual an IRLS weight divides by: 10⁻³ in ln(1 + x), about the f32 error
/// of a sum of a row's terms and far below any real material's mean error.
const IRLS_FLOOR: f32 = 1e-3;

impl<const N: usize, const M: usize, const P: usize> RowPass for WeightedRows<'_, N, M, P> {
    type Acc = LinearSums;

    fn init() -> Self::Acc {
        LinearSums::zero()
    }

    #[inline(always)]
    fn row(&self, acc: &mut Self::Acc, r: usize, p: usize) {
        let t = self.tables;
        let (i, j) = (r / THETA_D_RES, r % THETA_D_RES);
        let d = t.d32[i];
        let d = if d > 0.0 { d } else { 0.0 };
        let l1 = self.l1.then(|| {
            let fd = t.fresnel[j].map(|f| f as f32 * d);
            (fd, t.diffuse.map(|k| k as f32))
        });
        let (sums, error) = weighted_row(&self.set.data, r, self.ideals.row(p), l1);
        acc.error += error;
        add_row(acc, j, d as f64, &sums);
    }

    fn merge(a: &mut Self::Acc, b: Self::Acc) {
        a.add(&b);
    }
}

/// Adds a row of θd bin `j` and D = `d` to the normal equations, given its sums with D
/// factored out ([`weighted_row`]): m = D ι, so Σ w m² = D² Σ w ι² and Σ w m · = D Σ w ι ·.
#[inline(always)]
fn add_row(acc: &mut LinearSums, j: usize, d: f64, sums: &[[f64; 5]; 3]) {
    for (c, s) in sums.iter().enumerate() {
        let b = &mut acc.bins[j][c];
        b[0] += d * d * s[0];
        b[1] += d * s[1];
        b[2] += d * s[2];
        acc.diffuse[c][0] += s[3];
        acc.diffuse[c][1] += s[4];
    }
}

/// One row's weighted sums with D factored out: per channel [Σ w ι², Σ w ι μ, Σ w ι x,
/// Σ w μ², Σ w μ x] over the valid bins, ι = G2 / (4 cos θo) (`ideal`), μ = cos θi,
/// w = 1 / (1 + x)². With `l1` = (F D, ρd/π) per channel, a step of iteratively reweighted
/// least squares for the metric's L1 norm: w is also divided by that model's
/// |ln(1 + x_model) − ln(1 + x)| (at least `IRLS_FLOOR`), whose sum (the row's error, as
/// [`row_error`] gives it) is returned too.
#[inline(always)]
fn weighted_row<const N: usize, const M: usize, const P: usize>(
    data: &IsoData<N, M, P>,
    r: usize,
    ideal: &[f32; P],
    l1: Option<([f32; 3], [f32; 3])>,
) -> ([[f64; 5]; 3], f64) {
    let valid = data.valid(r);
    let mu_i = data.mu_i(r);
    // ι masked: with ι = μ = 0, an invalid bin's (or the padding's) terms and residual are 0
    // (x and ln(1 + x) are stored 0 there).
    let mut m = [0.0f32; P];
    for k in 0..P {
        m[k] = if valid[k] { ideal[k] } else { 0.0 };
    }
    let (mut sums, mut error) = ([[0.0f64; 5]; 3], 0.0);
    match l1 {
        None => {
            // The terms, cleared once for the three channels (each overwrites them all).
            let mut terms = [[0.0f32; P]; 5];
            for (c, out) in sums.iter_mut().enumerate() {
                let s = plain_channel(&m, &mu_i, &data.x(r, c), &mut terms);
                // A loop, not `map`: an array's map is called out of line, outside the
                // vector code.
                for (o, s) in out.iter_mut().zip(&s) {
                    *o = lanes_total(s);
                }
            }
        }
        Some((fd, kd)) => {
            let chunks = valid_chunks(valid);
            for (c, out) in sums.iter_mut().enumerate() {
                let (x, log_x) = (data.x(r, c), data.log_x(r, c));
                let (s, e) = l1_channel(&m, &mu_i, &x, log_x, fd[c], kd[c], &chunks);
                for (o, s) in out.iter_mut().zip(&s) {
                    *o = lanes_total(s);
                }
                error += lanes_total(&e);
            }
        }
    }
    (sums, error)
}

/// One channel of [`weighted_row`] without reweighting: the five sums in eight lanes. The terms
/// are stored per bin (in `t`, all overwritten) and summed after: the loop vectoriser's shape,
/// which here ran three times as fast as [`l1_channel`]'s chunk-by-chunk one (measured on
/// delrin, `cargo test` timing of the pass: 0.61 against 1.8 ms for 2025 rows).
#[inline(always)]
fn plain_channel<const P: usize>(
    m: &[f32; P],
    mu_i: &[f32; P],
    x: &[f32; P],
    t: &mut [[f32; P]; 5],
) -> [[f32; 8]; 5] {
    let mut s = [[0.0f32; 8]; 5];
    for k in 0..P {
        // w = 1 / (1 + x)² (d ln(1 + x) = dx / (1 + x))
        let w = 1.0 / ((1.0 + x[k]) * (1.0 + x[k]));
        let (wm, wu) = (w * m[k], w * mu_i[k]);
        t[0][k] = wm * m[k];
        t[1][k] = wm * mu_i[k];
        t[2][k] = wm * x[k];
        t[3][k] = wu * mu_i[k];
        t[4][k] = wu * x[k];
    }
    for (s, t) in s.iter_mut().zip(t.iter()) {
        for c in t.chunks_exact(8) {
            for l in 0..8 {
                s[l] += c[l];
            }
        }
    }
    s
}

/// One channel of [`weighted_row`] reweighted for the L1 norm (F D = `f`, ρd/π = `kd`): the
/// five sums and the residuals in eight lanes, chunk by chunk (those of `chunks`), each
/// chunk's lanes in registers. Stored per bin as [`plain_channel`] does, the pass took 1.7 times as long.
#[inline(always)]
fn l1_channel<const P: usize>(
    m: &[f32; P],
    mu_i: &[f32; P],
    x: &[f32; P],
    log_x: &[f32; P],
    f: f32,
    kd: f32,
    chunks: &std::ops::Range<usize>,
) -> ([[f32; 8]; 5], [f32; 8]) {
    let (mut s, mut e) = ([[0.0f32; 8]; 5], [0.0f32; 8]);
    for n in 0..P / 8 {
        // (Chunks without a valid bin add 0: ι = μ = x = ln(1 + x) = 0 there.)
        if !chunks.contains(&n) {
            continue;
        }
        for l in 0..8 {
            let k = 8 * n + l;
            // x_model = F D (G2 / (4 cos θo)) + ρd/π cos θi
            let res = (ln_1p_fused(f.mul_add(m[k], kd * mu_i[k])) - log_x[k]).abs();
            e[l] += res;
            // w = 1 / (1 + x)² over the residual (at least the floor): one division
            let w = 1.0 / (res.max(IRLS_FLOOR) * (1.0 + x[k]) * (1.0 + x[k]));
            let (wm, wu) = (w * m[k], w * mu_i[k]);
            s[0][l] += wm * m[k];
            s[1][l] += wm * mu_i[k];
            s[2][l] += wm * x[k];
            s[3][l] += wu * mu_i[k];
            s[4][l] += wu * x[k];
        }
    }
    (s, e)
}

/// Buckets of [`BinMedians`]' histograms in ln s over [−span, span]; index 0 gathers what
/// lies below, the last index what lies above. Odd, so that ln s = 0 is a bucket's centre: a
/// bin whose samples all meet their data at s = 1 stays where it is.
pub(crate) const MEDIAN_BUCKETS: usize = 129;

/// A θh bin's histograms of [`BinMedians`], four interleaved (bin k of a row in histogram
/// k mod 4): consecutive bins often share a bucket, and one histogram would chain every
/// addition on the one before.
type Histograms = [[f64; MEDIAN_BUCKETS + 2]; 4];

/// The weighted median of the scales at which a θh bin's samples are matched. With D of bin i
/// scaled by s, a sample's model is x(s) = s a + b (a = F D G2 / (4 cos θo), b = ρd/π cos θi)
/// and its error |ln(1 + s a + b) − ln(1 + x)|, whose slope in s is ±w, w = a / (1 + s a + b),
/// changing sign at s* = (x − b) / a. The bin's error is least where the weight of the samples
/// with s* below s equals that of those above: the weighted median of the s*, with w taken at
/// the current s = 1. The pass gathers per bin the histogram of ln s* weighted by w.
struct BinMedians<'a, const N: usize, const M: usize, const P: usize> {
    set: &'a IsoSamples<N, M, P>,
    tables: &'a IsoTables,
    ideals: &'a RowIdeals<P>,
    span: f32,
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
                // w = a / (1 + a + b), masked bins and a ≤ 0 weigh nothing
                let wk = a / (1.0 + a + b);
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

/// Σ of the error over samples and channels.
struct ErrorSum<'a, const N: usize, const M: usize, const P: usize> {
    set: &'a IsoSamples<N, M, P>,
    tables: &'a IsoTables,
    /// G2 / (4 cos θo) of the set's rows already formed.
    cached: Option<&'a RowIdeals<P>>,
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
        let f = t.fresnel[j].map(|f| f as f32 * t.d32[i]);
        let kd = t.diffuse.map(|k| k as f32);
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
        let kd = t.diffuse.map(|k| k as f32);
        for (a, fresnel) in acc.iter_mut().zip(self.fresnels) {
            let f = fresnel[j].map(|f| f as f32 * t.d32[i]);
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

/// A pass's rows, compiled for AVX2 and FMA as well where the CPU has them: the loops of a pass
/// are written for the compiler to vectorise, and the baseline x86-64 target gives it four
/// lanes (SSE2) where AVX2 gives eight. The results do not depend on the path taken: the
/// kernels fuse exactly the multiply-adds they write as `mul_add` (the logs' polynomial, the
/// model's F D ι + ρd/π μ; without FMA in the CPU these are emulated, exact and slow), Rust
/// contracts nothing else, and the sums run in eight lanes in all. FMA took a fifth off the
/// metric's pass (delrin, 2025 rows: 0.64 → 0.49 ms).
#[inline(always)]
fn run_rows<P: RowPass>(pass: &P, acc: &mut P::Acc, rows: &[u16], first: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        let fma = std::arch::is_x86_feature_detected!("fma");
        if fma && std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F and FMA, checked just above.
            return unsafe { run_rows_avx512(pass, acc, rows, first) };
        }
        if fma && std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 and FMA, checked just above.
            return unsafe { run_rows_avx2(pass, acc, rows, first) };
        }
    }
    run_rows_baseline(pass, acc, rows, first)
}

#[inline(always)]
fn run_rows_baseline<P: RowPass>(pass: &P, acc: &mut P::Acc, rows: &[u16], first: usize) {
    for (n, &r) in rows.iter().enumerate() {
        pass.row(acc, r as usize, first + n);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn run_rows_avx2<P: RowPass>(pass: &P, acc: &mut P::Acc, rows: &[u16], first: usize) {
    run_rows_baseline(pass, acc, rows, first)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
fn run_rows_avx512<P: RowPass>(pass: &P, acc: &mut P::Acc, rows: &[u16], first: usize) {
    run_rows_baseline(pass, acc, rows, first)
}

/// Whether row `r` (θd bin + 90 θh bin) has (θh bin + θd bin) ≡ 0 mod `stride` (a stride of 0
/// taken as 1).
fn on_diagonal(r: usize, stride: usize) -> bool {
    (r / THETA_D_RES + r % THETA_D_RES).is_multiple_of(stride.max(1))
}

/// The outputs of consecutive rows of an [`IsoData`] being built.
struct RowsOut<'a> {
    first: usize,
    /// Uninitialised on entry; every value is written, the padding with 0.
    log_x: &'a mut [MaybeUninit<f32>],
    /// Uninitialised on entry; every flag is written, the padding with `false`.
    valid: &'a mut [MaybeUninit<bool>],
    sum_x: &'a mut [[f64; 3]],
    sum_coarse_x: &'a mut [[f64; 3]],
    count: &'a mut [u16],
}

/// Fills rows from the MERL channels (AVX-512 or AVX2 where the CPU has it, as the passes);
/// returns the first sample out of range.
fn build_rows(out: RowsOut, raw: [&[[u8; 8]]; 3], geo: &MerlGeometry) -> Option<(usize, [f32; 3])> {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F, checked just above.
            return unsafe { build_rows_avx512(out, raw, geo) };
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2, checked just above.
            return unsafe { build_rows_avx2(out, raw, geo) };
        }
    }
    build_rows_baseline(out, raw, geo)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn build_rows_avx512(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
) -> Option<(usize, [f32; 3])> {
    build_rows_baseline(out, raw, geo)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn build_rows_avx2(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
) -> Option<(usize, [f32; 3])> {
    build_rows_baseline(out, raw, geo)
}

#[inline(always)]
fn build_rows_baseline(
    out: RowsOut,
    raw: [&[[u8; 8]]; 3],
    geo: &MerlGeometry,
) -> Option<(usize, [f32; 3])> {
    let mut bad = None;
    let sums = out.sum_x.iter_mut().zip(out.sum_coarse_x.iter_mut());
    for (n, ((sum, sum_coarse), count)) in sums.zip(out.count.iter_mut()).enumerate() {
        let r = out.first + n;
        let mu: &[f32; MU_ROW] = geo.mu_row(r).try_into().unwrap();
        // The row's flags and values are formed here and written out whole, padding included.
        let mut valid = [false; PADDED];
        // The stored values, little-endian as in the file, read in place.
        let v: [&[[u8; 8]; ROW]; 3] =
            std::array::from_fn(|c| raw[c][r * ROW..(r + 1) * ROW].try_into().unwrap());
        // cos θi of bin k: the cosine at 180 − k (the cosines 1..=180 reversed).
        let mut mu_i = [0.0f32; ROW];
        for (o, &m) in mu_i.iter_mut().zip(mu[1..].iter().rev()) {
            *o = m;
        }
        // Valid: both directions above the horizon and no channel missing (negative; a NaN
        // is a value, refused below as out of range). `&`, not `&&`: no branch in the loop.
        for k in 0..ROW {
            let missing = (0..3).fold(false, |m, c| m | (f64::from_le_bytes(v[c][k]) < 0.0));
            valid[k] = (mu_i[k] > 0.0) & (mu[k] > 0.0) & !missing;
        }
        // x = f_r cos θi, 0 where invalid
        let x = |c: usize, k: usize| {
            let x = (f64::from_le_bytes(v[c][k]) * crate::merl::SCALE[c] * mu_i[k] as f64) as f32;
            if valid[k] { x } else { 0.0 }
        };
        // x of each channel, then ln(1 + x) over it in place.
        let mut in_range = true;
        for c in 0..3 {
            let mut row = [0.0f32; PADDED];
            for (k, v) in row[..ROW].iter_mut().enumerate() {
                *v = x(c, k);
                in_range &= v.abs() <= MAX_X;
            }
            sum[c] = sum_f64(&row[..ROW]);
            let mut coarse = [0.0f32; COARSE_ROW];
            for (j, x) in coarse.iter_mut().enumerate() {
                *x = row[COARSE_STRIDE * j];
            }
            sum_coarse[c] = sum_f64(&coarse);
            let at = (3 * n + c) * PADDED;
            // ln(1 + 0) = 0 on the padding.
            for (o, x) in out.log_x[at..at + PADDED].iter_mut().zip(row) {
                o.write(ln_1p(x));
            }
        }
        for (o, v) in out.valid[n * PADDED..(n + 1) * PADDED]
            .iter_mut()
            .zip(valid)
        {
            o.write(v);
        }
        if bad.is_none() && !in_range {
            bad = (0..ROW)
                .find(|&k| (0..3).any(|c| !(x(c, k).abs() <= MAX_X)))
                .map(|k| (r * ROW + k, std::array::from_fn(|c| x(c, k))));
        }
        *count = valid.iter().filter(|&&v| v).count() as u16;
    }
    bad
}

/// Σ of f32 values in f64, in four lanes (a fixed order the compiler can vectorise).
#[inline(always)]
fn sum_f64(v: &[f32]) -> f64 {
    let mut acc = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let rest: f64 = chunks.remainder().iter().map(|&x| x as f64).sum();
    for c in chunks {
        for l in 0..4 {
            acc[l] += c[l] as f64;
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + rest
}

/// Σ of eight lanes in f64.
#[inline(always)]
fn lanes_total(acc: &[f32; 8]) -> f64 {
    acc.iter().map(|&a| a as f64).sum()
}

/// Σ of a row's values in eight f32 lanes (a fixed order, whatever the vector width), in f64.
#[inline(always)]
fn lanes_sum<const P: usize>(v: &[f32; P]) -> f64 {
    let mut acc = [0.0f32; 8];
    for c in v.chunks_exact(8) {
        for l in 0..8 {
            acc[l] += c[l];
        }
    }
    lanes_total(&acc)
}

/// Σ over a row's valid bins and channels of |ln(1 + x_model) − ln(1 + x_data)|, with
/// x_model = fd_c (G2 / (4 cos θo)) + kd_c cos θi: `fd` is F D of the row, `kd` ρd/π.
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

/// The 8-bin chunks of a row that hold a valid bin, from the first to the last: a row's valid
/// bins lie between its two horizons (cos θi > 0 and cos θo > 0), and the chunks outside them,
/// a quarter of the grid's, add nothing to a pass's sums.
#[inline(always)]
fn valid_chunks<const P: usize>(valid: &[bool; P]) -> std::ops::Range<usize> {
    let any = |n: usize| valid[8 * n..8 * n + 8].iter().any(|&v| v);
    let chunks = P / 8;
    let first = (0..chunks).find(|&n| any(n)).unwrap_or(chunks);
    let end = (first..chunks)
        .rev()
        .find(|&n| any(n))
        .map_or(first, |n| n + 1);
    first..end
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::parse_analytic;
    use crate::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};

    /// The plain normal equations from the rows' cached sums are the pass's: the same per-row
    /// sums ([`weighted_row`]) added in another order, so equal to f64 rounding (1e-12).
    #[test]
    fn cached_row_sums_give_the_pass_sums() {
        let src = parse_analytic("ggx?alpha=0.3&f0=0.04&kd=0.3,0.1,0.05").unwrap();
        let set = IsoSamples::new(&src).diagonal(4);
        let model = crate::microfacet::MicrofacetBrdf::ideal(
            "m",
            crate::microfacet::Ndf::Analytic(crate::microfacet::AnalyticNdf::isotropic(
                crate::microfacet::NdfKind::Beckmann,
                0.2,
            )),
        );
        let tables = IsoTables::new(&model).unwrap();
        let ideals = set.ideals(&tables);
        let pass = set.run(&WeightedRows {
            set: &set,
            tables: &tables,
            l1: false,
            ideals: &ideals,
        });
        let cached = set.plain_sums(&tables, &set.row_sums(&ideals));
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1e-300);
        for (j, (a, b)) in pass.bins.iter().zip(&cached.bins).enumerate() {
            for c in 0..3 {
                for n in 0..3 {
                    assert!(
                        close(a[c][n], b[c][n]),
                        "θd bin {j} c {c} n {n}: {a:?} {b:?}"
                    );
                }
            }
        }
        for c in 0..3 {
            for n in 0..2 {
                let (a, b) = (pass.diffuse[c][n], cached.diffuse[c][n]);
                assert!(a > 0.0 && close(a, b), "diffuse c {c} n {n}: {a} {b}");
            }
        }
    }

    /// The passes give the same bits on the vector path the CPU takes (AVX2 + FMA here) and on
    /// the baseline x86-64 path: `run_rows`' claim. Row by row for the metric (cached and
    /// formed G2 / (4 cos θo), with and without a diffuse lobe), the plain and the reweighted
    /// sums and the bin medians, on an eighth of a GGX-with-diffuse grid.
    #[test]
    fn vector_and_baseline_paths_agree_bitwise() {
        let src = parse_analytic("ggx?alpha=0.25&f0=0.04&kd=0.3,0.1,0.05").unwrap();
        let set = IsoSamples::new(&src).diagonal(8);
        let model = crate::microfacet::MicrofacetBrdf::ideal(
            "m",
            crate::microfacet::Ndf::Analytic(crate::microfacet::AnalyticNdf::isotropic(
                crate::microfacet::NdfKind::Ggx,
                0.2,
            )),
        );
        let mut tables = IsoTables::new(&model).unwrap();
        tables.set_fresnel(&vec![[0.05, 0.04, 0.03]; THETA_D_RES]);
        tables.diffuse = [0.09, 0.03, 0.015];
        let mut specular = tables.clone();
        specular.diffuse = [0.0; 3];
        let ideals = set.ideals(&tables);
        // Each row's accumulator on both paths, as bits.
        fn rows<P: RowPass>(set: &IsoSamples, pass: &P, bits: impl Fn(&P::Acc) -> Vec<u64>) {
            for (p, &r) in set.rows.iter().enumerate() {
                let (mut fast, mut base) = (P::init(), P::init());
                run_rows(pass, &mut fast, &[r], p);
                run_rows_baseline(pass, &mut base, &[r], p);
                assert_eq!(bits(&fast), bits(&base), "row {r}");
            }
        }
        let error = |e: &f64| vec![e.to_bits()];
        for t in [&tables, &specular] {
            for cached in [Some(&ideals), None] {
                let pass = ErrorSum {
                    set: &set,
                    tables: t,
                    cached,
                };
                rows(&set, &pass, error);
            }
        }
        let sums = |s: &LinearSums| {
            let bins = s.bins.iter().flatten().flatten();
            bins.chain(s.diffuse.iter().flatten())
                .chain([&s.error])
                .map(|v| v.to_bits())
                .collect()
        };
        for l1 in [false, true] {
            let pass = WeightedRows {
                set: &set,
                tables: &tables,
                l1,
                ideals: &ideals,
            };
            rows(&set, &pass, sums);
        }
        let pass = BinMedians {
            set: &set,
            tables: &tables,
            ideals: &ideals,
            span: 1.0,
        };
        rows(&set, &pass, |h: &Vec<(usize, Box<Histograms>)>| {
            h.iter()
                .flat_map(|(i, h)| {
                    std::iter::once(*i as u64).chain(h.iter().flatten().map(|v| v.to_bits()))
                })
                .collect()
        });
    }

    /// The coarse rows hold every fourth φd bin of the full ones with its cosines and λ(φ): a
    /// model's F / ρd solve, its error and the refinement's bin medians on them equal those on
    /// the full rows with the other bins masked off. The same samples and geometry, summed in other lanes: equal to f32 rounding.
    #[test]
    fn coarse_rows_are_every_fourth_bin_of_the_full_ones() {
        let src = parse_analytic("beckmann?alpha=0.15&f0=0.04&kd=0.3,0.1,0.05").unwrap();
        let full = IsoSamples::new(&src).diagonal(4);
        let coarse = full.coarse();
        let d = &*full.data;
        // Full rows keep ln(1 + x) alone (x recovered from it, as the coarse rows' is).
        assert!(d.x.is_empty());
        let (mut log_x, mut valid) = (d.log_x.clone(), d.valid.clone());
        let mut count = vec![0u16; ROWS];
        for r in 0..ROWS {
            for k in 0..PADDED {
                let kept = k % COARSE_STRIDE == 0 && valid[r * PADDED + k];
                valid[r * PADDED + k] = kept;
                count[r] += kept as u16;
                for c in 0..3 {
                    if !kept {
                        log_x[(3 * r + c) * PADDED + k] = 0.0;
                    }
                }
            }
        }
        // Σ x over the kept bins: the full rows' sums over every fourth bin.
        let sum_x = d.sum_coarse_x.clone();
        let masked: IsoSamples = IsoSamples {
            rows: full.rows.clone(),
            count: full.rows.iter().map(|&r| count[r as usize] as usize).sum(),
            data: Arc::new(IsoData {
                slot: Vec::new(),
                log_x,
                x: Vec::new(),
                valid,
                sum_x,
                sum_coarse_x: Vec::new(),
                count,
                out_of_range: None,
            }),
        };
        assert_eq!(coarse.count, masked.count);
        // The geometry gathered: cos θi and G2 / (4 cos θo) bit for bit (the same f32 steps).
        let tables = IsoTables::new(&MicrofacetBrdf::ideal(
            "m",
            Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.4)),
        ))
        .unwrap();
        let (ideal_full, ideal_coarse) = (full.ideals(&tables), coarse.ideals(&tables));
        for (p, &r) in coarse.rows.iter().enumerate() {
            let r = r as usize;
            let q = full.rows.iter().position(|&f| f as usize == r).unwrap();
            let (mu_f, mu_c) = (full.data.mu_i(r), coarse.data.mu_i(r));
            for j in (0..COARSE_ROW).filter(|&j| coarse.data.valid(r)[j]) {
                let k = COARSE_STRIDE * j;
                assert_eq!(mu_c[j].to_bits(), mu_f[k].to_bits(), "row {r} bin {k}");
                let (a, b) = (ideal_coarse.row(p)[j], ideal_full.row(q)[k]);
                assert_eq!(a.to_bits(), b.to_bits(), "row {r} bin {k}");
            }
        }
        let share = coarse.count as f64 / full.count as f64;
        assert!((share - 0.25).abs() < 0.01, "{share}");
        for (kind, alpha) in [(NdfKind::Ggx, 0.1), (NdfKind::Beckmann, 0.3)] {
            let ndf = Ndf::Analytic(AnalyticNdf::isotropic(kind, alpha));
            let tables = IsoTables::new(&MicrofacetBrdf::ideal("m", ndf)).unwrap();
            let (fa, qa, ea) = coarse.fresnel_diffuse_and_error_sum(&tables, 1);
            let (fb, qb, eb) = masked.fresnel_diffuse_and_error_sum(&tables, 1);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.abs().max(b.abs()) + 1e-9;
            assert!(close(ea, eb), "{kind:?}: error {ea} vs {eb}");
            assert!(
                (0..3).all(|c| close(qa[c], qb[c])),
                "{kind:?}: {qa:?} vs {qb:?}"
            );
            for (j, (a, b)) in fa.iter().zip(&fb).enumerate() {
                assert!(
                    (0..3).all(|c| close(a[c], b[c])),
                    "{kind:?} θd bin {j}: {a:?} {b:?}"
                );
            }
            // The refinement's bin medians at that F and ρd: every sample's s* and weight are
            // the same f32 values, so the same buckets, summed in another order.
            let mut tables = tables;
            tables.set_fresnel(&fa);
            tables.diffuse = qa;
            let ha = coarse.bin_medians(&tables, &coarse.ideals(&tables), 2.0);
            let hb = masked.bin_medians(&tables, &masked.ideals(&tables), 2.0);
            let weight: f64 = ha.iter().flatten().sum();
            assert!(weight > 0.0, "{kind:?}: no weight");
            for (i, (a, b)) in ha.iter().zip(&hb).enumerate() {
                for (k, (&a, &b)) in a.iter().zip(b).enumerate() {
                    assert!(close(a, b), "{kind:?} θh bin {i} bucket {k}: {a} vs {b}");
                }
            }
        }
    }

    /// The diagonal subsample keeps about 1/stride of every θh bin's and every θd bin's rows:
    /// no per-bin unknown is left without samples (every `stride`-th row in order would drop
    /// the odd θd bins).
    #[test]
    fn diagonal_subsample_keeps_every_bin() {
        let src = parse_analytic("ggx?alpha=0.2&f0=0.5").unwrap();
        let all = IsoSamples::new(&src);
        // Rows per θh bin (`by_h`) or per θd bin.
        let per_bin = |set: &IsoSamples, by_h: bool| {
            let mut n = [0usize; THETA_D_RES];
            for &r in &set.rows {
                let r = r as usize;
                n[if by_h {
                    r / THETA_D_RES
                } else {
                    r % THETA_D_RES
                }] += 1;
            }
            n
        };
        for stride in [4, 8] {
            let sub = all.diagonal(stride);
            for by_h in [true, false] {
                let (a, s) = (per_bin(&all, by_h), per_bin(&sub, by_h));
                for b in 0..THETA_D_RES {
                    // ⌊n / stride⌋ or ⌈n / stride⌉ of a bin's n rows, when n ≥ stride.
                    if a[b] >= stride {
                        assert!(
                            s[b] + 1 >= a[b] / stride,
                            "stride {stride} bin {b}: {} of {}",
                            s[b],
                            a[b]
                        );
                        assert!(s[b] <= a[b].div_ceil(stride) + 1, "stride {stride} bin {b}");
                    }
                }
            }
            let share = sub.count as f64 / all.count as f64;
            assert!(
                (share * stride as f64 - 1.0).abs() < 0.05,
                "stride {stride}: {share}"
            );
        }
    }
}
