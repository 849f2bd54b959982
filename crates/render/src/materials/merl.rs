//! The measured MERL-grid class: f read from the measurement's table (Matusik et al. 2003,
//! `shaders/render/materials/merl.inc.wgsl`), sampled as its fit's tabulated model is, shaded
//! by `shaders/render/shade_microfacet.wgsl`. Its class block is the sampling model's lobe,
//! then [`MerlBlock`].

use super::lobe::{self, LobeBlock};
use super::record::{ClassBlock, GpuMaterial};
use super::{MaterialPlan, ShadeStage};
use crate::class_block;
use crate::layout::gpu_types::MaterialKind;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::merl_grid::{MerlTable, SAMPLES};

class_block!(
    /// A MERL-grid measurement, after its sampling model's lobe.
    MerlBlock => "MerlBlock" {
        /// its table in the scene tables (materials/merl.inc.wgsl)
        table: u32,
    }
);

/// Where [`MerlBlock`] starts in the class block: after the lobe.
pub const MERL_AT: usize = LobeBlock::LAYOUT.words();

/// The plan of a MERL-grid measurement sampled by `fit`'s tabulated model; the table's offset
/// is set when it is placed ([`MaterialPlan::place_tables`]).
pub fn plan<'a>(gpu: GpuMaterial, fit: &'a FittedMaterial) -> MaterialPlan<'a> {
    let mut plan = lobe::plan(gpu, &fit.tabulated, fit, MaterialKind::Merl);
    plan.slot.ndf = None;
    plan
}

/// Points a MERL record at its table.
pub fn set_table(gpu: &mut GpuMaterial, table: u32) {
    gpu.put(MERL_AT, &MerlBlock { table });
}

/// Its stage.
pub fn stage() -> ShadeStage {
    lobe::microfacet_stage(true, true)
}

/// A MERL-grid table as `materials/merl.inc.wgsl` reads it: f_r per sample, RGB interleaved,
/// −1 where missing.
pub fn merl_block(table: &MerlTable) -> Vec<f32> {
    (0..SAMPLES)
        .flat_map(|s| match table.value_at(s) {
            Some(v) => v.map(|x| x as f32),
            None => [-1.0; 3],
        })
        .collect()
}
