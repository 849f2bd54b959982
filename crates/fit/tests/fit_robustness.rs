//! The fit under imperfect data: missing bins, multiplicative noise, and α at the numerical
//! extremes (α → 0, large α, a conductor's dynamic range, grazing directions).

mod common;

use common::{Rng, merl_from_spec, spec_table};
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::model::brdf::Brdf;
use facet_fit::model::geometry::{from_half_diff, spherical};
use facet_fit::model::material::ModelChoice;
use facet_fit::model::merl_grid::{PHI_D_RES, SAMPLES, THETA_D_RES, bin_angles};
use facet_fit::sources::merl::MerlBrdf;

fn ggx_alpha(src: &MerlBrdf) -> (f64, f64) {
    let p = fit_material(src, "test", &FitConfig::isotropic())
        .unwrap()
        .record
        .ggx
        .unwrap();
    (p.alpha_x, p.moments.alpha_x)
}

#[test]
fn missing_bins_and_horizon_barely_move_alpha() {
    for alpha in [0.1, 0.4] {
        let spec = format!("ggx?alpha={alpha}&f0=0.04");
        let clean = ggx_alpha(&merl_from_spec(&spec));
        let mut table = spec_table(&spec);
        let mut rng = Rng(7);
        let mut dropped = 0;
        for s in 0..SAMPLES {
            let (i, j, k) = (
                s / (PHI_D_RES * THETA_D_RES),
                s / PHI_D_RES % THETA_D_RES,
                s % PHI_D_RES,
            );
            let (wi, wo) = from_half_diff(bin_angles(i, j, k));
            // Everything below the horizon is already missing (the writer marks it); mark 5 % more.
            if wi.z > 0.0 && wo.z > 0.0 && rng.next() < 0.05 {
                table.mark_missing(s);
                dropped += 1;
            }
        }
        assert!(dropped > 40_000);
        let holed = ggx_alpha(&MerlBrdf::from_table("holed", table).unwrap());
        for (what, a, b) in [
            ("least squares", clean.0, holed.0),
            ("moments", clean.1, holed.1),
        ] {
            let moved = (b / a - 1.0).abs();
            println!(
                "GGX {alpha}: 5 % missing moves {what} α by {:.4} %",
                moved * 100.0
            );
            assert!(moved < 0.005, "{what}: {a} → {b}");
        }
    }
}

#[test]
fn multiplicative_noise_keeps_alpha_within_two_percent() {
    for alpha in [0.05, 0.2, 0.5] {
        let spec = format!("ggx?alpha={alpha}&f0=0.04");
        let mut table = spec_table(&spec);
        let mut rng = Rng(11);
        for s in 0..SAMPLES {
            // 5 % noise: uniform factor with standard deviation 0.05 (half-width 0.05·√3), per channel.
            let f = std::array::from_fn(|_| 1.0 + 0.05 * 3f64.sqrt() * (2.0 * rng.next() - 1.0));
            table.scale_sample(s, f);
        }
        let (lsq, moments) = ggx_alpha(&MerlBrdf::from_table("noisy", table).unwrap());
        println!("GGX {alpha} with 5 % noise: least squares {lsq:.5}, moments {moments:.5}");
        assert!((lsq / alpha - 1.0).abs() < 0.02 && (moments / alpha - 1.0).abs() < 0.02);
    }
}

#[test]
fn numerically_stable_at_the_extremes() {
    // α → 0, large α, and a conductor with a huge dynamic range: finite, non-negative tables
    // and α within a few per cent.
    for (spec, alpha) in [
        ("ggx?alpha=0.01&f0=0.04", 0.01),
        ("ggx?alpha=1.5&f0=0.04", 1.5),
        ("beckmann?alpha=0.02&f0=1", 0.02),
    ] {
        let r = fit_material(&merl_from_spec(spec), "test", &FitConfig::isotropic())
            .unwrap()
            .record;
        let t = &r.tabulated.tables;
        assert!(
            t.d.iter().chain(&t.g1).all(|v| v.is_finite() && *v >= 0.0),
            "{spec}"
        );
        let p = if spec.starts_with("ggx") {
            r.ggx.unwrap()
        } else {
            r.beckmann.unwrap()
        };
        println!(
            "{spec}: least squares {:.5}, moments {:.5}",
            p.alpha_x, p.moments.alpha_x
        );
        assert!(
            (p.alpha_x / alpha - 1.0).abs() < 0.03,
            "{spec}: {}",
            p.alpha_x
        );
    }
    // Grazing directions: every model stays finite and non-negative up to 89.99°.
    let fit = fit_material(
        &merl_from_spec("ggx?alpha=0.1&f0=0.04"),
        "test",
        &FitConfig::isotropic(),
    )
    .unwrap();
    for deg in [80.0, 89.0, 89.9, 89.99f64] {
        let (wi, wo) = (
            spherical(deg.to_radians(), 0.0),
            spherical(deg.to_radians(), 2.0),
        );
        for choice in [
            ModelChoice::Tabulated,
            ModelChoice::Ggx,
            ModelChoice::Beckmann,
        ] {
            let f = fit.model(choice).unwrap().eval(wi, wo).unwrap();
            assert!(
                f.iter().all(|v| v.is_finite() && *v >= 0.0),
                "{choice:?} at {deg}°: {f:?}"
            );
        }
    }
}
