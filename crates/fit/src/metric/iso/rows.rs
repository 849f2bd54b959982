//! The engine of every pass: a pass is a [`RowPass`] (an accumulator and what a row adds to
//! it), run over a set's rows with rayon over θh bins, each bin's rows compiled for AVX-512 or
//! AVX2 with FMA where the CPU has them ([`run_rows`]); [`RowFill`] writes a value per row.

use super::IsoSamples;
use crate::model::merl_grid::{THETA_D_RES, THETA_H_RES};
use rayon::prelude::*;

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
    /// `out[p]` = the value of the `p`-th row of this set: rayon over θh bins, each bin's rows
    /// vectorised as the passes are ([`run_rows`]).
    pub(super) fn fill_rows<F: RowFill>(&self, out: &mut [F::Out], fill: &F) {
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

    /// A pass over this set's rows, a θh bin's rows per task. The bins' accumulators merge in
    /// bin order, so the result does not depend on how the tasks were scheduled: a fit is the
    /// same, bit for bit, run to run.
    pub(super) fn run<R: RowPass>(&self, pass: &R) -> R::Acc {
        let bounds = self.bin_bounds();
        let per_bin: Vec<R::Acc> = (0..THETA_H_RES)
            .into_par_iter()
            .map(|i| {
                let mut acc = R::init();
                let rows = &self.rows[bounds[i]..bounds[i + 1]];
                run_rows(pass, &mut acc, rows, bounds[i]);
                acc
            })
            .collect();
        per_bin.into_iter().fold(R::init(), |mut a, b| {
            R::merge(&mut a, b);
            a
        })
    }
}

/// A pass: an accumulator, what one row adds to it, how two merge.
pub(super) trait RowPass: Sync {
    type Acc: Send;
    fn init() -> Self::Acc;
    /// Adds row `r`, the `p`-th row of the set.
    fn row(&self, acc: &mut Self::Acc, r: usize, p: usize);
    fn merge(a: &mut Self::Acc, b: Self::Acc);
}

/// A value per row that [`IsoSamples::fill_rows`] writes. `fill` is inlined into the
/// vectorised row loop ([`run_rows`]); a closure there would be called out of line, compiled
/// for the baseline target.
pub(super) trait RowFill: Sync {
    type Out: Send;
    /// The value of row `r`, the `p`-th of the set.
    fn fill(&self, r: usize, p: usize, out: &mut Self::Out);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::iso::error::ErrorSum;
    use crate::metric::iso::medians::{BinMedians, Histograms};
    use crate::metric::iso::solve::WeightedRows;
    use crate::metric::iso_tables::IsoTables;
    use crate::metric::sums::LinearSums;
    use crate::model::analytic::parse_analytic;
    use crate::model::brdf::Brdf;

    /// The passes give the same bits on the vector path the CPU takes (AVX2 + FMA here) and on
    /// the baseline x86-64 path: `run_rows`' claim. Row by row for the metric (cached and
    /// formed G2 / (4 cos θo), with and without a diffuse lobe), the plain and the reweighted
    /// sums and the bin medians, on an eighth of a GGX-with-diffuse grid.
    #[test]
    fn vector_and_baseline_paths_agree_bitwise() {
        let src = parse_analytic("ggx?alpha=0.25&f0=0.04&kd=0.3,0.1,0.05").unwrap();
        let set = IsoSamples::new(&src.merl_table(), 1.0).diagonal(8);
        let model = crate::model::microfacet::MicrofacetBrdf::ideal(
            "m",
            crate::model::microfacet::Ndf::Analytic(
                crate::model::microfacet::AnalyticNdf::isotropic(
                    crate::model::microfacet::NdfKind::Ggx,
                    0.2,
                ),
            ),
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
}
