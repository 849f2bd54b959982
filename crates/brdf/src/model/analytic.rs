//! Analytic microfacet materials from a spec string, e.g. `analytic:ggx?alpha=0.2&f0=0.04`.
//!
//! Keys: `alpha` or `alpha_x`/`alpha_y`, `rotation` (degrees), and one Fresnel: `f0=v` or
//! `f0=r,g,b` (Schlick), `eta=r,g,b&k=r,g,b` or `conductor=gold` (conductor), `ior=v`
//! (dielectric); `kd=v` or `kd=r,g,b` adds a Lambertian term. Default Fresnel: `f0=0.04`.
//!
//! Every value is checked here, with its range: α in [`ALPHA_RANGE`], `rotation` finite,
//! `f0` and `kd` in [0, 1], `ior` and `eta` positive, `k` non-negative, all finite; a key given
//! twice (or `alpha` beside `alpha_x`) is an error naming it.

/// The α a model may have: below 10⁻⁴ the peak 1/(π α²) leaves f64 and f32 arithmetic behind;
/// above 10 the lobe is flatter than Lambertian and nothing is left to fit.
pub const ALPHA_RANGE: std::ops::RangeInclusive<f64> = 1e-4..=10.0;

use crate::error::BrdfError;
use crate::model::fresnel::Fresnel;
use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};

/// Whether two keys set the same property: the same key, `alpha` with `alpha_x` or `alpha_y`,
/// or two Fresnel models (`eta` and `k` together are one).
fn conflicting(a: &str, b: &str) -> bool {
    let fresnel = |x: &str| matches!(x, "f0" | "ior" | "conductor" | "eta" | "k");
    let conductor = |x: &str| matches!(x, "eta" | "k");
    a == b
        || matches!(
            (a, b),
            ("alpha", "alpha_x" | "alpha_y") | ("alpha_x" | "alpha_y", "alpha")
        )
        || (fresnel(a) && fresnel(b) && !(conductor(a) && conductor(b)))
}

/// Parses the part after `analytic:`.
pub fn parse_analytic(spec: &str) -> Result<MicrofacetBrdf, BrdfError> {
    let bad = |problem: String| BrdfError::Spec {
        spec: format!("analytic:{spec}"),
        problem,
    };
    let (model, query) = spec.split_once('?').unwrap_or((spec, ""));
    let kind = match model {
        "ggx" => NdfKind::Ggx,
        "beckmann" => NdfKind::Beckmann,
        other => return Err(bad(format!("unknown model `{other}` (ggx or beckmann)"))),
    };
    let mut keys = Keys::default();
    let mut seen: Vec<&str> = Vec::new();
    for pair in query.split('&').filter(|p| !p.is_empty()) {
        let (key, value) = pair
            .split_once('=')
            .ok_or_else(|| bad(format!("`{pair}` is not key=value")))?;
        if let Some(prev) = seen.iter().find(|&&prev| conflicting(prev, key)) {
            return Err(bad(if *prev == key {
                format!("`{key}` is given twice")
            } else {
                format!("`{prev}` and `{key}` set the same property; give one")
            }));
        }
        seen.push(key);
        keys.read(key, value, &bad)?;
    }
    let Keys {
        alpha,
        rotation,
        mut fresnel,
        eta,
        k,
        diffuse,
    } = keys;
    if let (Some(eta), Some(k)) = (eta, k) {
        fresnel = Some(Fresnel::Conductor { eta, k });
    } else if eta.is_some() || k.is_some() {
        return Err(bad("a conductor needs both eta and k".into()));
    }
    let (Some(alpha_x), Some(alpha_y)) = alpha else {
        return Err(bad("give alpha, or alpha_x and alpha_y".into()));
    };
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

/// What a spec's keys set, as they are read: α along x and y, the rotation (radians), the
/// Fresnel, a conductor's η and k (one Fresnel once both are read), and ρd.
#[derive(Default)]
struct Keys {
    alpha: (Option<f64>, Option<f64>),
    rotation: f64,
    fresnel: Option<Fresnel>,
    eta: Option<[f64; 3]>,
    k: Option<[f64; 3]>,
    diffuse: [f64; 3],
}

impl Keys {
    /// Reads `key=value`, its value checked against the key's range; `bad` makes the error.
    fn read(
        &mut self,
        key: &str,
        value: &str,
        bad: &impl Fn(String) -> BrdfError,
    ) -> Result<(), BrdfError> {
        // `x` is one component of the value `v`; an error names the whole value.
        let num_of = |x: &str, v: &str, range: &std::ops::RangeInclusive<f64>, what: &str| {
            let x = x
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("`{key}={v}`: not a finite number")))?;
            if range.contains(&x) {
                Ok(x)
            } else {
                Err(bad(format!("`{key}={v}`: {what}")))
            }
        };
        let num =
            |v: &str, range: std::ops::RangeInclusive<f64>, what: &str| num_of(v, v, &range, what);
        let rgb = |v: &str, range: std::ops::RangeInclusive<f64>, what: &str| {
            let parts: Vec<f64> = v
                .split(',')
                .map(|x| num_of(x, v, &range, what))
                .collect::<Result<_, _>>()?;
            match parts[..] {
                [x] => Ok([x; 3]),
                [r, g, b] => Ok([r, g, b]),
                _ => Err(bad(format!("`{key}={v}`: give one value or r,g,b"))),
            }
        };
        let alpha_range = || {
            format!(
                "α must lie in [{:e}, {}]",
                ALPHA_RANGE.start(),
                ALPHA_RANGE.end()
            )
        };
        let positive = 1e-6..=1e6;
        match key {
            "alpha" => {
                let a = num(value, ALPHA_RANGE, &alpha_range())?;
                self.alpha = (Some(a), Some(a));
            }
            "alpha_x" => self.alpha.0 = Some(num(value, ALPHA_RANGE, &alpha_range())?),
            "alpha_y" => self.alpha.1 = Some(num(value, ALPHA_RANGE, &alpha_range())?),
            "rotation" => {
                self.rotation =
                    num(value, -360.0..=360.0, "rotation is in degrees, -360 to 360")?.to_radians()
            }
            "f0" => {
                self.fresnel = Some(Fresnel::Schlick {
                    f0: rgb(value, 0.0..=1.0, "f0 must lie in [0, 1]")?,
                })
            }
            "ior" => {
                self.fresnel = Some(Fresnel::Dielectric {
                    eta: num(value, positive, "ior must lie in [1e-6, 1e6]")?,
                })
            }
            "eta" => self.eta = Some(rgb(value, positive, "eta must lie in [1e-6, 1e6]")?),
            "k" => self.k = Some(rgb(value, 0.0..=1e6, "k must lie in [0, 1e6]")?),
            "conductor" if value == "gold" => self.fresnel = Some(Fresnel::GOLD),
            "conductor" => {
                return Err(bad(format!(
                    "unknown conductor `{value}` (gold, or give eta and k)"
                )));
            }
            "kd" => self.diffuse = rgb(value, 0.0..=1.0, "kd must lie in [0, 1]")?,
            other => {
                return Err(bad(format!(
                    "unknown key `{other}` (alpha, alpha_x, alpha_y, rotation, f0, ior, eta, k, conductor, kd)"
                )));
            }
        }
        Ok(())
    }
}
