//! A brute-force check of the isotropic least-squares fits: for each named MERL proxy, the
//! default fit's GGX and Beckmann α and error against the best α of a scan over the whole
//! grid (60 values log-spaced over [0.002, 2], then a shrinking bracket around the best; F and
//! ρd solved for each α with four reweighted steps, more than the fit's two).
//!
//! `cargo run --release -p facet-fit --example alpha_scan -- NAME...`

use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, fresnel_diffuse_and_error};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;

/// Reweighted steps of each scanned α's F / ρd solve.
const IRLS: usize = 4;

fn main() {
    let lib = NbrdfLibrary::embedded();
    for name in std::env::args().skip(1) {
        let net = lib.get(&name).unwrap_or_else(|e| panic!("{name}: {e}"));
        let src = MerlBrdf::from_table(&name, MerlTable::sample(&net)).unwrap();
        let record = fit_material(&src, &name, &FitConfig::isotropic())
            .unwrap()
            .record;
        let set = GridSamples::new(&src);
        for kind in NdfKind::ALL {
            let fitted = match kind {
                NdfKind::Ggx => record.ggx.as_ref(),
                NdfKind::Beckmann => record.beckmann.as_ref(),
            }
            .unwrap();
            let error = |alpha: f64| {
                let m = MicrofacetBrdf::ideal(
                    "scan",
                    Ndf::Analytic(AnalyticNdf::isotropic(kind, alpha)),
                );
                fresnel_diffuse_and_error(&m, &set, IRLS).map_or(f64::INFINITY, |r| r.2)
            };
            let (lo, hi) = (0.002f64.ln(), 2.0f64.ln());
            let mut best = (0..60)
                .map(|k| (lo + (hi - lo) * k as f64 / 59.0).exp())
                .map(|a| (error(a), a))
                .fold((f64::INFINITY, 1.0), |b, p| if p.0 < b.0 { p } else { b });
            // A bracket of ±12 % in α around the best, shrunk by √2 in ln α each step.
            let mut width = 1.13f64;
            for _ in 0..12 {
                for a in [best.1 / width, best.1 * width] {
                    let e = error(a);
                    if e < best.0 {
                        best = (e, a);
                    }
                }
                width = width.sqrt();
            }
            println!(
                "{name:28} {:<8} fit: α {:.4} error {:.4} | scan: α {:.4} error {:.4}",
                kind.name(),
                fitted.alpha_x,
                fitted.error,
                best.1,
                best.0
            );
        }
    }
}
