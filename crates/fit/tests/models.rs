//! The tabulated model (stretch, sampling), the grid's fast path, fit JSON, neural proxies,
//! numerical stability.

mod common;

use common::{Rng, merl_from_spec, scratch};
use facet_fit::analytic::parse_analytic;
use facet_fit::brdf::Brdf;
use facet_fit::extract::{ExtractConfig, Stopping, extract_isotropic};
use facet_fit::fit::{FitConfig, fit_material};
use facet_fit::fresnel::Fresnel;
use facet_fit::geometry::spherical;
use facet_fit::grid::{GridSamples, error_metric, microfacet_error, microfacet_errors};
use facet_fit::material::{FittedMaterial, ModelChoice};
use facet_fit::microfacet::{AnalyticNdf, MicrofacetBrdf, NdfKind};
use facet_fit::tabulated::{Stretch, TabulatedNdf};
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
            let p = (facet_fit::geometry::phi_of(h) / (2.0 * PI) * np as f64).min(np as f64 - 1.0)
                as usize;
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

#[test]
fn grid_fast_path_matches_direct_evaluation() {
    let src = facet_fit::merl::MerlBrdf::from_table(
        "noisy-gold",
        facet_fit::merl::MerlTable::sample(
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

#[test]
fn neural_proxies_load_and_evaluate() {
    let lib = common::nbrdf();
    assert_eq!(lib.names().count(), 100);
    let b = lib.get("gold-metallic-paint").unwrap();
    let (wi, wo) = (spherical(0.3, 0.0), spherical(0.5, 2.0));
    let f = b.eval(wi, wo).unwrap();
    assert!(f.iter().all(|v| v.is_finite() && *v > 0.0), "{f:?}");
    // Reciprocity and isotropy, which the network inherits from MERL's parameterisation.
    let g = b.eval(wo, wi).unwrap();
    assert!((0..3).all(|c| (f[c] / g[c] - 1.0).abs() < 1e-9));
    let rot = |w: DVec3| DVec3::new(w.x * 0.6 - w.y * 0.8, w.x * 0.8 + w.y * 0.6, w.z);
    let h = b.eval(rot(wi), rot(wo)).unwrap();
    assert!((0..3).all(|c| (f[c] / h[c] - 1.0).abs() < 1e-9));
    assert!(
        b.eval(spherical(1.7, 0.0), wo).is_none(),
        "below the horizon there is no value"
    );
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

#[test]
fn fixed_iteration_count_is_honoured() {
    let src = merl_from_spec("ggx?alpha=0.3&f0=0.04");
    let cfg = ExtractConfig {
        stopping: Stopping::Fixed(4),
        ..ExtractConfig::isotropic()
    };
    let ex = extract_isotropic(&src, &cfg).unwrap();
    assert_eq!(ex.iterations, 4);
    let conv = extract_isotropic(&src, &ExtractConfig::isotropic()).unwrap();
    assert!(conv.residual < 1e-9 && conv.residual < ex.residual);
    // λ is F(0) of the data.
    assert!(
        (conv.eigenvalue - 0.04).abs() < 1e-3,
        "λ = {}",
        conv.eigenvalue
    );
}
