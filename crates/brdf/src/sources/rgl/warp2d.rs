//! The marginal-conditional 2D warp of Dupuy & Jakob 2018 (Mitsuba 3's `Marginal2D`,
//! brdf-loader's `Warp2D*`): a bilinearly interpolated density on the unit square, sampled by
//! inversion (a marginal over rows, then a conditional over columns), optionally depending on
//! parameters between whose nodes it is interpolated linearly.
//!
//! The data of a warp with parameters of `n0, n1, …` nodes is an array `n0 × n1 × … × ny × nx`,
//! the last extent fastest; positions are `(x, y)` in [0, 1]², node `(i, j)` at
//! `(i / (nx − 1), j / (ny − 1))`. An interpolant ([`Warp2D::interpolant`]) returns the raw
//! values; a distribution ([`Warp2D::distribution`]) is normalised per parameter slice and can
//! be sampled and inverted. The arithmetic follows the format's reference code step by step, so
//! that a `.bsdf` evaluates here as it does in Mitsuba (in f64 rather than f32).

/// Sample bounds of the reference code: f32's largest value below one.
const ONE_MINUS_EPSILON: f64 = 0.999_999_940_395_355_2;

/// A 2D warp or interpolant with linear dependence on up to 3 parameters.
#[derive(Clone, Debug)]
pub struct Warp2D {
    /// Columns and rows.
    size: [usize; 2],
    /// The nodes of each parameter.
    params: Vec<Vec<f64>>,
    /// Slice stride of each parameter (0 when it has a single node).
    strides: Vec<usize>,
    /// Values, scaled so that [`Warp2D::eval`] returns the density (or the raw value).
    data: Vec<f64>,
    /// Per slice, the CDF over rows (empty for an interpolant).
    marginal: Vec<f64>,
    /// Per slice and row, the CDF over columns (empty for an interpolant).
    conditional: Vec<f64>,
}

/// Parameter slices and their weights for one query (at most 2³ corners).
struct Corners {
    slice: [usize; 8],
    weight: [f64; 8],
    n: usize,
}

impl Warp2D {
    /// Raw bilinear interpolation of `data` (`eval` returns the values themselves).
    pub fn interpolant(
        size: [usize; 2],
        data: &[f64],
        params: Vec<Vec<f64>>,
    ) -> Result<Self, String> {
        let mut w = Self::layout(size, data, params)?;
        if data.iter().any(|v| !v.is_finite()) {
            return Err("a value is not finite".into());
        }
        w.data = data.to_vec();
        Ok(w)
    }

    /// A density proportional to `data`, normalised per parameter slice, with the CDFs for
    /// [`Warp2D::sample`] and [`Warp2D::invert`]. Values must be finite and non-negative, and
    /// every slice must have some mass.
    pub fn distribution(
        size: [usize; 2],
        data: &[f64],
        params: Vec<Vec<f64>>,
    ) -> Result<Self, String> {
        let mut w = Self::layout(size, data, params)?;
        if let Some(i) = data.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(format!("value {i} ({}) is not a finite density", data[i]));
        }
        let [nx, ny] = size;
        let slices = data.len() / (nx * ny);
        w.marginal = vec![0.0; slices * ny];
        w.conditional = vec![0.0; slices * nx * ny];
        w.data = vec![0.0; data.len()];
        for s in 0..slices {
            let d = &data[s * nx * ny..(s + 1) * nx * ny];
            let cond = &mut w.conditional[s * nx * ny..(s + 1) * nx * ny];
            for y in 0..ny {
                let mut sum = 0.0;
                for x in 0..nx - 1 {
                    sum += 0.5 * (d[y * nx + x] + d[y * nx + x + 1]);
                    cond[y * nx + x + 1] = sum;
                }
            }
            let marg = &mut w.marginal[s * ny..(s + 1) * ny];
            let mut sum = 0.0;
            for y in 0..ny - 1 {
                sum += 0.5 * (cond[(y + 1) * nx - 1] + cond[(y + 2) * nx - 1]);
                marg[y + 1] = sum;
            }
            if !(sum > 0.0) {
                return Err(format!("parameter slice {s} has no mass"));
            }
            let norm = 1.0 / sum;
            cond.iter_mut().for_each(|c| *c *= norm);
            marg.iter_mut().for_each(|m| *m *= norm);
            for (o, v) in w.data[s * nx * ny..].iter_mut().zip(d) {
                *o = v * norm;
            }
        }
        Ok(w)
    }

    /// Checks the shapes and sets up the parameter strides.
    fn layout(size: [usize; 2], data: &[f64], params: Vec<Vec<f64>>) -> Result<Self, String> {
        if size[0] < 2 || size[1] < 2 {
            return Err(format!("a {} × {} grid (at least 2 × 2)", size[0], size[1]));
        }
        if params.len() > 3 {
            return Err("more than 3 parameters".into());
        }
        let mut strides = vec![0; params.len()];
        let mut slices = 1usize;
        for (d, nodes) in params.iter().enumerate().rev() {
            if nodes.is_empty() {
                return Err(format!("parameter {d} has no node"));
            }
            if nodes.iter().any(|v| !v.is_finite()) || nodes.windows(2).any(|w| w[0] >= w[1]) {
                return Err(format!("the nodes of parameter {d} do not increase"));
            }
            strides[d] = if nodes.len() > 1 { slices } else { 0 };
            slices *= nodes.len();
        }
        let want = slices * size[0] * size[1];
        if data.len() != want {
            return Err(format!(
                "{} values where the shape needs {want}",
                data.len()
            ));
        }
        Ok(Warp2D {
            size,
            params,
            strides,
            data: Vec::new(),
            marginal: Vec::new(),
            conditional: Vec::new(),
        })
    }

    /// Columns and rows.
    pub fn size(&self) -> [usize; 2] {
        self.size
    }

    /// The nodes of each parameter (the first varies slowest in [`Warp2D::data`]).
    pub fn params(&self) -> &[Vec<f64>] {
        &self.params
    }

    /// The values, `n0 × n1 × … × ny × nx` with the last extent fastest: raw for an
    /// interpolant, normalised per slice (densities over index units) for a distribution.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// Per parameter slice, the CDF over rows at the `ny` row nodes (empty for an interpolant).
    pub fn marginal(&self) -> &[f64] {
        &self.marginal
    }

    /// Per parameter slice and row, the CDF over columns at the `nx` column nodes, each row
    /// ending at that row's mass (empty for an interpolant).
    pub fn conditional(&self) -> &[f64] {
        &self.conditional
    }

    /// Whether this is a distribution (it can be sampled and inverted).
    pub fn is_distribution(&self) -> bool {
        !self.marginal.is_empty()
    }

    fn corners(&self, param: &[f64]) -> Corners {
        debug_assert_eq!(param.len(), self.params.len());
        let mut c = Corners {
            slice: [0; 8],
            weight: [0.0; 8],
            n: 1,
        };
        c.weight[0] = 1.0;
        for (d, nodes) in self.params.iter().enumerate() {
            if nodes.len() == 1 {
                continue;
            }
            let i = find_interval(nodes.len(), |k| nodes[k] <= param[d]);
            let w1 = ((param[d] - nodes[i]) / (nodes[i + 1] - nodes[i])).clamp(0.0, 1.0);
            for k in 0..c.n {
                c.slice[k + c.n] = c.slice[k] + (i + 1) * self.strides[d];
                c.weight[k + c.n] = c.weight[k] * w1;
                c.slice[k] += i * self.strides[d];
                c.weight[k] *= 1.0 - w1;
            }
            c.n *= 2;
        }
        c
    }

    /// Σ over the corners of weight × `array[slice · unit + i]`.
    fn lookup(array: &[f64], c: &Corners, unit: usize, i: usize) -> f64 {
        (0..c.n)
            .map(|k| c.weight[k] * array[c.slice[k] * unit + i])
            .sum()
    }

    /// Cells of a unit-square position: the patch and the fraction inside it.
    fn patch(&self, pos: [f64; 2]) -> ([usize; 2], [f64; 2]) {
        let mut p = [0; 2];
        let mut f = [0.0; 2];
        for a in 0..2 {
            let s = pos[a].clamp(0.0, 1.0) * (self.size[a] - 1) as f64;
            p[a] = (s as usize).min(self.size[a] - 2);
            f[a] = s - p[a] as f64;
        }
        (p, f)
    }

    /// (nx − 1)(ny − 1): densities in index units to the unit square.
    fn cells(&self) -> f64 {
        ((self.size[0] - 1) * (self.size[1] - 1)) as f64
    }

    /// The value (an interpolant) or density (a distribution) at `pos`.
    pub fn eval(&self, pos: [f64; 2], param: &[f64]) -> f64 {
        let c = self.corners(param);
        let ([px, py], [fx, fy]) = self.patch(pos);
        let nx = self.size[0];
        let unit = nx * self.size[1];
        let i = px + py * nx;
        let v = |k: usize| Self::lookup(&self.data, &c, unit, i + k);
        let (v00, v10, v01, v11) = (v(0), v(1), v(nx), v(nx + 1));
        let value = (1.0 - fy) * ((1.0 - fx) * v00 + fx * v10) + fy * ((1.0 - fx) * v01 + fx * v11);
        if self.marginal.is_empty() {
            value
        } else {
            value * self.cells()
        }
    }

    /// Warps a uniform `sample` to the distribution: the position and its density.
    pub fn sample(&self, sample: [f64; 2], param: &[f64]) -> ([f64; 2], f64) {
        debug_assert!(
            !self.marginal.is_empty(),
            "an interpolant cannot be sampled"
        );
        let [nx, ny] = self.size;
        let unit = nx * ny;
        let c = self.corners(param);
        let [mut sx, mut sy] = sample.map(|s| s.clamp(1.0 - ONE_MINUS_EPSILON, ONE_MINUS_EPSILON));
        let marg = |k: usize| Self::lookup(&self.marginal, &c, ny, k);
        let cond = |k: usize| Self::lookup(&self.conditional, &c, unit, k);
        // The row: the marginal CDF is piecewise quadratic between the row nodes.
        let row = find_interval(ny, |k| marg(k) < sy);
        sy -= marg(row);
        let offset = row * nx;
        let (r0, r1) = (cond(offset + nx - 1), cond(offset + 2 * nx - 1));
        sy = solve_linear_cdf(r0, r1, sy);
        // The column, in the row interpolated at that height.
        sx *= (1.0 - sy) * r0 + sy * r1;
        let cond_at = |k: usize| (1.0 - sy) * cond(offset + k) + sy * cond(offset + nx + k);
        let col = find_interval(nx, |k| cond_at(k) < sx);
        sx -= cond_at(col);
        let i = offset + col;
        let v = |k: usize| Self::lookup(&self.data, &c, unit, i + k);
        let c0 = (1.0 - sy) * v(0) + sy * v(nx);
        let c1 = (1.0 - sy) * v(1) + sy * v(nx + 1);
        sx = solve_linear_cdf(c0, c1, sx);
        let pos = [
            (col as f64 + sx) / (nx - 1) as f64,
            (row as f64 + sy) / (ny - 1) as f64,
        ];
        (pos, ((1.0 - sx) * c0 + sx * c1) * self.cells())
    }

    /// The inverse of [`Warp2D::sample`]: the uniform sample that maps to `pos`, and the
    /// density there.
    pub fn invert(&self, pos: [f64; 2], param: &[f64]) -> ([f64; 2], f64) {
        debug_assert!(
            !self.marginal.is_empty(),
            "an interpolant cannot be inverted"
        );
        let [nx, ny] = self.size;
        let unit = nx * ny;
        let c = self.corners(param);
        let ([px, py], [mut sx, mut sy]) = self.patch(pos);
        let i = px + py * nx;
        let v = |k: usize| Self::lookup(&self.data, &c, unit, i + k);
        let c0 = (1.0 - sy) * v(0) + sy * v(nx);
        let c1 = (1.0 - sy) * v(1) + sy * v(nx + 1);
        let pdf = (1.0 - sx) * c0 + sx * c1;
        let cond = |k: usize| Self::lookup(&self.conditional, &c, unit, k);
        // ∫₀ˣ of the linear c0 → c1, plus the row's CDF before the cell, over the row's total.
        sx *= c0 + 0.5 * sx * (c1 - c0);
        sx += (1.0 - sy) * cond(i) + sy * cond(i + nx);
        let row = py * nx;
        let (r0, r1) = (cond(row + nx - 1), cond(row + 2 * nx - 1));
        let total = (1.0 - sy) * r0 + sy * r1;
        sx = if total > 0.0 { sx / total } else { 0.0 };
        sy *= r0 + 0.5 * sy * (r1 - r0);
        sy += Self::lookup(&self.marginal, &c, ny, py);
        ([sx, sy], pdf * self.cells())
    }
}

/// The t ∈ [0, 1] where ∫₀ᵗ of the linear density a → b equals `s` (a and b in the same
/// units as `s`): the root of (b − a) t² / 2 + a t = s, by the reference code's formula.
fn solve_linear_cdf(a: f64, b: f64, s: f64) -> f64 {
    if (a - b).abs() < 1e-4 * (a + b) {
        if a + b > 0.0 { 2.0 * s / (a + b) } else { 0.5 }
    } else {
        (a - (a * a - 2.0 * s * (a - b)).max(0.0).sqrt()) / (a - b)
    }
}

/// The index i in [0, size − 2] with `pred(i)` true and `pred(i + 1)` false, for a predicate
/// that is true on a prefix (0 when it holds nowhere, size − 2 when everywhere).
pub(crate) fn find_interval(size: usize, pred: impl Fn(usize) -> bool) -> usize {
    let (mut first, mut len) = (1usize, size.saturating_sub(2));
    while len > 0 {
        let half = len / 2;
        let middle = first + half;
        if pred(middle) {
            first = middle + 1;
            len -= half + 1;
        } else {
            len = half;
        }
    }
    (first - 1).min(size.saturating_sub(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A lumpy density on a 5 × 4 grid with 2 × 3 parameter slices.
    fn lumpy() -> Warp2D {
        let data: Vec<f64> = (0..2 * 3 * 4 * 5)
            .map(|i| 0.2 + ((i * 37 % 11) as f64) / 3.0)
            .collect();
        Warp2D::distribution([5, 4], &data, vec![vec![0.0, 1.0], vec![-1.0, 0.5, 2.0]]).unwrap()
    }

    #[test]
    fn invert_undoes_sample_and_the_densities_agree() {
        let w = lumpy();
        for k in 0..400 {
            let u = [
                (k as f64 * 0.618_034).fract(),
                (k as f64 * 0.754_878).fract(),
            ];
            let param = [
                (k as f64 * 0.1).fract(),
                -1.0 + 3.0 * (k as f64 * 0.37).fract(),
            ];
            let (pos, pdf) = w.sample(u, &param);
            let (back, pdf2) = w.invert(pos, &param);
            let uc = u.map(|s| s.clamp(1.0 - ONE_MINUS_EPSILON, ONE_MINUS_EPSILON));
            assert!(
                (back[0] - uc[0]).abs() < 1e-9 && (back[1] - uc[1]).abs() < 1e-9,
                "{u:?} → {pos:?} → {back:?}"
            );
            assert!((pdf - pdf2).abs() < 1e-9 * pdf);
            assert!((w.eval(pos, &param) - pdf).abs() < 1e-9 * pdf);
        }
    }

    #[test]
    fn a_distribution_integrates_to_one_in_every_slice() {
        let w = lumpy();
        // A multiple of both cell counts, so that no midpoint cell straddles a kink.
        let n = 240;
        for param in [[0.0, -1.0], [1.0, 2.0], [0.3, 0.1]] {
            // Bilinear in each cell: the midpoint rule on a grid aligned with the cells is exact.
            let sum: f64 = (0..n * n)
                .map(|i| {
                    let p = [
                        ((i % n) as f64 + 0.5) / n as f64,
                        ((i / n) as f64 + 0.5) / n as f64,
                    ];
                    w.eval(p, &param)
                })
                .sum::<f64>()
                / (n * n) as f64;
            assert!((sum - 1.0).abs() < 1e-9, "{param:?}: {sum}");
        }
    }

    #[test]
    fn an_interpolant_returns_its_nodes() {
        let data: Vec<f64> = (0..12).map(f64::from).collect();
        let w = Warp2D::interpolant([4, 3], &data, vec![]).unwrap();
        assert_eq!(w.eval([1.0 / 3.0, 0.5], &[]), 5.0);
        // Linear data: the bilinear interpolant is exact between nodes.
        assert_eq!(w.eval([0.5, 0.25], &[]), 1.5 + 4.0 * 0.5);
    }

    #[test]
    fn bad_shapes_and_values_are_named() {
        assert!(Warp2D::interpolant([1, 3], &[0.0; 3], vec![]).is_err());
        assert!(
            Warp2D::distribution([2, 2], &[0.0; 4], vec![])
                .unwrap_err()
                .contains("no mass")
        );
        assert!(Warp2D::distribution([2, 2], &[1.0, -1.0, 1.0, 1.0], vec![]).is_err());
        assert!(
            Warp2D::interpolant([2, 2], &[0.0; 8], vec![vec![1.0, 1.0]])
                .unwrap_err()
                .contains("increase")
        );
        assert!(
            Warp2D::interpolant([2, 2], &[0.0; 5], vec![])
                .unwrap_err()
                .contains("5 values")
        );
    }

    #[test]
    fn find_interval_brackets() {
        let nodes = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(find_interval(4, |k| nodes[k] <= -1.0), 0);
        assert_eq!(find_interval(4, |k| nodes[k] <= 1.5), 1);
        assert_eq!(find_interval(4, |k| nodes[k] <= 9.0), 2);
    }
}
