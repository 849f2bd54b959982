//! Issue 48's last candidate pair measured: a clear coat *and* per-channel NDFs ("or both").
//! Per material, on a library of neural proxies tabulated on the MERL grid as `facet fit` reads
//! a file, the error metric on the same grid samples of:
//!
//! - the single layer (today's default without the coat step);
//! - the coat step (`CoatSearch::Always`: the coat kept only where it lowers the error);
//! - shared coat, per-channel bases: the coat the search finds on the RGB data, and under it
//!   channel c of the source fitted as a grey material (its own NDF, Fresnel and diffuse), the
//!   composite's channel c from base c (a clear coat is colourless, so one coat for all three);
//! - with `--own-coats`, per-channel coats too: channel c fitted with its own coat step.
//!
//! `cargo run --release -p facet-fit --example coat_per_channel -- [NBRDF.json|-] [FILTER] [--own-coats]`

use facet_fit::fitting::coat::{COAT_ETA, GridPlaces, Scorer, fit_base, search};
use facet_fit::fitting::{CoatSearch, FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, error_metric};
use facet_fit::model::brdf::Brdf;
use facet_fit::model::coat::{CoatLayer, Coated};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::MicrofacetBrdf;
use facet_fit::model::rgb::Rgb;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;
use glam::DVec3;
use std::time::Instant;

mod common;
use common::{Channel, PerChannel};

/// The coated errors of one material: (coat step, shared coat with per-channel bases, own
/// coats per channel) and the milliseconds of the second.
fn errors(src: &MerlBrdf, cfg: &FitConfig, set: &GridSamples, own: bool) -> (f64, f64, f64, f64) {
    let always = FitConfig {
        coat: CoatSearch::Always,
        ..*cfg
    };
    let m = fit_material(src, src.name(), &always).unwrap();
    let step = m
        .record
        .coat
        .as_ref()
        .map_or(m.record.tabulated.error.unwrap(), |c| c.error);
    let t = Instant::now();
    let data = src.merl_table();
    let coat = search(&Scorer::new(src, &data, cfg, set));
    let layer = CoatLayer::new(coat).unwrap();
    let places = GridPlaces::on_demand(COAT_ETA);
    let bases: [MicrofacetBrdf; 3] = [0, 1, 2].map(|c| {
        let ch = Channel(src, c);
        let data_c = ch.merl_table();
        fit_base(&ch, &data_c, &layer, cfg, &places)
            .unwrap()
            .tabulated
    });
    let shared = error_metric(
        &PerChannel(bases.map(|base| Coated {
            layer: layer.clone(),
            base,
        })),
        set,
    );
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let own_coats = if own {
        let fits = [0, 1, 2].map(|c| fit_material(&Channel(src, c), src.name(), &always).unwrap());
        error_metric(&PerChannel(fits.map(OneOf)), set)
    } else {
        f64::NAN
    };
    (step, shared, own_coats, ms)
}

/// A fitted material as a model: the coated one where its coat step kept a coat, else its
/// tabulated single layer.
struct OneOf(facet_fit::model::material::FittedMaterial);

impl Brdf for OneOf {
    fn name(&self) -> &str {
        "fit"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        match &self.0.coated {
            Some(c) => Coated {
                layer: c.layer.clone(),
                base: c.base.tabulated.clone(),
            }
            .eval(wi, wo),
            None => self.0.tabulated.eval(wi, wo),
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let lib = common::library(args.first());
    let filter = args.get(1).cloned().unwrap_or_default();
    let own = args.iter().any(|a| a == "--own-coats");
    let cfg = FitConfig::isotropic();
    let mut rows = Vec::new();
    for name in lib.names().filter(|n| n.contains(&filter)) {
        let src = MerlBrdf::from_table(name, MerlTable::sample(&lib.get(name).unwrap())).unwrap();
        let set = GridSamples::new(&src);
        let single = fit_material(
            &src,
            name,
            &FitConfig {
                coat: CoatSearch::Off,
                ..cfg
            },
        )
        .unwrap();
        let single = error_metric(&single.tabulated, &set);
        let (step, shared, own_coats, ms) = errors(&src, &cfg, &set, own);
        println!(
            "{name:<28} single {single:.4}  coat step {step:.4} ({:.3}×)  shared coat, per-channel bases {shared:.4} ({:.3}×, {ms:.0} ms)  own coats {own_coats:.4} ({:.3}×)",
            step / single,
            shared / single,
            own_coats / single
        );
        rows.push((name.to_owned(), single, step, shared, own_coats));
    }
    rows.sort_by(|a, b| b.1.total_cmp(&a.1));
    let col = |f: fn(&(String, f64, f64, f64, f64)) -> f64, n: usize| {
        rows.iter().take(n).map(f).collect::<Vec<f64>>()
    };
    for (label, n) in [("all", rows.len()), ("the ten worst", 10.min(rows.len()))] {
        println!(
            "{label}: median single {:.4}, coat step {:.4}, shared coat per-channel {:.4}, best of step and shared {:.4}, own coats {:.4}",
            quantile(&col(|r| r.1, n), 0.5),
            quantile(&col(|r| r.2, n), 0.5),
            quantile(&col(|r| r.3, n), 0.5),
            quantile(&col(|r| r.2.min(r.3), n), 0.5),
            quantile(&col(|r| r.4, n), 0.5),
        );
    }
}
