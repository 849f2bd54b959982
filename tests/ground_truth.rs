//! Ground truth: MERL files written from analytic BRDFs come back with their α and Fresnel.

use facet_fit::analytic::parse_analytic;
use facet_fit::fit::{FitConfig, fit_material};
use facet_fit::merl::{MerlBrdf, MerlTable};

fn roundtrip_merl(spec: &str) -> MerlBrdf {
    let model = parse_analytic(spec).unwrap();
    MerlBrdf::from_table(spec, MerlTable::sample(&model)).unwrap()
}

#[test]
fn ggx_and_beckmann_alpha_come_back() {
    for (kind, alpha) in [
        ("ggx", 0.05),
        ("ggx", 0.1),
        ("ggx", 0.2),
        ("ggx", 0.4),
        ("ggx", 0.7),
        ("beckmann", 0.05),
        ("beckmann", 0.2),
        ("beckmann", 0.5),
    ] {
        let src = roundtrip_merl(&format!("{kind}?alpha={alpha}&f0=0.04"));
        let t = std::time::Instant::now();
        let fit = fit_material(&src, "test", &FitConfig::isotropic()).unwrap();
        let r = &fit.record;
        let p = if kind == "ggx" {
            r.ggx.as_ref().unwrap()
        } else {
            r.beckmann.as_ref().unwrap()
        };
        println!(
            "{kind} {alpha}: lsq {:.5} ({:+.3}%) moments {:.5} ({:+.3}%) err tab {:.5} lsq {:.5} mom {:.5} it {} res {:.1e} λ {:.4} {:?} {:.0}ms",
            p.alpha_x,
            (p.alpha_x / alpha - 1.0) * 100.0,
            p.moments.alpha_x,
            (p.moments.alpha_x / alpha - 1.0) * 100.0,
            r.tabulated.error.unwrap(),
            p.error,
            p.moments.error,
            r.iterations,
            r.residual,
            r.eigenvalue,
            r.timings_ms,
            t.elapsed().as_secs_f64() * 1e3
        );
    }
}
