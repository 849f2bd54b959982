//! RGL .bsdf: tensor files, RGB, spectral and anisotropic.

use crate::harness::refused;
use facet_fit::export::rgl::{BsdfResolution, rgl_tensor};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::sources::rgl::RglBsdf;
use facet_oracles::fixtures::spectral_from_rgb;
use facet_oracles::{brdf_sane, direction_pairs};
use std::path::Path;

pub fn check_bsdf(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    match RglBsdf::from_bytes(path, bytes.to_vec()) {
        Ok(file) => {
            brdf_sane("the .bsdf", &file)?;
            for (wi, wo) in direction_pairs() {
                let pdf = file.pdf(wi, wo);
                if !(pdf.is_finite() && pdf >= 0.0) {
                    return Err(format!("accepted, but pdf({wi}, {wo}) = {pdf}"));
                }
            }
            Ok(true)
        }
        Err(e) => refused(path, e),
    }
}

/// Small `.bsdf` seeds (grids of 4 to 8): an RGB plastic, its spectral twin, an anisotropic
/// metal.
pub fn bsdf_seeds() -> Vec<(&'static str, Vec<u8>)> {
    let res = BsdfResolution {
        theta_i: 4,
        phi_i: 5,
        sample: 6,
        vndf: 8,
        ndf: 8,
    };
    let bytes = |spec: &str| {
        let model = parse_analytic(spec).unwrap();
        rgl_tensor(&model, &model.ndf, res, spec)
            .unwrap()
            .0
            .to_bytes()
    };
    let rgb = bytes("ggx?alpha=0.3&f0=0.04&kd=0.3,0.1,0.05");
    let spectral = spectral_from_rgb(&rgb);
    vec![
        ("rgb", rgb),
        ("spectral", spectral),
        ("aniso", bytes("ggx?alpha_x=0.1&alpha_y=0.3&f0=0.9")),
    ]
}
