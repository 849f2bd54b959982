//! The glTF 2.0 writer: a `.gltf` holding one metallic-roughness material (with
//! `KHR_materials_anisotropy`, `KHR_materials_ior`, `KHR_materials_specular` and
//! `KHR_materials_clearcoat` where they apply), the statement in its `extras`; and glTF's mapping of α to roughness and anisotropy.

use super::{Kind, Report, fmt_error, schlick_ior};
use crate::model::fresnel_curves::FresnelFits;
use crate::model::material::ParamRecord;
use serde_json::json;

/// The glTF 2.0 file of `p`: a material named `name`, adding to `report` what it approximates.
pub(super) fn write(
    name: &str,
    p: &ParamRecord,
    fits: &FresnelFits,
    report: &mut Report,
) -> String {
    let (ax, ay) = (p.alpha_x, p.alpha_y);
    let (amin, amax) = (ax.min(ay), ax.max(ay));
    let roughness = alpha_to_roughness(amin);
    if amin > 1.0 {
        report.notes.push(format!(
            "glTF's roughness is at most 1 (α = 1): α {amin} is clamped"
        ));
    }
    let mut extensions = serde_json::Map::new();
    if amax != amin {
        let (strength, rotation) = anisotropy(ax, ay, p.rotation);
        if amax > 1.0 {
            report.notes.push(format!(
                "KHR_materials_anisotropy's strength is at most 1 (α = 1 along the stretched axis): α {amax} is clamped"
            ));
        }
        extensions.insert(
            "KHR_materials_anisotropy".into(),
            json!({ "anisotropyStrength": strength, "anisotropyRotation": rotation }),
        );
        report.notes.push(
            "KHR_materials_anisotropy needs TANGENT vectors on the mesh: its rotation is from the tangent, like the fit's".into(),
        );
    }
    let kind = report.kind;
    let (base, metallic) = match kind {
        Kind::Conductor => {
            report.notes.push(format!(
                "glTF's metal Fresnel is Schlick's with F0 = baseColorFactor and F(90°) = 1: the Schlick fit stands in for the conductor's η {:?}, k {:?} (the conductor fit's error {})",
                fits.conductor_eta,
                fits.conductor_k,
                fmt_error(report.fresnel_fits_recorded.then_some(fits.conductor.error))
            ));
            (fits.schlick_f0.map(|f| f.clamp(0.0, 1.0)), 1.0)
        }
        Kind::Plastic => {
            // glTF's dielectric Fresnel is Schlick's with F0 = ((ior − 1)/(ior + 1))² ×
            // specularColorFactor: ior from the Schlick fit's mean F0, the colour (if any) as
            // the factor, is the Schlick fit exactly.
            let f0 = fits.schlick_f0.iter().sum::<f64>() / 3.0;
            let eta = schlick_ior(f0);
            extensions.insert("KHR_materials_ior".into(), json!({ "ior": eta }));
            let color = fits.schlick_f0.map(|s| if f0 > 0.0 { s / f0 } else { 1.0 });
            if color.iter().any(|c| (c - 1.0).abs() > 1e-3) {
                extensions.insert(
                    "KHR_materials_specular".into(),
                    json!({ "specularColorFactor": color }),
                );
            }
            if (eta / fits.dielectric_eta - 1.0).abs() > 1e-3 {
                report.notes.push(format!(
                    "ior {eta} is the Schlick fit's (glTF's Fresnel is Schlick's), not the dielectric fit's η {} (error {})",
                    fits.dielectric_eta,
                    fmt_error(report.fresnel_fits_recorded.then_some(fits.dielectric.error))
                ));
            }
            report.notes.push(
                "glTF's dielectric diffuse is ρd/π weighted by 1 − F (Schlick) of the specular layer, not ρd/π beside it".into(),
            );
            (p.diffuse, 0.0)
        }
    };
    if let Some(c) = report.coat {
        extensions.insert(
            "KHR_materials_clearcoat".into(),
            json!({
                "clearcoatFactor": c.weight,
                "clearcoatRoughnessFactor": alpha_to_roughness(c.alpha),
            }),
        );
    }
    let mut used: Vec<&String> = extensions.keys().collect();
    used.sort();
    let mut material = json!({
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [base[0], base[1], base[2], 1.0],
            "metallicFactor": metallic,
            "roughnessFactor": roughness,
        },
        "extras": { "facet_export": report, "statement": report.lines() },
    });
    if !extensions.is_empty() {
        material["extensions"] = serde_json::Value::Object(extensions.clone());
    }
    let mut doc = json!({
        "asset": {
            "version": "2.0",
            "generator": "facet export",
            "extras": { "summary": report.summary() },
        },
        "materials": [material],
    });
    if !used.is_empty() {
        doc["extensionsUsed"] = json!(used);
    }
    let mut s = serde_json::to_string_pretty(&doc).expect("a JSON value always serialises");
    s.push('\n');
    s
}

/// glTF's roughness of α (α = roughness²), at most 1.
pub fn alpha_to_roughness(alpha: f64) -> f64 {
    alpha.sqrt().min(1.0)
}

/// `KHR_materials_anisotropy` of (αx, αy, rotation): glTF keeps α = roughness² across the
/// stretched direction and raises it along it, α_t = mix(α, 1, strength²), so with the
/// material's roughness √min(αx, αy), strength = √((α_max − α_min)/(1 − α_min)) (at most 1) and
/// the rotation is the fit's, plus 90° when αy is the larger.
pub fn anisotropy(alpha_x: f64, alpha_y: f64, rotation: f64) -> (f64, f64) {
    let (amin, amax) = (alpha_x.min(alpha_y).min(1.0), alpha_x.max(alpha_y).min(1.0));
    let strength = if amin < 1.0 {
        ((amax - amin) / (1.0 - amin)).sqrt().min(1.0)
    } else {
        0.0
    };
    let rotation = if alpha_y > alpha_x {
        rotation + std::f64::consts::FRAC_PI_2
    } else {
        rotation
    };
    (strength, rotation)
}

/// (αx along the anisotropy direction, α across it) of glTF's roughness and strength: the
/// inverse of [`anisotropy`] with [`alpha_to_roughness`].
pub fn gltf_alphas(roughness: f64, strength: f64) -> (f64, f64) {
    let a = roughness * roughness;
    (a + (1.0 - a) * strength * strength, a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::tests::{material, param, run};
    use crate::export::{ModelRequest, Target, dielectric_f0};
    use crate::model::fresnel::Fresnel;

    /// glTF's roughness is √α exactly, and the anisotropy mapping inverted gives αx, αy back.
    #[test]
    fn roughness_and_anisotropy_invert() {
        for a in [1e-4, 0.01, 0.2, 0.5, 1.0] {
            // √α correctly rounded (IEEE sqrt), so roughness² is α to the last bit or two.
            assert_eq!(alpha_to_roughness(a), a.sqrt());
            assert!((alpha_to_roughness(a).powi(2) / a - 1.0).abs() < 4.0 * f64::EPSILON);
        }
        for (ax, ay, rot) in [(0.3, 0.1, 0.4), (0.05, 0.6, -1.0), (0.2, 0.2001, 0.0)] {
            let (s, r) = anisotropy(ax, ay, rot);
            let (along, across) = gltf_alphas(alpha_to_roughness(f64::min(ax, ay)), s);
            assert!(
                (along - f64::max(ax, ay)).abs() < 1e-12,
                "{ax} {ay}: {along}"
            );
            assert!((across - f64::min(ax, ay)).abs() < 1e-12);
            // The stretched direction is the fit's x axis, or its y axis (90° on) when αy is
            // the larger.
            let want = if ay > ax {
                rot + std::f64::consts::FRAC_PI_2
            } else {
                rot
            };
            assert_eq!(r, want);
        }
    }

    /// A coloured Schlick F0 on a plastic: glTF's ior × specularColorFactor gives it back.
    #[test]
    fn coloured_f0_goes_to_khr_materials_specular() {
        let f0 = [0.02, 0.04, 0.06];
        let m = material(
            Some(param(
                0.2,
                0.2,
                0.0,
                &Fresnel::Schlick { f0 },
                [0.2; 3],
                true,
            )),
            None,
        );
        let g = run(&m, Target::Gltf, ModelRequest::Ggx).unwrap();
        let v: serde_json::Value = serde_json::from_str(&g.text).unwrap();
        let ext = &v["materials"][0]["extensions"];
        let ior = ext["KHR_materials_ior"]["ior"].as_f64().unwrap();
        let color = &ext["KHR_materials_specular"]["specularColorFactor"];
        for c in 0..3 {
            let got = dielectric_f0(ior) * color[c].as_f64().unwrap();
            assert!((got - f0[c]).abs() < 1e-9, "{c}: {got}");
        }
        assert!(
            v["extensionsUsed"]
                .as_array()
                .unwrap()
                .contains(&"KHR_materials_specular".into())
        );
    }
}
