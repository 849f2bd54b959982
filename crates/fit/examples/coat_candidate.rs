//! Issue 48's second candidate measured: a clear dielectric coat over the fitted base (in the
//! manner of Weidlich & Wilkie 2007), against today's single-layer fit, on a library of neural
//! proxies. The model:
//!
//!   f(ωi, ωo) = w F(η, ωi·h) D_c(h) G2_c / (4 cos θi cos θo) + T(θi) T(θo) f_base(ωi', ωo'),
//!
//! a colourless GGX coat lobe of roughness α_c, T = 1 − w F(η, cos θ) the transmission at each
//! crossing, ωi' and ωo' the directions refracted into a smooth interface of index η (so that
//! the base sees an angle that depends on θh as well as θd, which one NDF × F(θd) cannot do).
//! The base is fitted by today's pipeline to the data seen from inside the coat,
//! (f_data − coat lobe) / (T T) at the outside directions of each inside pair (pairs past the
//! critical angle have none and are missing); the error is the composite's, on the source's own
//! grid samples. η = 1.5; α_c from a few values, the best kept per material (the fit would
//! search it), and the coat's weight w (its reflectance w F, its transmission 1 − w F) from two.
//! A first look at what a coat buys, not the fit issue 48 asks for.
//!
//! `cargo run --release -p facet-fit --example coat_candidate -- [NBRDF.json] [NAME_FILTER]`

use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, error_metric};
use facet_fit::model::brdf::Brdf;
use facet_fit::model::fresnel::dielectric;
use facet_fit::model::geometry::azimuth_between;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::{AnalyticNdf, MicrofacetBrdf, NdfKind, correlation, g2};
use facet_fit::model::rgb::Rgb;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use glam::DVec3;
use std::path::Path;

/// The coat's index of refraction.
const ETA: f64 = 1.5;
/// The coat roughnesses tried.
const ALPHAS: [f64; 5] = [0.01, 0.03, 0.06, 0.1, 0.2];
/// The coat weights tried.
const WEIGHTS: [f64; 2] = [0.3, 1.0];

/// A clear coat: its GGX roughness and the weight of its Fresnel reflectance (η is [`ETA`]).
#[derive(Clone, Copy)]
struct Coat {
    alpha: f64,
    weight: f64,
}

impl Coat {
    /// The coat's own reflection: w F(η, ωi·h) D G2 / (4 cos θi cos θo).
    fn lobe(&self, wi: DVec3, wo: DVec3) -> f64 {
        let ndf = AnalyticNdf {
            kind: NdfKind::Ggx,
            alpha_x: self.alpha,
            alpha_y: self.alpha,
            rotation: 0.0,
        };
        let h = (wi + wo).normalize();
        let g = g2(
            ndf.lambda(wi),
            ndf.lambda(wo),
            correlation(azimuth_between(wi, wo)),
        );
        self.weight * dielectric(wi.dot(h), ETA) * ndf.d(h) * g / (4.0 * wi.z * wo.z)
    }

    /// T = 1 − w F(η, cos θ): what crosses the interface.
    fn transmission(&self, w: DVec3) -> f64 {
        1.0 - self.weight * dielectric(w.z, ETA)
    }
}

/// Into the coat: sin θ' = sin θ / η.
fn refract_in(w: DVec3) -> DVec3 {
    let s = w.truncate() / ETA;
    DVec3::new(s.x, s.y, (1.0 - s.length_squared()).max(0.0).sqrt())
}

/// Out of the coat; `None` past the critical angle.
fn refract_out(w: DVec3) -> Option<DVec3> {
    let s = w.truncate() * ETA;
    let c2 = 1.0 - s.length_squared();
    (c2 > 0.0 && w.z > 0.0).then(|| DVec3::new(s.x, s.y, c2.sqrt()))
}

/// The data as the base must be under the coat, at inside directions.
struct SeenFromInside<'a> {
    data: &'a dyn Brdf,
    coat: Coat,
}

impl Brdf for SeenFromInside<'_> {
    fn name(&self) -> &str {
        self.data.name()
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        let (i, o) = (refract_out(wi)?, refract_out(wo)?);
        let d = self.data.eval(i, o)?;
        let c = self.coat.lobe(i, o);
        let t = self.coat.transmission(i) * self.coat.transmission(o);
        Some(d.map(|v| ((v - c) / t).max(0.0)))
    }
}

/// The coat over a fitted base.
struct Coated {
    coat: Coat,
    base: MicrofacetBrdf,
}

impl Brdf for Coated {
    fn name(&self) -> &str {
        "coated"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let c = self.coat.lobe(wi, wo);
        let t = self.coat.transmission(wi) * self.coat.transmission(wo);
        let b = self.base.eval(refract_in(wi), refract_in(wo))?;
        Some(b.map(|v| c + t * v))
    }
}

/// The coated model's error with coat `coat` over a base fitted under it; `None` where the
/// data under the coat leave too little to fit.
fn coated_error(src: &MerlBrdf, set: &GridSamples, coat: Coat, cfg: &FitConfig) -> Option<f64> {
    let seen = SeenFromInside { data: src, coat };
    let under = MerlBrdf::from_table("under", MerlTable::sample(&seen)).ok()?;
    let base = fit_material(&under, "under", cfg).ok()?;
    Some(error_metric(
        &Coated {
            coat,
            base: base.tabulated,
        },
        set,
    ))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let lib = match args.first() {
        Some(p) => NbrdfLibrary::open(Path::new(p)).unwrap(),
        None => NbrdfLibrary::embedded(),
    };
    let filter = args.get(1).cloned().unwrap_or_default();
    let cfg = FitConfig::isotropic();
    let mut rows = Vec::new();
    for name in lib.names().filter(|n| n.contains(&filter)) {
        let src = MerlBrdf::from_table(name, MerlTable::sample(&lib.get(name).unwrap())).unwrap();
        let set = GridSamples::new(&src);
        let single = error_metric(&fit_material(&src, name, &cfg).unwrap().tabulated, &set);
        let coats = ALPHAS
            .iter()
            .flat_map(|&alpha| WEIGHTS.map(|weight| Coat { alpha, weight }));
        let best = coats
            .filter_map(|coat| Some((coated_error(&src, &set, coat, &cfg)?, coat)))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let Some((coated, coat)) = best else {
            println!("{name:<28} one layer {single:.4}  no coated fit");
            rows.push((single, single));
            continue;
        };
        println!(
            "{name:<28} one layer {single:.4}  coated {coated:.4} (α_c {}, weight {})  {:.3}×",
            coat.alpha,
            coat.weight,
            coated / single
        );
        rows.push((single, coated.min(single)));
    }
    let one: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let kept: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let improved = rows.iter().filter(|r| r.1 < r.0 * 0.999).count();
    println!(
        "one layer: median {:.4} p90 {:.4}; the coat kept where it helps: median {:.4} p90 {:.4}; kept by {improved} of {}",
        quantile(&one, 0.5),
        quantile(&one, 0.9),
        quantile(&kept, 0.5),
        quantile(&kept, 0.9),
        rows.len()
    );
}
