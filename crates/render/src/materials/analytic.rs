//! The fitted analytic class: a fit's GGX or Beckmann model (its lobe, [`super::lobe`]),
//! shaded by `shaders/render/shade_microfacet.wgsl` with the NDF in closed form
//! (`common/microfacet.inc.wgsl`).

use super::lobe;
use super::record::GpuMaterial;
use super::{MaterialPlan, ShadeStage};
use crate::layout::gpu_types::MaterialKind;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::microfacet::MicrofacetBrdf;

/// The plan of analytic model `brdf` of `fit`.
pub fn plan<'a>(
    gpu: GpuMaterial,
    brdf: &'a MicrofacetBrdf,
    fit: &FittedMaterial,
) -> MaterialPlan<'a> {
    lobe::plan(gpu, brdf, fit, MaterialKind::Analytic)
}

/// Its stage.
pub fn stage() -> ShadeStage {
    lobe::microfacet_stage(false, false)
}
