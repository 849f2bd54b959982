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
