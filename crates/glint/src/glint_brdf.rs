//! The glint BRDF: the fraction of flakes in the footprint that reflect ωi into the cone of
//! half-angle γ around ωo, with Fresnel and shadowing of the smooth model:
//!   f cos θo = F G2 (h·ωo) count / (N a(A) σ(γ) cos θi cos θh).
//! Deviation from the formula: the 1/cos θh. With flake normals distributed as
//! p(m) = D(m) cos θm the expected count is N a P, P ≈ D(h) cos θh σ(γ) / (4 ωi·h), and only
//! with 1/cos θh does the limit become the smooth microfacet BRDF F G2 D / (4 cos θi cos θo).

use crate::dpf::cone_solid_angle;
use crate::flakes::{FlakeField, Footprint, direction_coords};
use crate::lit::{LitKey, blend_cells};
use facet_brdf::model::microfacet::{MicrofacetBrdf, correlation, g2};
use facet_brdf::model::rgb::Rgb;
use glam::{DVec2, DVec3};

/// How glints are counted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlintConfig {
    /// Half-angle of the cone of reflected directions, radians.
    pub gamma: f64,
    /// Expected counts above this use the mean N a P instead of counting flakes.
    pub threshold: f64,
    /// Whether the mean may replace the count at all.
    pub filtered: bool,
    /// Blend the counts of the direction cells around the half vector ([`blend_cells`]: the cell
    /// and, near an edge, its neighbours, weights continuous in the half vector),
    /// so that counts do not pop when the half vector crosses a cell edge; without it, the
    /// count of the one cell it is in.
    pub blend: bool,
}

impl GlintConfig {
    /// γ = 1°, threshold 16, filter on, cells blended.
    pub const fn standard() -> Self {
        GlintConfig {
            gamma: std::f64::consts::PI / 180.0,
            threshold: 16.0,
            filtered: true,
            blend: true,
        }
    }
}

/// Lit flakes in the footprint for (ωi, ωo) (blended over cells with `cfg.blend`), or N a P when
/// the filter takes over.
/// `p` is P(ωi, ωo, γ) from the DPF.
pub fn glint_count(
    field: &FlakeField,
    fp: &Footprint,
    wi: DVec3,
    wo: DVec3,
    p: f64,
    cfg: &GlintConfig,
) -> f64 {
    glint_count_at(field, fp, direction_coords(wi, wo, cfg.gamma), p, cfg)
}

/// [`glint_count`] for a half vector at direction coordinates `coords`
/// ([`crate::flakes::direction_coords`]).
pub fn glint_count_at(
    field: &FlakeField,
    fp: &Footprint,
    coords: DVec2,
    p: f64,
    cfg: &GlintConfig,
) -> f64 {
    let expected = field.density * fp.area() * p;
    if cfg.filtered && expected > cfg.threshold {
        return expected;
    }
    if !cfg.blend {
        let c = coords.floor();
        let q = |x: f64| (x as i64 + (1 << 24)) as u32;
        return field.lit_count(fp, p, LitKey::of_cell((q(c.x), q(c.y)))) as f64;
    }
    blend_cells(coords)
        .iter()
        .filter(|(_, w)| *w > 0.0)
        .map(|&(cell, w)| w * field.lit_count(fp, p, LitKey::of_cell(cell)) as f64)
        .sum()
}

/// f(ωi, ωo) of the glint model plus the model's diffuse lobe ρd/π; `model` gives F, G2 and ρd
/// (its NDF is the one the DPF was built from).
pub fn glint_eval(
    model: &MicrofacetBrdf,
    field: &FlakeField,
    fp: &Footprint,
    wi: DVec3,
    wo: DVec3,
    p: f64,
    cfg: &GlintConfig,
) -> Rgb {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return [0.0; 3];
    }
    let h = (wi + wo).normalize();
    let count = glint_count(field, fp, wi, wo, p, cfg);
    // The fit's diffuse lobe ρd/π lies under the flakes.
    let diffuse = model.diffuse.map(|k| k / std::f64::consts::PI);
    if count == 0.0 {
        return diffuse;
    }
    let phi = facet_brdf::model::geometry::azimuth_between(wi, wo);
    let g = g2(model.ndf.lambda(wi), model.ndf.lambda(wo), correlation(phi));
    let f = model.fresnel.eval(wi.dot(h));
    let scale = g * h.dot(wo) * count
        / (field.density * fp.area() * cone_solid_angle(cfg.gamma) * wi.z * h.z)
        / wo.z;
    std::array::from_fn(|c| f[c] * scale + diffuse[c])
}

/// Samples ωi for a given ωo from the smooth lobe (a normal visible from ωo, ωo reflected about
/// it); `None` below the horizon. The returned pdf is over solid angle of ωi:
/// pdf_h(h | ωo) / (4 |ωo·h|).
pub fn glint_sample(model: &MicrofacetBrdf, wo: DVec3, u: [f64; 2]) -> Option<(DVec3, f64)> {
    let h = model.ndf.sample_visible(wo, u);
    let cos = wo.dot(h);
    if cos <= 0.0 {
        return None;
    }
    let wi = 2.0 * cos * h - wo;
    (wi.z > 0.0).then(|| (wi, glint_pdf(model, wi, wo)))
}

/// The density of [`glint_sample`] at ωi.
pub fn glint_pdf(model: &MicrofacetBrdf, wi: DVec3, wo: DVec3) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let h = (wi + wo).normalize();
    model.ndf.pdf_visible(wo, h) / (4.0 * wo.dot(h).abs())
}
