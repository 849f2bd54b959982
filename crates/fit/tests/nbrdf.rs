//! The embedded neural BRDF proxies of MERL-100: they load and evaluate as MERL data would.

mod common;

use facet_fit::model::brdf::Brdf;
use facet_fit::model::geometry::spherical;
use glam::DVec3;

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
