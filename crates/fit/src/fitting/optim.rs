//! Minimisers of a few variables: Brent's method in one dimension (golden sections with
//! parabolic steps) and the Nelder–Mead simplex in three.

/// Brent's minimisation on [lo, hi] starting from `start` (Numerical Recipes `brent`, golden sections
/// with parabolic steps), to a relative tolerance `tol` in x.
pub(crate) fn brent(f: impl Fn(f64) -> f64, lo: f64, start: f64, hi: f64, tol: f64) -> f64 {
    brent_to(f, lo, start, hi, |x| tol * x.abs().max(1e-3))
}

/// [`brent`] to the tolerance `tol(x)` in x, absolute.
pub(crate) fn brent_to(
    f: impl Fn(f64) -> f64,
    lo: f64,
    start: f64,
    hi: f64,
    tol: impl Fn(f64) -> f64,
) -> f64 {
    const CGOLD: f64 = 0.381_966_011_250_105;
    let (mut a, mut b) = (lo.min(hi), lo.max(hi));
    let mut x = start.clamp(a, b);
    let mut fx = f(x);
    let (mut w, mut v) = (x, x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e): (f64, f64) = (0.0, 0.0);
    for _ in 0..100 {
        let xm = 0.5 * (a + b);
        let tol1 = tol(x);
        let tol2 = 2.0 * tol1;
        if (x - xm).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        if e.abs() > tol1 {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let etemp = e;
            e = d;
            if p.abs() >= (0.5 * q * etemp).abs() || p <= q * (a - x) || p >= q * (b - x) {
                e = if x >= xm { a - x } else { b - x };
                d = CGOLD * e;
            } else {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = tol1.copysign(xm - x);
                }
            }
        } else {
            e = if x >= xm { a - x } else { b - x };
            d = CGOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x
            } else {
                b = x
            }
            (v, w, x) = (w, x, u);
            (fv, fw, fx) = (fw, fx, fu);
        } else {
            if u < x {
                a = u
            } else {
                b = u
            }
            if fu <= fw || w == x {
                (v, w) = (w, u);
                (fv, fw) = (fw, fu);
            } else if fu <= fv || v == x || v == w {
                v = u;
                fv = fu;
            }
        }
    }
    x
}

/// Nelder–Mead simplex minimisation in 3-D.
pub(crate) fn nelder_mead(
    f: impl Fn(&[f64; 3]) -> f64,
    x0: [f64; 3],
    step: [f64; 3],
    tol: f64,
    max_evals: usize,
) -> [f64; 3] {
    let mut pts: Vec<([f64; 3], f64)> = (0..4)
        .map(|k| {
            let mut p = x0;
            if k > 0 {
                p[k - 1] += step[k - 1];
            }
            (p, f(&p))
        })
        .collect();
    let mut evals = 4;
    let lerp = |a: &[f64; 3], b: &[f64; 3], t: f64| -> [f64; 3] {
        std::array::from_fn(|i| a[i] + t * (b[i] - a[i]))
    };
    while evals < max_evals {
        pts.sort_by(|a, b| a.1.total_cmp(&b.1));
        if (pts[3].1 - pts[0].1).abs() <= tol * pts[0].1.abs().max(1e-12) {
            break;
        }
        let centroid: [f64; 3] =
            std::array::from_fn(|i| (pts[0].0[i] + pts[1].0[i] + pts[2].0[i]) / 3.0);
        let worst = pts[3];
        let reflect = lerp(&centroid, &worst.0, -1.0);
        let fr = f(&reflect);
        evals += 1;
        if fr < pts[0].1 {
            let expand = lerp(&centroid, &worst.0, -2.0);
            let fe = f(&expand);
            evals += 1;
            pts[3] = if fe < fr { (expand, fe) } else { (reflect, fr) };
        } else if fr < pts[2].1 {
            pts[3] = (reflect, fr);
        } else {
            let contract = lerp(&centroid, &worst.0, 0.5);
            let fc = f(&contract);
            evals += 1;
            if fc < worst.1 {
                pts[3] = (contract, fc);
            } else {
                let best = pts[0].0;
                for p in pts.iter_mut().skip(1) {
                    p.0 = lerp(&best, &p.0, 0.5);
                    p.1 = f(&p.0);
                    evals += 1;
                }
            }
        }
    }
    pts.sort_by(|a, b| a.1.total_cmp(&b.1));
    pts[0].0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brent_and_nelder_mead_find_minima() {
        let x = brent(|x| (x - 0.7).powi(2) + 1.0, -3.0, 0.0, 2.0, 1e-8);
        assert!((x - 0.7).abs() < 1e-6, "{x}");
        let p = nelder_mead(
            |p| (p[0] - 1.0).powi(2) + 2.0 * (p[1] + 0.5).powi(2) + (p[2] - 0.2).powi(2) + 1.0,
            [0.0; 3],
            [0.5; 3],
            1e-14,
            2000,
        );
        assert!(
            p.iter()
                .zip([1.0, -0.5, 0.2])
                .all(|(a, b)| (a - b).abs() < 1e-4),
            "{p:?}"
        );
    }
}
