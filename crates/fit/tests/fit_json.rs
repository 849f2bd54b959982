//! Fit JSON: saved and loaded unchanged, and a loaded fit as the source of another fit.

mod common;

use common::{merl_from_spec, scratch};
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, error_metric};
use facet_fit::model::material::{FittedMaterial, ModelChoice};

#[test]
fn fit_json_round_trip_and_fit_as_source() {
    let src = merl_from_spec("ggx?alpha=0.15&conductor=gold");
    let fit = fit_material(&src, "test", &FitConfig::isotropic()).unwrap();
    let path = scratch("fit_json").join("gold.json");
    fit.save(&path).unwrap();
    let back = FittedMaterial::load(&path).unwrap();
    assert_eq!(back.record, fit.record);
    // The fitted material is a BRDF source: fitting it again gives the same α.
    let again = fit_material(&back, "test", &FitConfig::isotropic())
        .unwrap()
        .record;
    let (a, b) = (fit.record.ggx.unwrap().alpha_x, again.ggx.unwrap().alpha_x);
    assert!((a / b - 1.0).abs() < 2e-3, "{a} vs {b}");
    // Every model evaluates like its source where it matters.
    for choice in [
        ModelChoice::Tabulated,
        ModelChoice::Ggx,
        ModelChoice::Beckmann,
    ] {
        let model = back.model(choice).unwrap();
        let e = error_metric(model, &GridSamples::new(&src).subsample(7));
        println!("{choice:?}: {e:.5}");
        assert!(e.is_finite() && e < 0.1);
    }
    // A broken file names itself.
    std::fs::write(&path, "{\"name\": 3}").unwrap();
    let err = FittedMaterial::load(&path).err().unwrap().to_string();
    assert!(err.contains("gold.json"), "{err}");
}

/// The figures a record reports are checked as it is read, the field named: a phase's time past
/// a week (1.7e308 ms summed to "inf s in all" in `facet fit --summary`), a negative or
/// non-finite look, a zero metric floor.
#[test]
fn a_records_times_and_looks_are_checked() {
    let src = merl_from_spec("ggx?alpha=0.15&conductor=gold");
    let fit = fit_material(&src, "test", &FitConfig::isotropic()).unwrap();
    let path = scratch("fit_json_figures").join("gold.json");
    fit.save(&path).unwrap();
    let good: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert!(
        good["look"]["tabulated"].as_f64().unwrap() < 0.1,
        "{}",
        good["look"]
    );
    for (pointer, value, field) in [
        (
            "/timings_ms/total",
            serde_json::json!(1.7e308),
            "timings_ms.total",
        ),
        ("/timings_ms/fit", serde_json::json!(-3.0), "timings_ms.fit"),
        ("/look/tabulated", serde_json::json!(-1.0), "look.tabulated"),
        (
            "/look/tabulated",
            serde_json::json!(1e300),
            "look.tabulated",
        ),
        ("/metric_floor", serde_json::json!(0.0), "metric_floor"),
    ] {
        let mut bad = good.clone();
        *bad.pointer_mut(pointer).unwrap() = value;
        let err = FittedMaterial::parse(&path, &bad.to_string())
            .err()
            .unwrap_or_else(|| panic!("{pointer} accepted"))
            .to_string();
        assert!(err.contains("gold.json") && err.contains(field), "{err}");
    }
}
