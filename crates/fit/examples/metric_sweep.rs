//! Issue 60's objective chosen by measurement: every proxy of a library fitted with a metric,
//! and the default model (the tabulated fit, coated where the fit kept a coat) compared with
//! the measurement on a sphere under the report's point light, rendered here on the CPU, in
//! CIEDE2000 — the figure `facet report` shows, without the GPU renders (one sample at each
//! pixel's centre, 64² pixels).
//!
//! `cargo run --release -p facet-fit --example metric_sweep -- METRIC [NBRDF.json|-] [CACHE_DIR] [NAME_FILTER]`
//!
//! `CHROMA=1` also prints the ΔE a colour table over (θh, θd) times the lobe could reach.
//! METRIC: `log` or `perceptual` (`FACET_METRIC_KAPPA` and `FACET_METRIC_EPS`
//! override its floor's fraction of the mean and its least value); `SWEEP_COAT=off`
//! or `always` overrides the coat search. The proxies'
//! MERL-grid tables are cached as `.binary` files in CACHE_DIR (default `target/merl-cache`).

use facet_fit::fitting::{CoatSearch, FitConfig, fit_material};
use facet_fit::metric::Metric;
use facet_fit::metric::grid::{GridSamples, microfacet_error};
use facet_fit::metric::look::SphereScene;
use facet_fit::model::brdf::Brdf;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod common;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let metric = match args.first().map(String::as_str) {
        Some("log") => Metric::Log,
        Some("perceptual") => Metric::Perceptual,
        _ => panic!("METRIC: log or perceptual"),
    };
    let lib = common::library(args.get(1));
    let cache = PathBuf::from(args.get(2).map_or("target/merl-cache", String::as_str));
    std::fs::create_dir_all(&cache).unwrap();
    let filter = args.get(3).cloned().unwrap_or_default();
    // SWEEP_COAT=off: the single layer alone (the coat's search is most of a fit's time).
    let coat = match std::env::var("SWEEP_COAT").as_deref() {
        Ok("off") => CoatSearch::Off,
        Ok("always") => CoatSearch::Always,
        _ => FitConfig::isotropic().coat,
    };
    let cfg = FitConfig {
        metric,
        coat,
        ..FitConfig::isotropic()
    };
    let (mut rows, mut floor) = (Vec::new(), Vec::new());
    for name in lib.names().filter(|n| n.contains(&filter)) {
        let src = cached(&cache, name, || MerlTable::sample(&lib.get(name).unwrap()));
        let t = Instant::now();
        let m = fit_material(&src, name, &cfg).unwrap();
        let secs = t.elapsed().as_secs_f64();
        let log_err = microfacet_error(&m.tabulated, &GridSamples::new(&src));
        let de = sphere_delta_e(&src, &m);
        // CHROMA=1: the bound a colour table over (θh, θd) times the lobe could reach.
        if std::env::var("CHROMA").is_ok() {
            let chroma = Chromatic::fit(&src, &m.tabulated);
            println!(
                "{name:32} with a chromatic table: ΔE {:.2}",
                sphere_delta_e(&src, &chroma)
            );
        }
        println!(
            "{name:32} ΔE {de:6.2}  log {log_err:.4}  fit {secs:5.2} s  ρd {:.3} {:.3} {:.3}  coat {}  \
             error {:.4} coated {:.4}  look {:.3} coated {:.3}  coat step {:.2} s",
            m.record.tabulated.diffuse[0],
            m.record.tabulated.diffuse[1],
            m.record.tabulated.diffuse[2],
            m.record.coat.is_some(),
            m.record.tabulated.error.unwrap_or(f64::NAN),
            m.record.coat.as_ref().map_or(f64::NAN, |c| c.error),
            m.record.look.map_or(f64::NAN, |l| l.tabulated),
            m.record.look.and_then(|l| l.coated).unwrap_or(f64::NAN),
            m.record.timings_ms.coat / 1e3,
        );
        floor.push(m.record.metric_floor);
        rows.push((de, log_err, secs));
    }
    let col = |f: fn(&(f64, f64, f64)) -> f64| rows.iter().map(f).collect::<Vec<_>>();
    let (de, log, secs) = (col(|r| r.0), col(|r| r.1), col(|r| r.2));
    let count = |f: &dyn Fn(f64) -> bool| de.iter().filter(|&&d| f(d)).count();
    println!(
        "{} materials, metric {} (ε median {:.4}): ΔE median {:.2}, mean {:.2}; below 1: {}; above 3: {}; above 4: {}; \
         log median {:.4}; fit median {:.3} s, max {:.2} s, total {:.1} s",
        rows.len(),
        metric.name(),
        quantile(&floor, 0.5),
        quantile(&de, 0.5),
        de.iter().sum::<f64>() / de.len().max(1) as f64,
        count(&|d| d < 1.0),
        count(&|d| d > 3.0),
        count(&|d| d > 4.0),
        quantile(&log, 0.5),
        quantile(&secs, 0.5),
        secs.iter().cloned().fold(0.0, f64::max),
        secs.iter().sum::<f64>(),
    );
}

/// The proxy's MERL-grid table, from the cache or tabulated and cached.
fn cached(dir: &Path, name: &str, table: impl FnOnce() -> MerlTable) -> MerlBrdf {
    let path = dir.join(format!("{name}.binary"));
    if let Ok(src) = MerlBrdf::open(&path) {
        return src;
    }
    let src = MerlBrdf::from_table(name, table()).unwrap();
    src.table().write(&path).unwrap();
    src
}

/// The look of `model` against `data`: the report's point-light sphere, mean CIEDE2000.
fn sphere_delta_e(data: &dyn Brdf, model: &dyn Brdf) -> f64 {
    SphereScene::REPORT.delta_e(data, model)
}

/// The tabulated model with its lobe times a colour table over (θh, θd) bins, each bin's ratio
/// Σ (data − diffuse) / Σ lobe over its φd bins per channel: the most a chromatic table of the
/// AxF kind could give this single layer (issue 60's third question), before any smoothing.
struct Chromatic {
    lobe: facet_fit::model::microfacet::MicrofacetBrdf,
    diffuse: [f64; 3],
    table: Vec<[f64; 3]>,
}

impl Chromatic {
    fn fit(data: &MerlBrdf, model: &facet_fit::model::microfacet::MicrofacetBrdf) -> Self {
        use facet_fit::model::merl_grid::{PHI_D_RES, THETA_D_RES, THETA_H_RES, bin_directions};
        let lobe = facet_fit::model::microfacet::MicrofacetBrdf {
            diffuse: [0.0; 3],
            ..model.clone()
        };
        let kd = model.diffuse.map(|d| d / std::f64::consts::PI);
        let mut table = vec![[1.0; 3]; THETA_H_RES * THETA_D_RES];
        for i in 0..THETA_H_RES {
            for j in 0..THETA_D_RES {
                let (mut num, mut den) = ([0.0; 3], [0.0; 3]);
                for k in 0..PHI_D_RES {
                    let (wi, wo) = bin_directions(i, j, k);
                    let (Some(d), Some(l)) = (data.table().value(i, j, k), lobe.eval(wi, wo))
                    else {
                        continue;
                    };
                    if wi.z <= 0.0 || wo.z <= 0.0 {
                        continue;
                    }
                    for c in 0..3 {
                        num[c] += (d[c] - kd[c]).max(0.0);
                        den[c] += l[c];
                    }
                }
                for c in 0..3 {
                    if den[c] > 0.0 {
                        table[i * THETA_D_RES + j][c] = (num[c] / den[c]).clamp(0.0, 10.0);
                    }
                }
            }
        }
        Chromatic {
            lobe,
            diffuse: kd,
            table,
        }
    }
}

impl Brdf for Chromatic {
    fn name(&self) -> &str {
        "chromatic"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<facet_fit::Rgb> {
        use facet_fit::model::merl_grid::{THETA_D_RES, THETA_H_RES};
        let hd = facet_fit::model::geometry::to_half_diff(wi, wo);
        let half_pi = std::f64::consts::FRAC_PI_2;
        let i = (((hd.theta_h.max(0.0) / half_pi).sqrt() * THETA_H_RES as f64) as usize)
            .min(THETA_H_RES - 1);
        let j =
            ((hd.theta_d.max(0.0) / half_pi * THETA_D_RES as f64) as usize).min(THETA_D_RES - 1);
        let c = self.table[i * THETA_D_RES + j];
        let l = self.lobe.eval(wi, wo)?;
        Some(std::array::from_fn(|k| l[k] * c[k] + self.diffuse[k]))
    }
}
