//! The 100 MERL proxies fitted side by side in one run: the paper's single lobe
//! (`FitConfig::single_lobe`), the default fit with a diffuse lobe and the refinement, and the
//! default fit of the tabulated model alone (`--model tabulated`, which separates the diffuse
//! lobe without the analytic fits). Prints per-material errors and the medians, 90th
//! percentiles and win counts.
//!
//! `cargo run --release -p facet-fit --example proxy_sweep [-- NAME_FILTER]`

use facet_fit::fitting::{FitConfig, Models, fit_material};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use std::time::Instant;

struct Row {
    tab: f64,
    ggx: f64,
    beckmann: f64,
    max_f: f64,
    ms: f64,
}

fn main() {
    let filter = std::env::args().nth(1).unwrap_or_default();
    let lib = NbrdfLibrary::embedded();
    let names: Vec<String> = lib
        .names()
        .filter(|n| n.contains(&filter))
        .map(str::to_owned)
        .collect();
    let configs = [
        ("single lobe", FitConfig::single_lobe()),
        ("diffuse + refine", FitConfig::isotropic()),
    ];
    let mut rows: Vec<Vec<Row>> = vec![Vec::new(), Vec::new()];
    let tabulated_only = FitConfig {
        models: Models {
            ggx: false,
            beckmann: false,
            ..Models::ALL
        },
        ..FitConfig::isotropic()
    };
    // The tabulated-only fits' errors and times.
    let (mut alone, mut alone_ms, mut alone_no_worse) = (Vec::new(), Vec::new(), 0);
    println!(
        "material | single: tab ggx beckmann | diffuse: tab ggx beckmann ρd(tab) origin \
         | tabulated only: tab"
    );
    for name in &names {
        // Sampled once onto the MERL grid, as `facet fit` reads a MERL file: the fits are timed,
        // not the network.
        let net = lib.get(name).unwrap();
        let src = MerlBrdf::from_table(name, MerlTable::sample(&net)).unwrap();
        let mut line = format!("{name:28}");
        for (k, (_, cfg)) in configs.iter().enumerate() {
            let t = Instant::now();
            let r = fit_material(&src, name, cfg).unwrap().record;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let max_f = r
                .fresnel
                .rgb
                .iter()
                .flatten()
                .fold(0.0f64, |a, &b| a.max(b));
            let row = Row {
                tab: r.tabulated.error.unwrap(),
                ggx: r.ggx.as_ref().unwrap().error,
                beckmann: r.beckmann.as_ref().unwrap().error,
                max_f,
                ms,
            };
            line += &format!(" | {:.4} {:.4} {:.4}", row.tab, row.ggx, row.beckmann);
            if k == 1 {
                let d = r.tabulated.diffuse;
                line += &format!(
                    " ρd ({:.3} {:.3} {:.3}) {} sep {} ref {} {:.0} ms (extract {:.0} tab {:.0} fits {:.0})",
                    d[0],
                    d[1],
                    d[2],
                    r.tabulated.origin,
                    r.separation_rounds,
                    r.refine_rounds,
                    ms,
                    r.timings_ms.extract,
                    r.timings_ms.fresnel,
                    r.timings_ms.fit
                );
            }
            rows[k].push(row);
        }
        let t = Instant::now();
        let r = fit_material(&src, name, &tabulated_only).unwrap().record;
        alone_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let e = r.tabulated.error.unwrap();
        // Within 0.2 % of the default fit's tabulated error, or below it.
        alone_no_worse += usize::from(e <= rows[1].last().unwrap().tab * 1.002);
        alone.push(e);
        line += &format!(" | {e:.4}");
        println!("{line}");
    }
    for (k, (label, _)) in configs.iter().enumerate() {
        let r = &rows[k];
        let col = |f: fn(&Row) -> f64| r.iter().map(f).collect::<Vec<_>>();
        let (tab, ggx, beck) = (col(|r| r.tab), col(|r| r.ggx), col(|r| r.beckmann));
        let wins = r.iter().filter(|r| r.tab <= r.ggx.min(r.beckmann)).count();
        println!(
            "{label}: median/p90 tabulated {:.4}/{:.4}, GGX {:.4}/{:.4}, Beckmann {:.4}/{:.4}; \
             tabulated <= min(GGX, Beckmann) on {wins} of {}; largest F median {:.2} max {:.2}; \
             time per material median {:.0} ms",
            quantile(&tab, 0.5),
            quantile(&tab, 0.9),
            quantile(&ggx, 0.5),
            quantile(&ggx, 0.9),
            quantile(&beck, 0.5),
            quantile(&beck, 0.9),
            r.len(),
            quantile(&col(|r| r.max_f), 0.5),
            quantile(&col(|r| r.max_f), 1.0),
            quantile(&col(|r| r.ms), 0.5),
        );
    }
    println!(
        "tabulated only: median/p90 {:.4}/{:.4}; within 0.2 % of the default's tabulated error \
         or below it on {alone_no_worse} of {}; time per material median {:.0} ms",
        quantile(&alone, 0.5),
        quantile(&alone, 0.9),
        alone.len(),
        quantile(&alone_ms, 0.5),
    );
}
