//! Analytic microfacet materials from a spec string, e.g. `analytic:ggx?alpha=0.2&f0=0.04`.
//!
//! Keys: `alpha` or `alpha_x`/`alpha_y`, `rotation` (degrees), and one Fresnel: `f0=v` or
//! `f0=r,g,b` (Schlick), `eta=r,g,b&k=r,g,b` or `conductor=gold` (conductor), `ior=v`
//! (dielectric); `kd=v` or `kd=r,g,b` adds a Lambertian term. Default Fresnel: `f0=0.04`.

use crate::brdf::Rgb;
use crate::error::FitError;
use crate::fresnel::Fresnel;
use crate::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};

/// Parses the part after `analytic:`.
pub fn parse_analytic(spec: &str) -> Result<MicrofacetBrdf, FitError> {
    let bad = |problem: String| FitError::Spec {
        spec: format!("analytic:{spec}"),
        problem,
    };
    let (model, query) = spec.split_once('?').unwrap_or((spec, ""));
    let kind = match model {
        "ggx" => NdfKind::Ggx,
        "beckmann" => NdfKind::Beckmann,
        other => return Err(bad(format!("unknown model `{other}` (ggx or beckmann)"))),
    };
    let mut alpha = (None, None);
    let (mut rotation, mut fresnel, mut eta, mut k, mut diffuse) =
        (0.0, None, None, None, [0.0; 3]);
    for pair in query.split('&').filter(|p| !p.is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .ok_or_else(|| bad(format!("`{pair}` is not key=value")))?;
        let num = |v: &str| -> Result<f64, FitError> {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("`{key}={v}`: not a finite number")))
        };
        let rgb = |v: &str| -> Result<Rgb, FitError> {
            let parts: Vec<f64> = v.split(',').map(num).collect::<Result<_, _>>()?;
            match parts[..] {
                [x] => Ok([x; 3]),
                [r, g, b] => Ok([r, g, b]),
                _ => Err(bad(format!("`{key}={v}`: give one value or r,g,b"))),
            }
        };
        match key {
            "alpha" => alpha = (Some(num(value)?), Some(num(value)?)),
            "alpha_x" => alpha.0 = Some(num(value)?),
            "alpha_y" => alpha.1 = Some(num(value)?),
            "rotation" => rotation = num(value)?.to_radians(),
            "f0" => fresnel = Some(Fresnel::Schlick { f0: rgb(value)? }),
            "ior" => fresnel = Some(Fresnel::Dielectric { eta: num(value)? }),
            "eta" => eta = Some(rgb(value)?),
            "k" => k = Some(rgb(value)?),
            "conductor" if value == "gold" => fresnel = Some(Fresnel::GOLD),
            "conductor" => {
                return Err(bad(format!(
                    "unknown conductor `{value}` (gold, or give eta and k)"
                )));
            }
            "kd" => diffuse = rgb(value)?,
            other => return Err(bad(format!("unknown key `{other}`"))),
        }
    }
    if let (Some(eta), Some(k)) = (eta, k) {
        fresnel = Some(Fresnel::Conductor { eta, k });
    } else if eta.is_some() || k.is_some() {
        return Err(bad("a conductor needs both eta and k".into()));
    }
    let (Some(alpha_x), Some(alpha_y)) = alpha else {
        return Err(bad("give alpha, or alpha_x and alpha_y".into()));
    };
    if !(alpha_x > 0.0 && alpha_y > 0.0) {
        return Err(bad(format!(
            "α must be positive, got ({alpha_x}, {alpha_y})"
        )));
    }
    if diffuse.iter().any(|d| *d < 0.0) {
        return Err(bad("kd must be non-negative".into()));
    }
    let ndf = Ndf::Analytic(AnalyticNdf {
        kind,
        alpha_x,
        alpha_y,
        rotation,
    });
    let name = format!(
        "analytic-{}",
        spec.replace(
            |c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-'),
            "_"
        )
    );
    Ok(MicrofacetBrdf {
        name,
        ndf,
        fresnel: fresnel.unwrap_or(Fresnel::Schlick { f0: [0.04; 3] }),
        diffuse,
    })
}
