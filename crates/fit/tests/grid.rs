//! The error metric's grid: its fast path (tables of D, G and ρd per bin) and its batched pass
//! against direct evaluation.

use facet_fit::metric::grid::{GridSamples, error_metric, microfacet_error, microfacet_errors};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::fresnel::Fresnel;
use facet_fit::model::microfacet::MicrofacetBrdf;

#[test]
fn grid_fast_path_matches_direct_evaluation() {
    let src = facet_fit::sources::merl::MerlBrdf::from_table(
        "noisy-gold",
        facet_fit::model::merl_grid::MerlTable::sample(
            &parse_analytic("ggx?alpha=0.25&conductor=gold&kd=0.05").unwrap(),
        ),
    )
    .unwrap();
    let set = GridSamples::new(&src);
    for spec in [
        "ggx?alpha=0.2&f0=0.1",
        "beckmann?alpha=0.35&conductor=gold",
        "ggx?alpha=0.02&f0=0.9",
    ] {
        let model = parse_analytic(spec).unwrap();
        let (fast, direct) = (microfacet_error(&model, &set), error_metric(&model, &set));
        println!("{spec}: fast {fast:.6}, direct {direct:.6}");
        assert!(
            (fast / direct - 1.0).abs() < 1e-3,
            "{spec}: {fast} vs {direct}"
        );
    }
    // The batched pass (one model's D, G and ρd with several Fresnels) gives each Fresnel's
    // own error: the same f32 row sums, so equal up to the f64 order of the row totals.
    let model = parse_analytic("ggx?alpha=0.2&f0=0.1&kd=0.1,0.2,0.3").unwrap();
    let curves = [
        Fresnel::Schlick { f0: [0.04; 3] },
        Fresnel::Dielectric { eta: 1.5 },
        Fresnel::Conductor {
            eta: [0.18, 0.42, 1.37],
            k: [3.42, 2.35, 1.77],
        },
    ];
    let batched = microfacet_errors(&model, &curves, &set);
    for (fresnel, b) in curves.iter().zip(batched) {
        let one = MicrofacetBrdf {
            fresnel: fresnel.clone(),
            ..model.clone()
        };
        let e = microfacet_error(&one, &set);
        assert!((b / e - 1.0).abs() < 1e-9, "{fresnel:?}: {b} vs {e}");
    }
}
