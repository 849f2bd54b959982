//! Directional albedo E(ωo) = ∫ f(ωi, ωo) cos θi dωi of a microfacet BRDF, by quadrature.
//!
//! The integral is taken in the NDF's own sampling coordinates: ωi = reflect(ωo, h(u)),
//! u ∈ [0,1)², so E = ∫∫ f cos θi / p(ωi) du with p(ωi) = pdf(h) / (4 |ωo·h|) — an exact change
//! of variables whose integrand is smooth even for small α, integrated by the midpoint rule on an
//! n × n grid. (The diffuse term, if any, is added in closed form: ρd.) This is what the
//! renderer's white-furnace tests compare against.

use crate::model::brdf::Brdf;
use crate::model::microfacet::MicrofacetBrdf;
use crate::model::rgb::Rgb;
use glam::DVec3;

/// E(ωo) per channel with an n × n midpoint grid over the sampling square.
pub fn directional_albedo(brdf: &MicrofacetBrdf, wo: DVec3, n: usize) -> Rgb {
    let mut sum = [0.0f64; 3];
    if wo.z <= 0.0 {
        return sum;
    }
    let specular = MicrofacetBrdf {
        diffuse: [0.0; 3],
        ..brdf.clone()
    };
    for i in 0..n {
        for j in 0..n {
            let u = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64];
            let h = brdf.ndf.sample(u);
            let c = wo.dot(h);
            let wi = 2.0 * c * h - wo;
            if c <= 0.0 || wi.z <= 0.0 {
                continue;
            }
            let pdf = brdf.ndf.pdf(h) / (4.0 * c);
            if pdf <= 0.0 {
                continue;
            }
            if let Some(f) = specular.eval(wi, wo) {
                for k in 0..3 {
                    sum[k] += f[k] * wi.z / pdf;
                }
            }
        }
    }
    let n2 = (n * n) as f64;
    std::array::from_fn(|k| sum[k] / n2 + brdf.diffuse[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::fresnel::Fresnel;
    use crate::model::microfacet::{AnalyticNdf, Ndf, NdfKind};

    fn ggx(alpha: f64) -> MicrofacetBrdf {
        MicrofacetBrdf {
            name: "ggx".into(),
            ndf: Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, alpha)),
            fresnel: Fresnel::Schlick { f0: [1.0; 3] },
            diffuse: [0.0; 3],
        }
    }

    /// A near-mirror conductor with F = 1 at normal incidence reflects nearly everything:
    /// E = G1(ωo) exactly for the uncorrelated-at-mirror limit, ≈ 1 for α → 0.
    #[test]
    fn small_alpha_albedo_is_one() {
        let e = directional_albedo(&ggx(0.01), DVec3::Z, 64);
        assert!((e[0] - 1.0).abs() < 1e-3, "{e:?}");
    }

    /// Against brute-force uniform-hemisphere quadrature at α = 0.5, θo = 60°.
    #[test]
    fn matches_hemisphere_quadrature() {
        let b = ggx(0.5);
        let wo = DVec3::new(60f64.to_radians().sin(), 0.0, 60f64.to_radians().cos());
        let e = directional_albedo(&b, wo, 256)[0];
        let (nt, np) = (2000, 400);
        let mut s = 0.0;
        for i in 0..nt {
            let ct = (i as f64 + 0.5) / nt as f64; // uniform in cos θ: dω = dcosθ dφ
            let st = (1.0 - ct * ct).sqrt();
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * std::f64::consts::TAU;
                let wi = DVec3::new(st * phi.cos(), st * phi.sin(), ct);
                s += b.eval(wi, wo).map_or(0.0, |f| f[0]) * ct;
            }
        }
        let brute = s * std::f64::consts::TAU / (nt * np) as f64;
        assert!((e - brute).abs() < 2e-3 * brute, "{e} vs {brute}");
    }
}
