//! A fit is the same, bit for bit, whatever the thread schedule: the passes over the grid sum
//! fixed chunks in order (metric/grid.rs, metric/iso/rows.rs), so one thread and three give one
//! record. (Before, rayon's work stealing chose where the partial sums were cut, and two fits of
//! one table differed at round-off.)

use facet_fit::fitting::{CoatSearch, FitConfig, fit_material};
use facet_fit::model::fresnel::Fresnel;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use facet_fit::sources::merl::MerlBrdf;

fn fit_on(threads: usize, src: &MerlBrdf, cfg: &FitConfig) -> String {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let m = pool.install(|| fit_material(src, "synthetic", cfg).unwrap());
    // The record without its timings.
    let mut json = serde_json::to_value(&m.record).unwrap();
    strip_times(&mut json);
    json.to_string()
}

/// Removes every `*_ms` / `ms` field (wall-clock times) from `v`.
fn strip_times(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(map) => {
            map.retain(|k, _| !(k == "ms" || k.ends_with("_ms") || k.contains("time")));
            map.values_mut().for_each(strip_times);
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(strip_times),
        _ => {}
    }
}

#[test]
fn a_fit_does_not_depend_on_the_thread_count() {
    let truth = MicrofacetBrdf {
        name: "truth".into(),
        ndf: Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.3)),
        fresnel: Fresnel::GOLD,
        diffuse: [0.02, 0.01, 0.0],
    };
    let src = MerlBrdf::from_table("truth", MerlTable::sample(&truth)).unwrap();
    let cfg = FitConfig {
        coat: CoatSearch::Off,
        ..FitConfig::isotropic()
    };
    let one = fit_on(1, &src, &cfg);
    let three = fit_on(3, &src, &cfg);
    assert!(one == three, "the records differ:\n{one}\n{three}");
}
