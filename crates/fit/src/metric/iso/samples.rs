//! Sets of a grid's rows: the coarse rows (every fourth φd bin), the searches' subsamples and
//! the diagonal pattern, copies of the rows they keep where a pass reads them many times.

use super::lanes::sum_f64;
use super::{CoarseSamples, IsoData, IsoSamples};
use crate::metric::fast_log::exp_m1;
use crate::metric::merl_geometry::{COARSE_STRIDE, ROW, ROWS};
use crate::model::merl_grid::THETA_D_RES;
use rayon::prelude::*;
use std::sync::Arc;

impl IsoSamples {
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
        let eps = 1.0 / full.scale;
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
                        *x = exp_m1(l) * eps;
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
            scale: full.scale,
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
    ///
    /// [`PADDED`]: super::PADDED
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
    pub(super) fn rows_of(data: Arc<IsoData<N, M, P>>) -> Self {
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
}

/// Whether row `r` (θd bin + 90 θh bin) has (θh bin + θd bin) ≡ 0 mod `stride` (a stride of 0
/// taken as 1).
fn on_diagonal(r: usize, stride: usize) -> bool {
    (r / THETA_D_RES + r % THETA_D_RES).is_multiple_of(stride.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::iso::PADDED;
    use crate::metric::iso_tables::IsoTables;
    use crate::metric::merl_geometry::COARSE_ROW;
    use crate::model::analytic::parse_analytic;
    use crate::model::brdf::Brdf;
    use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};

    /// The coarse rows hold every fourth φd bin of the full ones with its cosines and λ(φ): a
    /// model's F / ρd solve, its error and the refinement's bin medians on them equal those on
    /// the full rows with the other bins masked off. The same samples and geometry, summed in other lanes: equal to f32 rounding.
    #[test]
    fn coarse_rows_are_every_fourth_bin_of_the_full_ones() {
        let src = parse_analytic("beckmann?alpha=0.15&f0=0.04&kd=0.3,0.1,0.05").unwrap();
        let full = IsoSamples::new(&src.merl_table(), 1.0).diagonal(4);
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
                scale: d.scale,
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
        let all = IsoSamples::new(&src.merl_table(), 1.0);
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
