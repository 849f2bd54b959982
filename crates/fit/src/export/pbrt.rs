//! The pbrt-v4 writer: a `MakeNamedMaterial` statement (`conductor` or `coateddiffuse`), the
//! statement in `#` comments above it.

use super::{Kind, Report, list};
use crate::model::fresnel_curves::FresnelFits;
use crate::model::material::ParamRecord;

/// The pbrt-v4 file of `p`: a material named `id`, adding to `report` what it approximates.
pub(super) fn write(id: &str, p: &ParamRecord, fits: &FresnelFits, report: &mut Report) -> String {
    let (ax, ay) = (p.alpha_x, p.alpha_y);
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
