//! The pbrt-v4 writer: a `MakeNamedMaterial` statement (`conductor` or `coateddiffuse`; under a
//! fit's coat `coatedconductor`, or `coateddiffuse` with the coat as its interface), the
//! statement in `#` comments above it.

use super::{CoatExport, Kind, Report, list};
use crate::model::fresnel_curves::FresnelFits;
use crate::model::material::ParamRecord;

/// The pbrt-v4 file of `p`: a material named `id`, adding to `report` what it approximates.
pub(super) fn write(id: &str, p: &ParamRecord, fits: &FresnelFits, report: &mut Report) -> String {
    let (ax, ay) = (p.alpha_x, p.alpha_y);
    if let Some(coat) = report.coat {
        let material = coated(p, fits, coat, report);
        return statement(id, report, material);
    }
    let mut params = Vec::new();
    let kind = report.kind;
    let ty = match kind {
        Kind::Conductor => {
            params.push(format!(
                "\"rgb eta\" [ {} ]",
                list(&fits.conductor_eta, " ")
            ));
            params.push(format!("\"rgb k\" [ {} ]", list(&fits.conductor_k, " ")));
            "conductor"
        }
        Kind::Plastic => {
            params.push(format!("\"rgb reflectance\" [ {} ]", list(&p.diffuse, " ")));
            params.push(format!("\"float eta\" [ {} ]", fits.dielectric_eta));
            report.notes.push(
                "coateddiffuse is a layered BSDF evaluated stochastically (a Lambertian base of reflectance ρd under a rough dielectric interface of η, thickness 0.01, no medium): its diffuse light passes the interface twice and scatters between the layers, so it is not ρd/π".into(),
            );
            "coateddiffuse"
        }
    };
    params.push(format!("\"float uroughness\" [ {ax} ]"));
    params.push(format!("\"float vroughness\" [ {ay} ]"));
    params.push("\"bool remaproughness\" [ false ]".into());
    statement(id, report, (ty, params))
}

/// The type and parameters under a coat: `coatedconductor` (the coat the interface, the base the
/// conductor), or `coateddiffuse` (the coat the interface over ρd; the base's own specular
/// lobe has no place there and is dropped, said in `report`).
fn coated(
    p: &ParamRecord,
    fits: &FresnelFits,
    coat: CoatExport,
    report: &mut Report,
) -> (&'static str, Vec<String>) {
    let interface = [
        format!("\"float uroughness\" [ {} ]", coat.alpha),
        format!("\"float vroughness\" [ {} ]", coat.alpha),
    ];
    let params = match report.kind {
        Kind::Conductor => {
            let mut v = vec![format!("\"float interface.eta\" [ {} ]", coat.eta)];
            v.extend(
                interface
                    .iter()
                    .map(|s| s.replacen("\"float ", "\"float interface.", 1)),
            );
            v.push(format!(
                "\"rgb conductor.eta\" [ {} ]",
                list(&fits.conductor_eta, " ")
            ));
            v.push(format!(
                "\"rgb conductor.k\" [ {} ]",
                list(&fits.conductor_k, " ")
            ));
            v.push(format!("\"float conductor.uroughness\" [ {} ]", p.alpha_x));
            v.push(format!("\"float conductor.vroughness\" [ {} ]", p.alpha_y));
            v
        }
        Kind::Plastic => {
            report.notes.push(format!(
                "coateddiffuse has one interface, the coat's: the base's own specular lobe (α {:.4}, dielectric η {}) is dropped, its ρd kept",
                p.alpha_x, fits.dielectric_eta
            ));
            let mut v = vec![
                format!("\"rgb reflectance\" [ {} ]", list(&p.diffuse, " ")),
                format!("\"float eta\" [ {} ]", coat.eta),
            ];
            v.extend(interface);
            v
        }
    };
    let ty = match report.kind {
        Kind::Conductor => "coatedconductor",
        Kind::Plastic => "coateddiffuse",
    };
    let mut params = params;
    params.push("\"bool remaproughness\" [ false ]".into());
    (ty, params)
}

/// The statement of `report` in comments, then the material `id` of type `ty`.
fn statement(id: &str, report: &Report, (ty, params): (&str, Vec<String>)) -> String {
    let mut s = String::new();
    for line in report.lines() {
        s += &format!("# {}\n", line.replace(['\n', '\r'], " "));
    }
    // A name in a pbrt string cannot hold a double quote; `id` is a safe file stem.
    s += &format!("MakeNamedMaterial \"{id}\"\n    \"string type\" [ \"{ty}\" ]\n");
    for p in params {
        s += &format!("    {p}\n");
    }
    s
}
