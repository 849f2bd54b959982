//! F per θd bin and ρd/π solved for a model's D and G: the plain weighted least-squares
//! solve (a pass, or O(rows) from the rows' cached sums), the steps of iteratively reweighted
//! least squares towards the metric's L1 minimum, and the error of the best.

use super::error::ErrorSum;
use super::lanes::{lanes_total, valid_chunks};
use super::rows::{RowFill, RowPass};
use super::{IsoData, IsoSamples, RowIdeals, RowSums};
use crate::metric::fast_log::ln_1p_fused;
use crate::metric::iso_tables::IsoTables;
use crate::metric::sums::LinearSums;
use crate::model::merl_grid::THETA_D_RES;
use crate::model::rgb::Rgb;

impl<const N: usize, const M: usize, const P: usize> IsoSamples<N, M, P> {
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

/// The weighted sums of the F / ρd solve (each row's G2 / (4 cos θo) given). Per bin
/// w = 1 / (1 + x)², m = D G2 / (4 cos θo) (0 where D ≤ 0), μ = cos θi. With `l1`, a step of
/// iteratively reweighted least squares for the metric's L1 norm: w is also divided by the
/// current model's |ln(1 + x_model) − ln(1 + x)| (at least `IRLS_FLOOR`; F and ρd/π from
/// `tables`), whose sum the pass gathers.
pub(super) struct WeightedRows<'a, const N: usize, const M: usize, const P: usize> {
    pub(super) set: &'a IsoSamples<N, M, P>,
    pub(super) tables: &'a IsoTables,
    pub(super) l1: bool,
    pub(super) ideals: &'a RowIdeals<P>,
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
        // F D and ρd/π in the metric's space (x/ε)
        let sc = self.set.data.scale;
        let l1 = self.l1.then(|| {
            let fd = t.fresnel[j].map(|f| f as f32 * d * sc);
            (fd, t.diffuse.map(|k| k as f32 * sc))
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
/// `error::row_error` gives it) is returned too.
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
                let s = plain_channel(&m, &mu_i, &data.x(r, c), data.scale, &mut terms);
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
                let l1 = L1Model {
                    fd: fd[c],
                    kd: kd[c],
                    scale: data.scale,
                };
                let (s, e) = l1_channel(&m, &mu_i, &x, log_x, l1, &chunks);
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
    scale: f32,
    t: &mut [[f32; P]; 5],
) -> [[f32; 8]; 5] {
    let mut s = [[0.0f32; 8]; 5];
    for k in 0..P {
        // w = 1 / (1 + x/ε)² (d ln(1 + x/ε) = (dx/ε) / (1 + x/ε); the constant 1/ε² dropped)
        let y = scale.mul_add(x[k], 1.0);
        let w = 1.0 / (y * y);
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

/// The model of one channel of an L1 step: F D / ε of the row, ρd/(π ε), and 1/ε itself.
#[derive(Clone, Copy)]
struct L1Model {
    fd: f32,
    kd: f32,
    scale: f32,
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
    model: L1Model,
    chunks: &std::ops::Range<usize>,
) -> ([[f32; 8]; 5], [f32; 8]) {
    let L1Model { fd: f, kd, scale } = model;
    let (mut s, mut e) = ([[0.0f32; 8]; 5], [0.0f32; 8]);
    for n in 0..P / 8 {
        // (Chunks without a valid bin add 0: ι = μ = x = ln(1 + x) = 0 there.)
        if !chunks.contains(&n) {
            continue;
        }
        for l in 0..8 {
            let k = 8 * n + l;
            // x_model/ε = F D/ε (G2 / (4 cos θo)) + ρd/(π ε) cos θi
            let res = (ln_1p_fused(f.mul_add(m[k], kd * mu_i[k])) - log_x[k]).abs();
            e[l] += res;
            // w = 1 / (1 + x/ε)² over the residual (at least the floor): one division
            let y = scale.mul_add(x[k], 1.0);
            let w = 1.0 / (res.max(IRLS_FLOOR) * y * y);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::analytic::parse_analytic;
    use crate::model::brdf::Brdf;

    /// The plain normal equations from the rows' cached sums are the pass's: the same per-row
    /// sums ([`weighted_row`]) added in another order, so equal to f64 rounding (1e-12).
    #[test]
    fn cached_row_sums_give_the_pass_sums() {
        let src = parse_analytic("ggx?alpha=0.3&f0=0.04&kd=0.3,0.1,0.05").unwrap();
        let set = IsoSamples::new(&src.merl_table(), 1.0).diagonal(4);
        let model = crate::model::microfacet::MicrofacetBrdf::ideal(
            "m",
            crate::model::microfacet::Ndf::Analytic(
                crate::model::microfacet::AnalyticNdf::isotropic(
                    crate::model::microfacet::NdfKind::Beckmann,
                    0.2,
                ),
            ),
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
}
