//! The choice of quadrature, justified by measurement: α error of the extraction (moment
//! estimate) for each rule and resolution on analytic GGX and Beckmann data.

mod common;

use common::merl_from_spec;
use facet_fit::extract::{ExtractConfig, extract_isotropic};
use facet_fit::fitting::params::fit_moments;
use facet_fit::model::microfacet::NdfKind;
use facet_fit::numerics::quadrature::Quadrature;

#[test]
fn sqrt_theta_rules_beat_the_papers_uniform_theta() {
    let sources: Vec<_> = [
        (NdfKind::Ggx, 0.05),
        (NdfKind::Ggx, 0.2),
        (NdfKind::Beckmann, 0.1),
    ]
    .into_iter()
    .map(|(k, a)| {
        (
            k,
            a,
            merl_from_spec(&format!("{}?alpha={a}&f0=0.04", k.name())),
        )
    })
    .collect();
    println!("{:<22} {:>4} {:>12}", "quadrature", "N", "worst |Δα|/α");
    for n in [16, 32, 64] {
        let mut worst = Vec::new();
        for q in Quadrature::ALL {
            let cfg = ExtractConfig {
                resolution: n,
                quadrature: q,
                ..ExtractConfig::isotropic()
            };
            let w = sources
                .iter()
                .map(|(kind, alpha, src)| {
                    let ex = extract_isotropic(src, &cfg).unwrap();
                    (fit_moments(*kind, &ex.ndf).alpha_x / alpha - 1.0).abs()
                })
                .fold(0.0, f64::max);
            println!("{:<22} {n:>4} {:>11.4} %", format!("{q:?}"), w * 100.0);
            worst.push(w);
        }
        // Both sqrt-θ rules beat the paper's uniform θ by a wide margin at every N; beyond
        // N = 32 they sit on the same floor (~0.3 %), set by the MERL bins, not the quadrature.
        assert!(
            worst[1] < worst[0] / 5.0 && worst[2] < worst[0] / 5.0,
            "N = {n}: {worst:?}"
        );
        if n >= 32 {
            assert!(worst[2] < 0.01, "N = {n}: default rule error {}", worst[2]);
        }
    }
}
