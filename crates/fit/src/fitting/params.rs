//! GGX and Beckmann parameters from an extracted NDF: by first absolute slope moments (the
//! paper) and by least squares in the space of the error metric.

use crate::fitting::optim::{brent_to, nelder_mead};
use crate::metric::grid::{
    GridSamples, fresnel_and_error, fresnel_average, fresnel_diffuse_and_error, microfacet_error,
    tables_error,
};
use crate::metric::iso_tables::IsoTables;
use crate::model::fresnel::{Fresnel, FresnelTable};
use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use crate::model::tabulated::TabulatedNdf;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Bounds of any fitted α.
pub const ALPHA_MIN: f64 = 1e-3;
/// The upper bound (`ALPHA_MIN` is the lower).
pub const ALPHA_MAX: f64 = 4.0;
/// Points of the isotropic least-squares search's coarse scan over [ln `ALPHA_MIN`,
/// ln `ALPHA_MAX`]: 0.76 apart in ln α, about half the width of the error's basin.
const COARSE_SCAN: usize = 12;
/// The α searches' tolerance in ln α, relative to max(|ln α|, 1): 0.02 % in α near α = 1, where
/// a tolerance relative to |ln α| alone vanished. (Absolute 2e-3 in ln α took 1–4 fewer of the
/// 30–40 evaluations, but the ground truth's α came back 0.03 % off instead of 0.005 %: the ±5 %
/// bracket of the final steps, [`refine_by_bracket`], skips a vertex of tiny predicted gain.)
const SEARCH_TOLERANCE: f64 = 2e-4;

/// E|x~ cos ψ + y~ sin ψ| of the tabulated slope distribution for ψ = 0, 45°, 90°, 135°.
fn abs_slope_moments(ndf: &TabulatedNdf) -> [f64; 4] {
    // E|·| = ∫∫ D(θ,φ) sin²θ |cos(φ − ψ)| dθ dφ  (tan θ · D cos θ · sin θ), midpoint in u = sqrt(θ/(π/2)).
    let nu = 2048;
    let nphi = if ndf.tables().nphi == 1 { 1 } else { 512 };
    let mut m = [0.0; 4];
    for a in 0..nu {
        let u = (a as f64 + 0.5) / nu as f64;
        let theta = u * u * FRAC_PI_2;
        let dtheta = PI * u / nu as f64;
        let radial = theta.sin().powi(2) * dtheta;
        if nphi == 1 {
            // ∫₀^{2π} |cos(φ − ψ)| dφ = 4
            let v = 4.0 * ndf.base_d(theta, 0.0) * radial;
            m.iter_mut().for_each(|x| *x += v);
            continue;
        }
        for b in 0..nphi {
            let phi = (b as f64 + 0.5) / nphi as f64 * 2.0 * PI;
            let v = ndf.base_d(theta, phi) * radial * 2.0 * PI / nphi as f64;
            for (k, x) in m.iter_mut().enumerate() {
                *x += v * (phi - k as f64 * PI / 4.0).cos().abs();
            }
        }
    }
    m
}

/// α by the first absolute slope moment along the principal axes.
///
/// For an elliptical slope distribution the moment along direction ψ is c · s(ψ) with
/// s(ψ)² = αx² cos²(ψ − ρ) + αy² sin²(ψ − ρ) = A + B cos 2(ψ − ρ); four directions give A, B and ρ.
pub fn fit_moments(kind: NdfKind, ndf: &TabulatedNdf) -> AnalyticNdf {
    let m = abs_slope_moments(ndf).map(|x| x * x);
    let a = m.iter().sum::<f64>() / 4.0;
    let (bc, bs) = ((m[0] - m[2]) / 2.0, (m[1] - m[3]) / 2.0);
    let b = bc.hypot(bs);
    let rotation = if b > 1e-9 * a {
        0.5 * bs.atan2(bc)
    } else {
        0.0
    };
    let alpha = |s2: f64| {
        kind.alpha_from_abs_slope_moment(s2.max(0.0).sqrt())
            .clamp(ALPHA_MIN, ALPHA_MAX)
    };
    let (alpha_x, alpha_y) = (alpha(a + b), alpha(a - b));
    if ndf.tables().nphi == 1 {
        return AnalyticNdf::isotropic(kind, alpha_x);
    }
    canonical(AnalyticNdf {
        kind,
        alpha_x,
        alpha_y,
        rotation,
    })
}

/// A parametric model together with the Fresnel table averaged for it.
pub fn model_with_fresnel(name: &str, ndf: AnalyticNdf, set: &GridSamples) -> MicrofacetBrdf {
    let mut model = MicrofacetBrdf::ideal(name, Ndf::Analytic(ndf));
    model.fresnel = Fresnel::Table(FresnelTable::on_merl_bins(fresnel_average(&model, set)));
    model
}

/// The error of a parametric model whose Fresnel is re-averaged for it, or with `diffuse`
/// whose F and ρd are solved for it ([`fresnel_diffuse_and_error`], isotropic sets).
fn error_of(name: &str, ndf: AnalyticNdf, diffuse: bool, set: &GridSamples) -> f64 {
    let model = MicrofacetBrdf::ideal(name, Ndf::Analytic(ndf));
    if diffuse && let Some((_, _, e)) = fresnel_diffuse_and_error(&model, set, 0) {
        return e;
    }
    match IsoTables::new(&model).filter(|_| set.rotations.len() == 1) {
        Some(_) if set.iso.is_some() => fresnel_and_error(&model, set).1,
        Some(mut tables) => {
            let f = tables.fresnel_average(set);
            tables.set_fresnel(&f);
            tables_error(&tables, set)
        }
        None => microfacet_error(&model_with_fresnel(name, ndf, set), set),
    }
}

/// The minima of the error metric over isotropic α on `set` found by Brent's method on ln α
/// from two brackets: around `start` (ln α − 3 to ln α + 1.5), and around the best point of a
/// coarse scan of the whole range of ln α. The start (the slope moments) can lie far from the
/// metric's minimum: haze or a diffuse term in the extraction's tails put the moments' α a
/// hundred times above a sharp lobe's (specular-violet-phenolic: 0.84 against 0.006), outside
/// a bracket around it; on a flat, bumpy error (rough materials) the two may settle in
/// neighbouring dips. One candidate when both agree; the caller picks on a finer set.
pub fn least_squares_candidates(
    start: AnalyticNdf,
    diffuse: bool,
    set: &GridSamples,
) -> Vec<AnalyticNdf> {
    candidates_of(start, |n| error_of("lsq", n, diffuse, set))
}

/// [`least_squares_candidates`] for any error function of the isotropic NDF (the fit's: on
/// every fourth φd bin of the search's rows, [`crate::metric::grid::CoarseGrid::error`]).
pub(crate) fn candidates_of(
    start: AnalyticNdf,
    error: impl Fn(AnalyticNdf) -> f64,
) -> Vec<AnalyticNdf> {
    let kind = start.kind;
    let f = |t: f64| error(AnalyticNdf::isotropic(kind, t.exp()));
    let (lo, hi) = (ALPHA_MIN.ln(), ALPHA_MAX.ln());
    let x0 = start.alpha_x.clamp(ALPHA_MIN, ALPHA_MAX).ln();
    let tol = |t: f64| SEARCH_TOLERANCE * t.abs().max(1.0);
    let local = brent_to(f, (x0 - 3.0).max(lo), x0, (x0 + 1.5).min(hi), tol);
    let step = (hi - lo) / (COARSE_SCAN - 1) as f64;
    let (_, x) = (0..COARSE_SCAN)
        .map(|k| lo + step * k as f64)
        .map(|t| (f(t), t))
        .fold((f64::INFINITY, x0), |b, p| if p.0 < b.0 { p } else { b });
    let global = brent_to(f, (x - step).max(lo), x, (x + step).min(hi), tol);
    let mut out = vec![AnalyticNdf::isotropic(kind, local.exp())];
    // Two minima closer than a few tolerances are one.
    if (global - local).abs() > 5.0 * SEARCH_TOLERANCE {
        out.push(AnalyticNdf::isotropic(kind, global.exp()));
    }
    out
}

/// α (and rotation when anisotropic) minimising the error metric on `set`, from `start`.
/// Isotropic: the better on `set` of [`least_squares_candidates`]. Anisotropic: Nelder–Mead
/// on (ln αx, ln αy, ρ) from the better of `start` and the isotropic candidates. With
/// `diffuse`, each candidate's F and ρd are solved for it ([`crate::fitting::diffuse`]).
pub fn fit_least_squares(
    start: AnalyticNdf,
    anisotropic: bool,
    diffuse: bool,
    set: &GridSamples,
) -> AnalyticNdf {
    let kind = start.kind;
    if !anisotropic {
        let candidates = least_squares_candidates(start, diffuse, set);
        let error = |n: &AnalyticNdf| error_of("lsq", *n, diffuse, set);
        return match candidates[..] {
            [a, b] if error(&b) < error(&a) => b,
            _ => candidates[0],
        };
    }
    let make = |p: &[f64; 3]| AnalyticNdf {
        kind,
        alpha_x: p[0].exp().clamp(ALPHA_MIN, ALPHA_MAX),
        alpha_y: p[1].exp().clamp(ALPHA_MIN, ALPHA_MAX),
        rotation: p[2],
    };
    // Beyond the α bounds the clamp makes the error flat: the excess in ln α scales it up, so
    // that a simplex that strays there comes back.
    let (lo, hi) = (ALPHA_MIN.ln(), ALPHA_MAX.ln());
    let excess = |t: f64| (lo - t).max(0.0) + (t - hi).max(0.0);
    let error =
        |p: &[f64; 3]| error_of("lsq", make(p), diffuse, set) * (1.0 + excess(p[0]) + excess(p[1]));
    // The simplex starts from the better of the moments and the isotropic search's minimum. A
    // lobe over an unmodelled diffuse term has moments far from the minimum (Beckmann on GGX
    // 0.01 / 0.02 over ρd 0.5: from the moments the simplex ended at αx = 4, error 0.27,
    // against 0.17 for the best isotropic α).
    let p_of = |n: &AnalyticNdf| [n.alpha_x.ln(), n.alpha_y.ln(), n.rotation];
    let mean = AnalyticNdf::isotropic(kind, (start.alpha_x * start.alpha_y).sqrt());
    let p0 = least_squares_candidates(mean, diffuse, set)
        .iter()
        .map(p_of)
        .chain([p_of(&start)])
        .map(|p| (error(&p), p))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, p)| p)
        .expect("the moments' start");
    let p = nelder_mead(error, p0, [0.3, 0.3, 0.3], 1e-5, 200);
    canonical(make(&p))
}

/// The final steps of an isotropic least-squares fit, from the search's candidates
/// ln α ∈ `starts` ([`least_squares_candidates`]): `error(t)` is the error at ln α = t with the
/// model's own Fresnel table (and ρd) on the bracket's rows, finer than the search's (the fit
/// uses the final steps' rows with every fourth φd bin, [`crate::metric::grid::GridSamples::coarse`]).
/// Each start is evaluated and the lowest, t0, kept; ln α is evaluated at t0 ± h, the bracket
/// moved by h towards the lower side (at most `MOVES` times) until its centre is lowest, then
/// the parabola's vertex through the three points; the lowest point evaluated wins. Returns
/// (t, error, payload) of that point. The error near its minimum is close to a parabola in
/// ln α, and the search's subsampled grid puts its minimum within a few percent of the finer
/// rows' (`examples/fit_timing.rs` sweeps it), so one bracket of h = 0.05 (5 % in α) and one
/// vertex usually suffice: four evaluations.
pub fn refine_by_bracket<F, E>(
    starts: &[f64],
    mut error: impl FnMut(f64) -> Result<(f64, F), E>,
) -> Result<(f64, f64, F), E> {
    const H: f64 = 0.05;
    const MOVES: usize = 8;
    let (lo, hi) = (ALPHA_MIN.ln(), ALPHA_MAX.ln());
    let mut best: Option<(f64, f64, F)> = None;
    let mut eval = |t: f64, best: &mut Option<(f64, f64, F)>| -> Result<f64, E> {
        let (e, f) = error(t)?;
        if best.as_ref().is_none_or(|b| e < b.1) {
            *best = Some((t, e, f));
        }
        Ok(e)
    };
    debug_assert!(!starts.is_empty(), "a start to refine");
    let (mut c, mut ec) = (f64::NAN, f64::INFINITY);
    for &t in starts {
        let t = t.clamp(lo + H, hi - H);
        let e = eval(t, &mut best)?;
        if c.is_nan() || e < ec {
            (c, ec) = (t, e);
        }
    }
    let (mut em, mut ep) = (eval(c - H, &mut best)?, eval(c + H, &mut best)?);
    for _ in 0..MOVES {
        if ec <= em && ec <= ep {
            break;
        }
        // Move towards the lower neighbour; the old centre becomes the far point.
        if em < ep && c - 2.0 * H >= lo {
            (c, ep, ec) = (c - H, ec, em);
            em = eval(c - H, &mut best)?;
        } else if ep <= em && c + 2.0 * H <= hi {
            (c, em, ec) = (c + H, ec, ep);
            ep = eval(c + H, &mut best)?;
        } else {
            break;
        }
    }
    // Vertex of the parabola through (c − h, em), (c, ec), (c + h, ep).
    let curvature = em - 2.0 * ec + ep;
    if curvature > 0.0 && ec <= em && ec <= ep {
        let v = c + 0.5 * H * (em - ep) / curvature;
        // The parabola's predicted gain at v: (em − ep)² / (8 curvature).
        let gain = (em - ep).powi(2) / (8.0 * curvature);
        if (v - c).abs() > 1e-4 && gain > 1e-4 * ec {
            eval(v, &mut best)?;
        }
    }
    Ok(best.expect("at least one evaluation"))
}

/// The canonical form of an anisotropic NDF: ρ ∈ (−π/4, π/4]. ρ and ρ + π are one NDF, and so
/// are (αx, αy, ρ) and (αy, αx, ρ + π/2): the axis nearer the tangent is called x.
fn canonical(mut n: AnalyticNdf) -> AnalyticNdf {
    let mut r = n.rotation.rem_euclid(PI); // [0, π)
    if r > FRAC_PI_2 {
        r -= PI; // (−π/2, π/2]
    }
    if r > FRAC_PI_4 || r <= -FRAC_PI_4 {
        std::mem::swap(&mut n.alpha_x, &mut n.alpha_y);
        r -= FRAC_PI_2.copysign(r);
    }
    n.rotation = r;
    n
}
