//! A fit's microfacet model as the GPU reads it, the block the fitted classes share (analytic,
//! tabulated, glint, and the MERL class's sampling model) at word 0 of their class block:
//!   f = F(θd) D(h) G2(ωi, ωo) / (4 cos θi cos θo) + ρd / π,
//! F a table over θd in the scene tables, D its analytic NDF (GGX, Beckmann) or its table
//! stretched by (αx, αy) and rotated.

use super::record::GpuMaterial;
use super::{MaterialPlan, MaterialSlot, ShadeStage};
use crate::class_block;
use crate::layout::gpu_types::MaterialKind;
use crate::layout::queues::Queue;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::microfacet::{MicrofacetBrdf, Ndf};
use facet_glint::tags::NdfTag;

/// Fresnel tables are resampled on this many θd nodes over [0, π/2], inclusive.
pub const FRESNEL_NODES: usize = 91;

/// The GGX α the ray cone widens by where a material states none (a tabulated fit without a
/// GGX model, an RGL file): a moderately rough lobe.
pub const UNKNOWN_CONE_ALPHA: f32 = 0.3;

class_block!(
    /// A fit's microfacet lobe: Fresnel table, diffuse term, NDF.
    LobeBlock => "LobeBlock" {
        /// ρd, the Lambertian albedo (rgb)
        diffuse: [f32; 3],
        /// F(θd)'s table in the scene tables: FRESNEL_NODES rgb nodes
        fresnel: u32,
        /// the Fresnel table's nodes
        fresnel_nodes: u32,
        /// the NDF: NDF_KIND_GGX, NDF_KIND_BECKMANN or NDF_KIND_TABULATED
        ndf_kind: u32,
        /// the NDF's stretch along the tangent (an analytic NDF's αx)
        alpha_x: f32,
        /// the NDF's stretch along the bitangent (αy)
        alpha_y: f32,
        /// the stretch's rotation from the tangent (radians)
        rotation: f32,
        /// a tabulated NDF's block in the scene tables (materials/tabulated.inc.wgsl), NONE else
        table: u32,
        /// the GGX α the ray cone widens by
        cone_alpha: f32,
    }
);

/// F(θd) of `brdf` at [`FRESNEL_NODES`] nodes, RGB interleaved.
pub fn fresnel_table(brdf: &MicrofacetBrdf) -> Vec<f32> {
    (0..FRESNEL_NODES)
        .flat_map(|j| {
            let theta_d = j as f64 / (FRESNEL_NODES - 1) as f64 * std::f64::consts::FRAC_PI_2;
            brdf.fresnel.eval(theta_d.cos()).map(|v| v as f32)
        })
        .collect()
}

/// The lobe of model `brdf` of `fit`; its table offsets are set when its tables are placed.
pub fn lobe(brdf: &MicrofacetBrdf, fit: &FittedMaterial) -> LobeBlock {
    let d = brdf.diffuse.map(|v| v as f32);
    let (alpha_x, alpha_y, rotation, cone_alpha) = match &brdf.ndf {
        Ndf::Analytic(a) => {
            let cone = (a.alpha_x * a.alpha_y).sqrt() as f32;
            (a.alpha_x, a.alpha_y, a.rotation, cone)
        }
        Ndf::Tabulated(tab) => {
            // The ray cone widens by the fit's GGX α where there is one, stretched as the table.
            let ggx = fit.record.ggx.as_ref();
            let alpha = ggx.map_or(UNKNOWN_CONE_ALPHA, |p| {
                (p.alpha_x * p.alpha_y).sqrt() as f32
            });
            let s = &tab.stretch;
            let cone = alpha * (s.alpha_x * s.alpha_y).sqrt() as f32;
            (s.alpha_x, s.alpha_y, s.rotation, cone)
        }
    };
    LobeBlock {
        diffuse: [d[0], d[1], d[2]],
        fresnel: 0,
        fresnel_nodes: FRESNEL_NODES as u32,
        ndf_kind: NdfTag::of(&brdf.ndf) as u32,
        alpha_x: alpha_x as f32,
        alpha_y: alpha_y as f32,
        rotation: rotation as f32,
        table: crate::layout::gpu_types::NONE,
        cone_alpha,
    }
}

/// The lobe of a record of a fitted class.
pub fn of(gpu: &GpuMaterial) -> LobeBlock {
    gpu.get(0)
}

/// Sets the lobe's table offsets in `gpu` (`None`: kept).
pub fn set_tables(gpu: &mut GpuMaterial, fresnel: Option<u32>, table: Option<u32>) {
    let mut lobe = of(gpu);
    lobe.fresnel = fresnel.unwrap_or(lobe.fresnel);
    lobe.table = table.unwrap_or(lobe.table);
    gpu.put(0, &lobe);
}

/// The plan of a fitted class `kind` rendering model `brdf` of `fit`: its lobe, its Fresnel
/// table and (a tabulated NDF) its table, placed by [`MaterialPlan::place_tables`].
pub fn plan<'a>(
    mut gpu: GpuMaterial,
    brdf: &'a MicrofacetBrdf,
    fit: &FittedMaterial,
    kind: MaterialKind,
) -> MaterialPlan<'a> {
    gpu.put(0, &lobe(brdf, fit));
    let ndf = match &brdf.ndf {
        Ndf::Analytic(a) => Some(a.kind),
        Ndf::Tabulated(_) => None,
    };
    let mut plan = MaterialPlan::new(MaterialSlot::new(gpu, kind, ndf, Queue::Shade(kind)));
    plan.fresnel = Some(fresnel_table(brdf));
    if let Ndf::Tabulated(tab) = &brdf.ndf {
        plan.tabulated = Some(tab.as_ref());
    }
    plan
}

/// The stage of the fitted classes without glints, `shaders/render/shade_microfacet.wgsl`:
/// with `tabulated` its NDF is a table, with `measured` f is a MERL-grid table sampled as its
/// fit's tabulated model.
pub fn microfacet_stage(tabulated: bool, measured: bool) -> ShadeStage {
    use facet_brdf::model::merl_grid::{PHI_D_RES, THETA_D_RES, THETA_H_RES};
    let flag = |b: bool| b as u32 as f64;
    ShadeStage::new(
        "render/shade_microfacet.wgsl",
        "shade_microfacet",
        vec![
            ("TABULATED", flag(tabulated)),
            ("MEASURED", flag(measured)),
            ("MERL_THETA_H", THETA_H_RES as f64),
            ("MERL_THETA_D", THETA_D_RES as f64),
            ("MERL_PHI_D", PHI_D_RES as f64),
        ],
    )
}
