//! Issue 48's first candidate measured: one power iteration (and one fit) per colour channel
//! against today's single NDF, on a library of neural proxies. Per material: the default fit's
//! tabulated error, and the error of the per-channel model — channel c of the source fitted as a
//! grey material, its tabulated model's channel c taken — both in the error metric on the same
//! grid samples of the source, tabulated on the MERL grid first as `facet fit` reads a file.
//! Prints the rows worst first, then the medians and 90th percentiles and the fit times.
//!
//! `cargo run --release -p facet-fit --example per_channel -- [NBRDF.json] [NAME_FILTER]`
//! (default: the embedded MERL-100; the RGL proxies: `docs/bench/rgl_nbrdf_json.py`).

use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, error_metric};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use std::time::Instant;

mod common;
use common::{Channel, PerChannel};

struct Row {
    name: String,
    single: f64,
    per_channel: f64,
    ms: [f64; 2],
}

fn row(lib: &NbrdfLibrary, name: &str, cfg: &FitConfig) -> Row {
    let proxy = lib.get(name).unwrap();
    let src = MerlBrdf::from_table(name, MerlTable::sample(&proxy)).unwrap();
    let set = GridSamples::new(&src);
    let t = Instant::now();
    let single = fit_material(&src, name, cfg).unwrap();
    let t_single = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let fits = [0, 1, 2].map(|c| fit_material(&Channel(&src, c), name, cfg).unwrap());
    let t_per = t.elapsed().as_secs_f64() * 1e3;
    Row {
        name: name.to_owned(),
        single: error_metric(&single.tabulated, &set),
        per_channel: error_metric(&PerChannel(fits.map(|f| f.tabulated)), &set),
        ms: [t_single, t_per],
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let lib = common::library(args.first());
    let filter = args.get(1).cloned().unwrap_or_default();
    let cfg = FitConfig::isotropic();
    let names: Vec<String> = lib
        .names()
        .filter(|n| n.contains(&filter))
        .map(str::to_owned)
        .collect();
    let mut rows: Vec<Row> = names.iter().map(|n| row(&lib, n, &cfg)).collect();
    rows.sort_by(|a, b| b.single.total_cmp(&a.single));
    println!(
        "{:<28} {:>9} {:>11} {:>7}",
        "material", "one NDF", "per channel", "ratio"
    );
    for r in &rows {
        let ratio = r.per_channel / r.single;
        println!(
            "{:<28} {:>9.4} {:>11.4} {ratio:>7.3}",
            r.name, r.single, r.per_channel
        );
    }
    let col = |f: fn(&Row) -> f64| rows.iter().map(f).collect::<Vec<_>>();
    for (label, v) in [
        ("one NDF", col(|r| r.single)),
        ("per channel", col(|r| r.per_channel)),
        ("fit ms, one NDF", col(|r| r.ms[0])),
        ("fit ms, per channel", col(|r| r.ms[1])),
    ] {
        println!(
            "{label:<20} median {:.4}  p90 {:.4}",
            quantile(&v, 0.5),
            quantile(&v, 0.9)
        );
    }
    let worse = rows
        .iter()
        .filter(|r| r.per_channel > r.single * 1.001)
        .count();
    println!(
        "{worse} of {} materials worse per channel (by > 0.1 %)",
        rows.len()
    );
}
