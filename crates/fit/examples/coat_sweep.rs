//! Issue 48's coat measured on a library of neural proxies: each fitted with and without the
//! coat step ([`facet_fit::fitting::coat`]) searched on every material (`CoatSearch::Always`;
//! the default searches only where the single layer's look is above `coat::TRY_ABOVE`), the
//! errors side by side, the coat kept (by the look) and its time.
//!
//! `cargo run --release -p facet-fit --example coat_sweep -- [NBRDF.json] [NAME_FILTER]`

use facet_fit::fitting::{CoatSearch, FitConfig, fit_material};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;

mod common;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let lib = common::library(args.first());
    let filter = args.get(1).cloned().unwrap_or_default();
    let (mut rows, mut looks_off) = (Vec::new(), Vec::new());
    for name in lib.names().filter(|n| n.contains(&filter)) {
        let src = MerlBrdf::from_table(name, MerlTable::sample(&lib.get(name).unwrap())).unwrap();
        let cfg = FitConfig {
            coat: CoatSearch::Always,
            ..FitConfig::isotropic()
        };
        let m = fit_material(&src, name, &cfg).unwrap();
        let t = m.record.timings_ms;
        let single = m.record.tabulated.error.unwrap();
        let (with, note) = match &m.record.coat {
            Some(c) => (
                c.error,
                format!(
                    "coat η {:.2} α {:.4} w {:.3}; base GGX α {:.4}",
                    c.coat.eta,
                    c.coat.alpha,
                    c.coat.weight,
                    c.base.ggx.as_ref().map_or(f64::NAN, |p| p.alpha_x)
                ),
            ),
            None => (single, "no coat".into()),
        };
        println!(
            "{name:<28} single {single:.4}  coated {with:.4} ({:.3}×)  {note}  fit {:.0} ms, coat {:.0} ms",
            with / single,
            t.total - t.coat,
            t.coat
        );
        looks_off.push(
            m.record
                .look
                .is_some_and(|l| l.tabulated > facet_fit::fitting::coat::TRY_ABOVE),
        );
        rows.push((
            name.to_owned(),
            single,
            with,
            m.record.coat.is_some(),
            t.total - t.coat,
            t.coat,
        ));
    }
    let one: Vec<f64> = rows.iter().map(|r| r.1).collect();
    let two: Vec<f64> = rows.iter().map(|r| r.2).collect();
    let kept = rows.iter().filter(|r| r.3).count();
    let ms: Vec<f64> = rows.iter().map(|r| r.4 + r.5).collect();
    println!(
        "single layer: median {:.4} p90 {:.4}; with the coat step: median {:.4} p90 {:.4}; coat kept by {kept} of {}; fit time median {:.0} ms",
        quantile(&one, 0.5),
        quantile(&one, 0.9),
        quantile(&two, 0.5),
        quantile(&two, 0.9),
        rows.len(),
        quantile(&ms, 0.5),
    );
    // The default (`CoatSearch::Auto`) searches only where the look is above TRY_ABOVE.
    let searched = |i: usize| looks_off[i];
    let auto_err: Vec<f64> = (0..rows.len())
        .map(|i| if searched(i) { rows[i].2 } else { rows[i].1 })
        .collect();
    let auto_ms: Vec<f64> = (0..rows.len())
        .map(|i| rows[i].4 + if searched(i) { rows[i].5 } else { 0.0 })
        .collect();
    let single_ms: Vec<f64> = rows.iter().map(|r| r.4).collect();
    println!(
        "the default (--coat auto, searched where the single layer's look is above ΔE {}): searched {}, kept {}; median {:.4} p90 {:.4}; fit time median {:.0} ms, p90 {:.0} ms (the single layer alone: median {:.0} ms)",
        facet_fit::fitting::coat::TRY_ABOVE,
        (0..rows.len()).filter(|&i| searched(i)).count(),
        (0..rows.len())
            .filter(|&i| searched(i) && rows[i].3)
            .count(),
        quantile(&auto_err, 0.5),
        quantile(&auto_err, 0.9),
        quantile(&auto_ms, 0.5),
        quantile(&auto_ms, 0.9),
        quantile(&single_ms, 0.5),
    );
    rows.sort_by(|a, b| b.1.total_cmp(&a.1));
    println!("the ten worst single layers:");
    for r in rows.iter().take(10) {
        println!("  {:<28} {:.4} → {:.4}", r.0, r.1, r.2);
    }
}
