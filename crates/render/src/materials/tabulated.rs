//! The tabulated class: a fit's model with its tabulated NDF (Dupuy et al. 2015), stretched and
//! rotated, shaded by `shaders/render/shade_microfacet.wgsl` with the table's D, Λ and
//! sampling (`shaders/render/materials/tabulated.inc.wgsl`).

use super::lobe;
use super::record::GpuMaterial;
use super::{MaterialPlan, ShadeStage};
use crate::layout::gpu_types::MaterialKind;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::microfacet::MicrofacetBrdf;
use facet_brdf::model::tabulated::TabulatedNdf;

/// The plan of tabulated model `brdf` of `fit`.
pub fn plan<'a>(
    gpu: GpuMaterial,
    brdf: &'a MicrofacetBrdf,
    fit: &FittedMaterial,
) -> MaterialPlan<'a> {
    lobe::plan(gpu, brdf, fit, MaterialKind::Tabulated)
}

/// Its stage.
pub fn stage() -> ShadeStage {
    lobe::microfacet_stage(true, false)
}

/// A tabulated NDF's block in the `tables` buffer, as `materials/tabulated.inc.wgsl` reads it:
/// [nu, nphi, ng, n_theta_v, n_phi_v, rows, columns, 0], then D₀, G1₀, the D cos θ cells'
/// CDF and pdf, and the visible-normal slices' CDF and pdf.
pub fn tabulated_block(tab: &TabulatedNdf) -> Vec<f32> {
    let tt = tab.tables();
    let (cdf, cell_pdf) = tab.sampling_tables();
    let vis = tab.visible_tables();
    let header = [
        tt.nu,
        tt.nphi,
        tt.ng,
        vis.n_theta_v,
        vis.n_phi_v,
        vis.rows,
        vis.columns,
        0,
    ];
    let mut block: Vec<f32> = header.iter().map(|&n| n as f32).collect();
    for t in [&tt.d, &tt.g1, cdf, cell_pdf, &vis.cdf, &vis.cell_pdf] {
        block.extend(t.iter().map(|&v| v as f32));
    }
    block
}

/// The tabulated NDFs a scene's tables hold, by address, with their offsets: an NDF shared by
/// many materials (the fit they all name) is placed once (about 1 MB each).
pub type PlacedNdfs = Vec<(*const TabulatedNdf, u32)>;
