//! The material classes, one file each: its class block (the fields of the GPU record that
//! only it reads), its plan (a scene material to its record and tables), its queue and its
//! shading stage. Their WGSL is beside them in `shaders/render/materials/` and their stage files.
//!
//! | class ([`MaterialKind`]) | file | shading stage | class block |
//! |---|---|---|---|
//! | glTF metallic-roughness | [`gltf`] | `shade_diffuse.wgsl` | [`gltf::GltfBlock`] |
//! | a fit's GGX / Beckmann model | [`analytic`] | `shade_microfacet.wgsl` | [`lobe::LobeBlock`] |
//! | a fit's tabulated NDF | [`tabulated`] | `shade_microfacet.wgsl`, TABULATED | [`lobe::LobeBlock`] |
//! | a MERL-grid measurement | [`merl`] | `shade_microfacet.wgsl`, MEASURED | lobe, then [`merl::MerlBlock`] |
//! | an RGL `.bsdf` | [`rgl`] | `shade_rgl.wgsl` | [`rgl::RglBlock`] |
//! | glints | [`glint`] | `shade_glint.wgsl`, one per material | [`lobe::LobeBlock`] |
//!
//! The coat ([`coat`]) is a layer over any fitted class, named by the record's header. A new
//! class adds its file here, its variant to [`MaterialKind`] (`layout/tags.rs`; the compiler
//! then asks for its arms in this file: its name, its stage), its choice in [`plan`], its block
//! in [`class_blocks`], and its WGSL.

pub mod analytic;
pub mod coat;
pub mod glint;
pub mod gltf;
pub mod lobe;
pub mod merl;
pub mod record;
pub mod rgl;
pub mod tabulated;

pub use lobe::FRESNEL_NODES;
pub use record::GpuMaterial;

use crate::error::RenderError;
use crate::layout::bindings::{self, Group};
use crate::layout::gpu_types::{MaterialKind, NONE};
use crate::layout::queues::Queue;
use crate::layout::tables::Tables;
use crate::scene::{GlintParams, Material, Measurement};
use facet_brdf::model::coat::CoatLayer;
use facet_brdf::model::microfacet::{Ndf, NdfKind};
use facet_brdf::model::tabulated::TabulatedNdf;
use record::{BlockLayout, ClassBlock};
use std::sync::Arc;

/// A class's shading stage: its pipeline file, entry point, bind groups and override
/// constants (the integrator adds the queue's, `Q_SHADE`).
#[derive(Clone, Debug)]
pub struct ShadeStage {
    /// The pipeline file under `shaders/`.
    pub file: &'static str,
    /// Its entry point.
    pub entry: &'static str,
    /// The groups of its pipeline layout, in group order.
    pub groups: &'static [Group],
    /// Its override constants.
    pub constants: Vec<(&'static str, f64)>,
}

impl ShadeStage {
    /// A stage of `file`'s `entry` over the path state and the scene, with `constants`.
    pub fn new(
        file: &'static str,
        entry: &'static str,
        constants: Vec<(&'static str, f64)>,
    ) -> Self {
        ShadeStage {
            file,
            entry,
            groups: bindings::STAGE,
            constants,
        }
    }
}

impl MaterialKind {
    /// The class's name, as `Built::classes` lists it.
    pub const fn name(self) -> &'static str {
        match self {
            MaterialKind::Gltf => "diffuse",
            MaterialKind::Analytic => "analytic",
            MaterialKind::Tabulated => "tabulated",
            MaterialKind::Merl => "measured MERL",
            MaterialKind::Rgl => "measured RGL",
            MaterialKind::Glint => "glint",
        }
    }

    /// The class's shading stage.
    pub fn stage(self) -> ShadeStage {
        match self {
            MaterialKind::Gltf => gltf::stage(),
            MaterialKind::Analytic => analytic::stage(),
            MaterialKind::Tabulated => tabulated::stage(),
            MaterialKind::Merl => merl::stage(),
            MaterialKind::Rgl => rgl::stage(),
            MaterialKind::Glint => glint::stage(),
        }
    }
}

/// Every class block, in the order `shaders/render/materials/blocks.inc.wgsl` holds them.
pub fn class_blocks() -> Vec<BlockLayout> {
    vec![
        gltf::GltfBlock::LAYOUT,
        lobe::LobeBlock::LAYOUT,
        merl::MerlBlock::LAYOUT,
        rgl::RglBlock::LAYOUT,
    ]
}

/// The committed `shaders/render/materials/blocks.inc.wgsl`, generated.
pub fn wgsl() -> String {
    record::wgsl(&class_blocks())
}

/// An uploaded material as the CPU knows it: its GPU record and, as types, the class, NDF kind
/// and shading queue that the record carries for the GPU. The CPU reads these from here; the
/// record's queue is written from them, never parsed back.
#[derive(Clone, Copy, Debug)]
pub struct MaterialSlot {
    gpu: GpuMaterial,
    kind: MaterialKind,
    ndf: Option<NdfKind>,
    queue: Queue,
}

impl MaterialSlot {
    /// `gpu` with its queue written from `queue`.
    pub(crate) fn new(
        gpu: GpuMaterial,
        kind: MaterialKind,
        ndf: Option<NdfKind>,
        queue: Queue,
    ) -> Self {
        let mut slot = MaterialSlot {
            gpu,
            kind,
            ndf,
            queue,
        };
        slot.set_queue(queue);
        slot
    }

    /// The record as uploaded.
    pub fn gpu(&self) -> &GpuMaterial {
        &self.gpu
    }

    /// The material's class.
    pub fn kind(&self) -> MaterialKind {
        self.kind
    }

    /// The analytic NDF's kind (`None`: a glTF material, or a tabulated NDF).
    pub fn ndf(&self) -> Option<NdfKind> {
        self.ndf
    }

    /// The shading queue its hits go to.
    pub(crate) fn queue(&self) -> Queue {
        self.queue
    }

    /// Routes the material's hits to `queue`.
    pub(crate) fn set_queue(&mut self, queue: Queue) {
        self.queue = queue;
        self.gpu.queue = queue.index();
    }

    /// The slot with the record's table offsets and queue taken from `old` (an update in place
    /// of a fitted class, whose tables are its lobe's).
    pub(crate) fn in_place_of(self, old: &MaterialSlot) -> MaterialSlot {
        let mut slot = self;
        let was = lobe::of(&old.gpu);
        lobe::set_tables(&mut slot.gpu, Some(was.fresnel), Some(was.table));
        slot.set_queue(old.queue);
        slot
    }
}

/// What one material needs on the GPU: its slot (table offsets and a glint material's queue
/// still to be assigned), its Fresnel table, its tabulated NDF, its glint parameters, its
/// measurement, its coat.
pub struct MaterialPlan<'a> {
    /// The material's record and class.
    pub slot: MaterialSlot,
    /// F(θd) at FRESNEL_NODES nodes, RGB interleaved (fitted classes).
    pub fresnel: Option<Vec<f32>>,
    /// A tabulated NDF.
    pub tabulated: Option<&'a TabulatedNdf>,
    /// A glint material's NDF and parameters.
    pub glint: Option<(Ndf, GlintParams)>,
    /// A measured material's data, placed once per scene however many materials share it.
    pub measured: Option<&'a Arc<Measurement>>,
    /// A coated fit's coat (its base is the plan's model).
    pub coat: Option<&'a CoatLayer>,
}

impl MaterialPlan<'_> {
    /// The plan of `slot` alone, no tables.
    pub(crate) fn new(slot: MaterialSlot) -> Self {
        MaterialPlan {
            slot,
            fresnel: None,
            tabulated: None,
            glint: None,
            measured: None,
            coat: None,
        }
    }

    /// Whether `self` fits in place of `old` (the slot uploaded before): the same class and
    /// NDF kind, no glints, so the same tables at the same offsets.
    pub fn fits_in_place_of(&self, old: &MaterialSlot) -> Result<(), &'static str> {
        if self.glint.is_some() || old.kind == MaterialKind::Glint {
            return Err("glint materials are rebuilt");
        }
        let measured = |k| matches!(k, MaterialKind::Merl | MaterialKind::Rgl);
        if self.measured.is_some() || measured(old.kind) {
            return Err("measured materials are rebuilt");
        }
        if self.coat.is_some() || old.gpu.coat != NONE {
            return Err("coated materials are rebuilt");
        }
        if self.slot.kind != old.kind || self.slot.ndf != old.ndf {
            return Err("the material class changed");
        }
        if self.fresnel.is_none() {
            return Err("not a fitted material");
        }
        Ok(())
    }

    /// Appends the plan's tables (Fresnel, tabulated NDF, coat) to `tables` and sets their
    /// offsets; a tabulated NDF already in `placed` (one fit named by many materials) is not
    /// appended again. Whether a tabulated NDF was appended.
    pub fn place_tables(
        &mut self,
        tables: &mut Tables,
        source: &str,
        placed: &mut tabulated::PlacedNdfs,
    ) -> bool {
        // Per material: an update in place rewrites it.
        let fresnel = self
            .fresnel
            .as_ref()
            .map(|f| tables.push(source, f.iter().copied()));
        let mut appended = false;
        let table = self.tabulated.map(|tab| {
            let key = std::ptr::from_ref(tab);
            match placed.iter().find(|(k, _)| *k == key) {
                Some(&(_, at)) => at,
                None => {
                    let at = tables.push(source, tabulated::tabulated_block(tab));
                    placed.push((key, at));
                    appended = true;
                    at
                }
            }
        });
        if fresnel.is_some() || table.is_some() {
            lobe::set_tables(&mut self.slot.gpu, fresnel, table);
        }
        if let Some(layer) = self.coat {
            self.slot.gpu.coat = tables.push(source, coat::coat_block(layer));
        }
        appended
    }

    /// Points the record at its measured table in the scene tables.
    pub(crate) fn set_measured_offset(&mut self, offset: u32) {
        match self.slot.kind {
            MaterialKind::Merl => merl::set_table(&mut self.slot.gpu, offset),
            MaterialKind::Rgl => rgl::set_table(&mut self.slot.gpu, offset),
            _ => debug_assert!(false, "{:?} has no measured table", self.slot.kind),
        }
    }
}

/// A measurement's block in the `tables` buffer: a MERL grid ([`merl::merl_block`]) or an RGL
/// file ([`rgl::rgl_block`]).
pub fn measured_block(data: &Measurement) -> Vec<f32> {
    match data {
        Measurement::Merl(table) => merl::merl_block(table),
        Measurement::Rgl(bsdf) => rgl::rgl_block(bsdf),
    }
}

/// The header every class shares: emission, normal map.
fn header(m: &Material) -> GpuMaterial {
    GpuMaterial {
        emissive: m.emissive.to_array(),
        tex_emissive: m.emissive_texture.unwrap_or(NONE),
        tex_normal: m.normal_texture.unwrap_or(NONE),
        normal_scale: m.normal_scale,
        ..Default::default()
    }
}

/// The plan of material `m`: a measured material by its measurement's class, a fitted one by
/// its model's NDF (and glints), else glTF metallic-roughness.
pub fn plan(m: &Material) -> Result<MaterialPlan<'_>, RenderError> {
    let gpu = header(m);
    if let Some(measured) = &m.measured {
        let mut plan = match (&*measured.data, &measured.fit) {
            (Measurement::Merl(_), None) => {
                return Err(RenderError::Scene(format!(
                    "material `{}`: the MERL-grid measurement {} has no fit to be sampled by: \
                     name one beside it (`extras.facet.fit`, or a fit JSON as the source), or \
                     fit it before building the scene (`Scene::fit_measured`, as `facet render` \
                     does)",
                    m.name, measured.source
                )));
            }
            (Measurement::Merl(_), Some(fit)) => merl::plan(gpu, fit),
            (Measurement::Rgl(_), _) => rgl::plan(gpu),
        };
        plan.measured = Some(&measured.data);
        return Ok(plan);
    }
    let Some(f) = &m.facet else {
        return Ok(gltf::plan(gpu, m));
    };
    // A fit that kept a coat renders its coated model: a glint material its base's flakes
    // under the coat.
    let coated = f.fit.coated.as_deref();
    let fit = coated.map_or(&*f.fit, |c| &c.base);
    let brdf = fit.model(f.model).ok_or_else(|| {
        RenderError::input(
            &f.source,
            format!("material {:?}: the fit has no {:?} model", m.name, f.model),
        )
    })?;
    let mut plan = match (&brdf.ndf, f.glint) {
        (_, Some(params)) => glint::plan(gpu, brdf, fit, params),
        (Ndf::Analytic(_), None) => analytic::plan(gpu, brdf, fit),
        (Ndf::Tabulated(_), None) => tabulated::plan(gpu, brdf, fit),
    };
    plan.coat = coated.map(|c| &c.layer);
    Ok(plan)
}
