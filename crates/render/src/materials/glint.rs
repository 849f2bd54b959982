//! The glint class: a fit's model whose NDF (analytic or tabulated) is rendered as discrete
//! flakes (Wang et al. 2018 over Jakob et al. 2014). Its class block is the model's lobe; each
//! glint material has a queue and a stage of its own, `shaders/render/shade_glint.wgsl` with
//! its DPF pyramid levels and flake field in bind group 2 (built by `resources/glints.rs`).

use super::lobe;
use super::record::GpuMaterial;
use super::{MaterialPlan, ShadeStage};
use crate::layout::gpu_types::MaterialKind;
use crate::layout::queues::Queue;
use crate::scene::GlintParams;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::microfacet::MicrofacetBrdf;

/// The plan of model `brdf` of `fit` as glints of `params`; its queue, `Queue::Glint(k)`, is
/// the k-th glint material's, set when the scene's materials are placed.
pub fn plan<'a>(
    gpu: GpuMaterial,
    brdf: &'a MicrofacetBrdf,
    fit: &FittedMaterial,
    params: GlintParams,
) -> MaterialPlan<'a> {
    let mut plan = lobe::plan(gpu, brdf, fit, MaterialKind::Glint);
    plan.slot.set_queue(Queue::Glint(0));
    plan.glint = Some((brdf.ndf.clone(), params));
    plan
}

/// Its stage (one per glint material).
pub fn stage() -> ShadeStage {
    ShadeStage {
        groups: crate::layout::bindings::GLINT_STAGE,
        ..ShadeStage::new(
            "render/shade_glint.wgsl",
            "shade_glint",
            facet_glint::gpu::flake_constants(),
        )
    }
}
