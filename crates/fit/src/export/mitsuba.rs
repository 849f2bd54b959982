//! The Mitsuba 3 writer: a `<bsdf>` element (`roughconductor` or `roughplastic`) as the root of
//! an XML file, the statement in an XML comment above it.

use super::{Kind, Report, dielectric_f0, list};
use crate::model::fresnel::dielectric;
use crate::model::fresnel_curves::FresnelFits;
use crate::model::material::ParamRecord;

/// The hemispherical (cosine-weighted) reflectance of a smooth dielectric of index η seen from
/// outside, 2 ∫ F(μ) μ dμ (midpoint rule, 1024 steps).
fn hemispherical_reflectance(eta: f64) -> f64 {
    const N: usize = 1024;
    (0..N)
        .map(|i| {
            let mu = (i as f64 + 0.5) / N as f64;
            2.0 * dielectric(mu, eta) * mu / N as f64
        })
        .sum()
}

/// The ratio of Mitsuba's `roughplastic` diffuse term at normal incidence to ρd/π, for a smooth
/// interface: t(0)² / (η² (1 − R_int)) with 1 − R_int = (1 − R_ext)/η², i.e. t(0)² / (1 − R_ext).
pub fn plastic_diffuse_ratio(eta: f64) -> f64 {
    let t0 = 1.0 - dielectric_f0(eta);
    t0 * t0 / (1.0 - hemispherical_reflectance(eta))
}

/// Text safe inside an XML comment: no `--`, no stray control characters.
fn xml_comment(s: &str) -> String {
    let mut out: String = s
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    while out.contains("--") {
        out = out.replace("--", "- -");
    }
    if out.ends_with('-') {
        out.push(' ');
    }
    out
}

/// Text safe inside an XML attribute value.
fn xml_attr(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The least `int_ior` written for Mitsuba (which refuses an interface of index 1).
const MITSUBA_MIN_IOR: f64 = 1.0001;

/// The Mitsuba 3 file of `p`: a `<bsdf>` with id `id`, adding to `report` what it approximates.
pub(super) fn write(id: &str, p: &ParamRecord, fits: &FresnelFits, report: &mut Report) -> String {
    let dist = report.distribution;
    let mut body = vec![format!(
        r#"    <string name="distribution" value="{dist}"/>"#
    )];
    let kind = report.kind;
    let (ax, ay) = (p.alpha_x, p.alpha_y);
    let bsdf = match kind {
        Kind::Conductor => {
            if ax == ay {
                body.push(format!(r#"    <float name="alpha" value="{ax}"/>"#));
            } else {
                body.push(format!(r#"    <float name="alpha_u" value="{ax}"/>"#));
                body.push(format!(r#"    <float name="alpha_v" value="{ay}"/>"#));
            }
            body.push(format!(
                r#"    <rgb name="eta" value="{}"/>"#,
                list(&fits.conductor_eta, ", ")
            ));
            body.push(format!(
                r#"    <rgb name="k" value="{}"/>"#,
                list(&fits.conductor_k, ", ")
            ));
            "roughconductor"
        }
        Kind::Plastic => {
            let alpha = if ax == ay {
                ax
            } else {
                let a = (ax * ay).sqrt();
                report.notes.push(format!(
                    "Mitsuba's roughplastic is isotropic: α = √(αx αy) = {a} (the same peak D(0) = 1/(π αx αy)) in place of αx {ax}, αy {ay}"
                ));
                a
            };
            // Mitsuba refuses int_ior = ext_ior; the dielectric fit's η lies in [1, 4].
            let eta = fits.dielectric_eta.max(MITSUBA_MIN_IOR);
            if eta != fits.dielectric_eta {
                report.notes.push(format!(
                    "roughplastic needs int_ior ≠ ext_ior: the dielectric fit's η {} is written as {eta}",
                    fits.dielectric_eta
                ));
            }
            report.notes.push(format!(
                "roughplastic's diffuse term is ρ t(θi) t(θo) / (π η² (1 − R_int)) (internal scattering under the interface, nonlinear = false), not ρd/π: with ρ = ρd it is about {:.3} × ρd/π at normal incidence (smooth-interface estimate) and falls to 0 at grazing",
                plastic_diffuse_ratio(eta)
            ));
            body.push(format!(r#"    <float name="alpha" value="{alpha}"/>"#));
            body.push(format!(r#"    <float name="int_ior" value="{eta}"/>"#));
            body.push(r#"    <float name="ext_ior" value="1"/>"#.into());
            body.push(format!(
                r#"    <rgb name="diffuse_reflectance" value="{}"/>"#,
                list(&p.diffuse, ", ")
            ));
            body.push(r#"    <boolean name="nonlinear" value="false"/>"#.into());
            "roughplastic"
        }
    };
    document(bsdf, id, &body, report)
}

/// The Mitsuba 3 file of a coated model tabulated in `table` (a file name beside it): a
/// `measured` `<bsdf>`, the statement above it. Mitsuba finds the table through its file
/// resolver, which holds the folder of a file loaded with `mi.load_file`.
pub(super) fn write_measured(id: &str, table: &str, report: &Report) -> String {
    let body = [format!(
        r#"    <string name="filename" value="{}"/>"#,
        xml_attr(table)
    )];
    document("measured", id, &body, report)
}

/// The XML file: the statement of `report` in a comment, then `<bsdf type=bsdf id=id>` holding
/// `body`'s lines.
fn document(bsdf: &str, id: &str, body: &[String], report: &Report) -> String {
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!--\n");
    for line in report.lines() {
        s += &format!("  {}\n", xml_comment(&line));
    }
    s += "-->\n";
    s += &format!(
        "<bsdf type=\"{bsdf}\" id=\"{}\" version=\"3.0.0\">\n",
        xml_attr(id)
    );
    for b in body {
        s += b;
        s.push('\n');
    }
    s += "</bsdf>\n";
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plastic's diffuse in Mitsuba at η = 1.5 is within a few percent of ρd/π at normal
    /// incidence; the estimate is exactly 1 at η = 1 (no interface).
    #[test]
    fn plastic_diffuse_ratio_is_near_one() {
        assert!((plastic_diffuse_ratio(1.0) - 1.0).abs() < 1e-12);
        let r = plastic_diffuse_ratio(1.5);
        assert!(r > 1.0 && r < 1.05, "{r}");
    }
}
