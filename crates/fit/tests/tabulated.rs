//! The tabulated model: a stretched tabulated NDF is the scaled NDF, and its sampling follows
//! its pdf.

mod common;

use common::{Rng, merl_from_spec};
use facet_fit::extract::{ExtractConfig, extract_isotropic};
use facet_fit::model::geometry::spherical;
use facet_fit::model::microfacet::{AnalyticNdf, NdfKind};
use facet_fit::model::tabulated::{Stretch, TabulatedNdf};
use glam::DVec3;
use std::f64::consts::PI;

/// ∫ f(h) dω over the upper hemisphere, midpoint in u = sqrt(θ/(π/2)) × φ.
fn hemisphere(f: impl Fn(DVec3) -> f64, nu: usize, nphi: usize) -> f64 {
    let mut s = 0.0;
    for a in 0..nu {
        let u = (a as f64 + 0.5) / nu as f64;
        let theta = u * u * PI / 2.0;
        let w = theta.sin() * PI * u / nu as f64 * 2.0 * PI / nphi as f64;
        for b in 0..nphi {
            s += f(spherical(theta, (b as f64 + 0.5) / nphi as f64 * 2.0 * PI)) * w;
        }
    }
    s
}

fn tabulated_ggx(alpha: f64) -> TabulatedNdf {
    let src = merl_from_spec(&format!("ggx?alpha={alpha}&f0=0.04"));
    extract_isotropic(&src, &ExtractConfig::isotropic())
        .unwrap()
        .ndf
}

#[test]
fn stretched_tabulated_ndf_is_the_scaled_ndf() {
    // GGX is shape-invariant: stretching the tabulated GGX(0.1) by (2, 3) must give the
    // analytic GGX(0.2, 0.3), D and Λ alike, and stay normalised.
    let tab = tabulated_ggx(0.1).with_stretch(Stretch {
        alpha_x: 2.0,
        alpha_y: 3.0,
        rotation: 0.5,
    });
    let truth = AnalyticNdf {
        kind: NdfKind::Ggx,
        alpha_x: 0.2,
        alpha_y: 0.3,
        rotation: 0.5,
    };
    let norm = hemisphere(|h| tab.d(h) * h.z, 800, 256);
    assert!((norm - 1.0).abs() < 5e-3, "∫ D cos = {norm}");
    let mut rng = Rng(5);
    for _ in 0..500 {
        let h = spherical(rng.next() * 1.3, rng.next() * 2.0 * PI);
        let (a, b) = (tab.d(h), truth.d(h));
        assert!((a / b - 1.0).abs() < 0.02, "D at {h}: {a} vs {b}");
        let (a, b) = (tab.lambda(h), truth.lambda(h));
        assert!((a - b).abs() < 0.01 * (1.0 + b), "Λ at {h}: {a} vs {b}");
    }
}

#[test]
fn sampling_matches_its_pdf() {
    for stretch in [
        Stretch::IDENTITY,
        Stretch {
            alpha_x: 0.5,
            alpha_y: 2.0,
            rotation: 0.3,
        },
    ] {
        let tab = tabulated_ggx(0.3).with_stretch(stretch);
        // The pdf integrates to 1 and is close to D cos θ.
        let total = hemisphere(|h| tab.pdf(h), 1200, 256);
        assert!((total - 1.0).abs() < 5e-3, "∫ pdf = {total}");
        // Histogram of samples over cells of (cos θ, φ) against the integral of the pdf.
        let (nc, np, n) = (8, 8, 400_000);
        let mut hist = vec![0.0; nc * np];
        let mut rng = Rng(9);
        for _ in 0..n {
            let h = tab.sample([rng.next(), rng.next()]);
            assert!(h.z > 0.0 && (h.length() - 1.0).abs() < 1e-9);
            let c = ((1.0 - h.z) * nc as f64).min(nc as f64 - 1.0) as usize;
            let p = (facet_fit::model::geometry::phi_of(h) / (2.0 * PI) * np as f64)
                .min(np as f64 - 1.0) as usize;
            hist[c * np + p] += 1.0 / n as f64;
        }
        let mut expect = vec![0.0; nc * np];
        let m = 200;
        for a in 0..nc * m {
            let cos = 1.0 - (a as f64 + 0.5) / (nc * m) as f64;
            for b in 0..np * m / 4 {
                let phi = (b as f64 + 0.5) / (np * m / 4) as f64 * 2.0 * PI;
                let h = spherical(cos.acos(), phi);
                let w = 1.0 / (nc * m) as f64 * 2.0 * PI / (np * m / 4) as f64;
                expect[(a / m) * np + (b * 4 / m)] += tab.pdf(h) * w;
            }
        }
        for (k, (h, e)) in hist.iter().zip(&expect).enumerate() {
            let sigma = (e / n as f64).sqrt();
            assert!(
                (h - e).abs() < 5.0 * sigma + 1e-3 * e,
                "cell {k}: {h} vs {e}"
            );
        }
    }
}
