//! A scene material to its GPU record: the one conversion both the first upload and
//! [`SceneResources::update_material`](super::SceneResources::update_material) use.

use super::tables::Tables;
use crate::error::RenderError;
use crate::layout::gpu_types::{GpuMaterial, MaterialKind, NONE};
use crate::layout::queues::Queue;
use crate::scene::{GlintParams, Material, MeasuredMaterial, Measurement};
use facet_brdf::model::coat::CoatLayer;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::merl_grid::{MerlTable, SAMPLES};
use facet_brdf::model::microfacet::{MicrofacetBrdf, Ndf, NdfKind};
use facet_brdf::model::tabulated::TabulatedNdf;
use facet_glint::tags::NdfTag;
use std::sync::Arc;

/// Fresnel tables are resampled on this many θd nodes over [0, π/2], inclusive.
pub const FRESNEL_NODES: usize = 91;

/// The GGX α the ray cone widens by where a material states none (a tabulated fit without a
/// GGX model, an RGL file): a moderately rough lobe.
const UNKNOWN_CONE_ALPHA: f32 = 0.3;

/// An uploaded material as the CPU knows it: its GPU record and, as types, the class, NDF kind
/// and shading queue that the record carries as tags for the GPU. The CPU reads these from here;
/// the record's tags are written from them, never parsed back.
#[derive(Clone, Copy, Debug)]
pub struct MaterialSlot {
    gpu: GpuMaterial,
    kind: MaterialKind,
    ndf: Option<NdfKind>,
    queue: Queue,
}

impl MaterialSlot {
    /// `gpu` with its class and queue tags written from `kind` and `queue`.
    fn new(gpu: GpuMaterial, kind: MaterialKind, ndf: Option<NdfKind>, queue: Queue) -> Self {
        let mut slot = MaterialSlot {
            gpu,
            kind,
            ndf,
            queue,
        };
        slot.gpu.kind = kind as u32;
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

    /// Points the record at its measured table in `tables`.
    pub(crate) fn set_measured_offset(&mut self, offset: u32) {
        self.gpu.measured_offset = offset;
    }

    /// Routes the material's hits to `queue`.
    pub(crate) fn set_queue(&mut self, queue: Queue) {
        self.queue = queue;
        self.gpu.queue = queue.index();
    }

    /// The slot with the record's table offsets and queue taken from `old` (an update in place).
    pub(crate) fn in_place_of(self, old: &MaterialSlot) -> MaterialSlot {
        let mut slot = MaterialSlot {
            gpu: GpuMaterial {
                fresnel_offset: old.gpu.fresnel_offset,
                fresnel_count: old.gpu.fresnel_count,
                tab_offset: old.gpu.tab_offset,
                ..self.gpu
            },
            ..self
        };
        slot.set_queue(old.queue);
        slot
    }
}

/// What one material needs on the GPU: its slot (table offsets and a glint material's queue
/// still to be assigned), its Fresnel table, its tabulated NDF, its glint parameters.
pub struct MaterialPlan<'a> {
    /// The material's record and class.
    pub slot: MaterialSlot,
    /// F(θd) at FRESNEL_NODES nodes, RGB interleaved (fitted materials).
    pub fresnel: Option<Vec<f32>>,
    /// A tabulated material's NDF.
    pub tabulated: Option<&'a TabulatedNdf>,
    /// A glint material's NDF and parameters.
    pub glint: Option<(Ndf, GlintParams)>,
    /// A measured material's data, placed once per scene however many materials share it.
    pub measured: Option<&'a Arc<Measurement>>,
    /// A coated fit's coat (its base is the plan's model).
    pub coat: Option<&'a CoatLayer>,
}

impl MaterialPlan<'_> {
    /// Whether `self` fits in place of `old` (the slot uploaded before): the same class and
    /// NDF kind, no glints, so the same tables at the same offsets.
    pub fn fits_in_place_of(&self, old: &MaterialSlot) -> Result<(), &'static str> {
        if self.glint.is_some() || old.kind == MaterialKind::Glint {
            return Err("glint materials are rebuilt");
        }
        if self.measured.is_some() || old.kind == MaterialKind::Measured {
            return Err("measured materials are rebuilt");
        }
        if self.coat.is_some() || old.gpu.coat_block != NONE {
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

    /// Appends the plan's tables (Fresnel, tabulated NDF) to `tables` and sets their offsets;
    /// a tabulated NDF already in `placed` (one fit named by many materials) is not appended
    /// again. Whether a tabulated NDF was appended.
    pub fn place_tables(
        &mut self,
        tables: &mut Tables,
        source: &str,
        placed: &mut PlacedNdfs,
    ) -> bool {
        if let Some(f) = &self.fresnel {
            // Per material: an update in place rewrites it.
            self.slot.gpu.fresnel_offset = tables.push(source, f.iter().copied());
            self.slot.gpu.fresnel_count = FRESNEL_NODES as u32;
        }
        let mut appended = false;
        if let Some(tab) = self.tabulated {
            let key = std::ptr::from_ref(tab);
            self.slot.gpu.tab_offset = match placed.iter().find(|(k, _)| *k == key) {
                Some(&(_, at)) => at,
                None => {
                    let at = tables.push(source, tabulated_block(tab));
                    placed.push((key, at));
                    appended = true;
                    at
                }
            };
        }
        if let Some(layer) = self.coat {
            let gpu = &mut self.slot.gpu;
            gpu.coat_block = tables.push(source, coat_block(layer));
            gpu.coat_weight = layer.coat.weight as f32;
            gpu.coat_alpha = layer.coat.alpha as f32;
            gpu.coat_eta = layer.coat.eta as f32;
        }
        appended
    }
}

/// The tabulated NDFs a scene's tables hold, by address, with their offsets: an NDF shared by
/// many materials (the fit they all name) is placed once (about 1 MB each).
pub type PlacedNdfs = Vec<(*const TabulatedNdf, u32)>;

/// A tabulated NDF's block in the `tables` buffer, as shaders/render/tabulated.inc.wgsl reads
/// it: [nu, nphi, ng, n_theta_v, n_phi_v, rows, columns, 0], then D₀, G1₀, the D cos θ cells'
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

/// A coat's block as shaders/render/coat.inc.wgsl reads it: [n, E_c at the n nodes].
pub fn coat_block(layer: &CoatLayer) -> Vec<f32> {
    let nodes = layer.albedo_nodes();
    std::iter::once(nodes.len() as f32)
        .chain(nodes.iter().map(|&e| e as f32))
        .collect()
}

/// A MERL-grid table as shaders/render/merl.inc.wgsl reads it: f_r per sample, RGB
/// interleaved, −1 where missing.
pub fn merl_block(table: &MerlTable) -> Vec<f32> {
    (0..SAMPLES)
        .flat_map(|s| match table.value_at(s) {
            Some(v) => v.map(|x| x as f32),
            None => [-1.0; 3],
        })
        .collect()
}

/// A measurement's block in the `tables` buffer: a MERL grid ([`merl_block`]) or an RGL file.
pub fn measured_block(data: &Measurement) -> Vec<f32> {
    match data {
        Measurement::Merl(table) => merl_block(table),
        Measurement::Rgl(bsdf) => super::rgl_table::rgl_block(bsdf),
    }
}

fn texture(t: Option<u32>) -> u32 {
    t.unwrap_or(NONE)
}

/// The plan of material `m`. A fitted material takes its model's NDF, Fresnel and diffuse term;
/// a glint material renders that model's NDF (analytic or tabulated) as flakes; a measured
/// material is evaluated from its table, a MERL-grid one sampled by its fit's tabulated model.
pub fn plan(m: &Material) -> Result<MaterialPlan<'_>, RenderError> {
    let mut gpu = GpuMaterial {
        base_color: m.base_color.to_array(),
        emissive: m.emissive.extend(m.specular).to_array(),
        alpha_x: 1.0,
        alpha_y: 1.0,
        metallic: m.metallic,
        roughness: m.roughness,
        normal_scale: m.normal_scale,
        tex_base: texture(m.base_color_texture),
        tex_mr: texture(m.metallic_roughness_texture),
        tex_normal: texture(m.normal_texture),
        tex_emissive: texture(m.emissive_texture),
        coat_block: NONE,
        tex_clearcoat: NONE,
        tex_clearcoat_roughness: NONE,
        tex_clearcoat_normal: NONE,
        ..Default::default()
    };
    if let Some(c) = &m.clearcoat {
        gpu.coat_weight = c.factor;
        gpu.coat_alpha = c.roughness;
        gpu.tex_clearcoat = texture(c.texture);
        gpu.tex_clearcoat_roughness = texture(c.roughness_texture);
        gpu.tex_clearcoat_normal = texture(c.normal_texture);
        gpu.clearcoat_normal_scale = c.normal_scale;
    }
    if let Some(measured) = &m.measured {
        return plan_measured(gpu, m, measured);
    }
    let Some(f) = &m.facet else {
        return Ok(MaterialPlan {
            slot: MaterialSlot::new(gpu, MaterialKind::Gltf, None, Queue::Diffuse),
            fresnel: None,
            tabulated: None,
            glint: None,
            measured: None,
            coat: None,
        });
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
    let mut plan = plan_model(gpu, brdf, fit);
    plan.coat = coated.map(|c| &c.layer);
    // A glint material keeps its NDF's parameters (and a tabulated one its tables) for the
    // glint stage's D, Λ and sampling.
    plan.glint = f.glint.map(|g| {
        plan.slot.kind = MaterialKind::Glint;
        plan.slot.gpu.kind = MaterialKind::Glint as u32;
        (brdf.ndf.clone(), g)
    });
    Ok(plan)
}

/// The plan of a fitted model `brdf` (of `fit`): its Fresnel table, diffuse term and NDF.
fn plan_model<'a>(
    mut gpu: GpuMaterial,
    brdf: &'a MicrofacetBrdf,
    fit: &FittedMaterial,
) -> MaterialPlan<'a> {
    let fresnel: Vec<f32> = (0..FRESNEL_NODES)
        .flat_map(|j| {
            let theta_d = j as f64 / (FRESNEL_NODES - 1) as f64 * std::f64::consts::FRAC_PI_2;
            brdf.fresnel.eval(theta_d.cos()).map(|v| v as f32)
        })
        .collect();
    gpu.diffuse = [
        brdf.diffuse[0] as f32,
        brdf.diffuse[1] as f32,
        brdf.diffuse[2] as f32,
        0.0,
    ];
    let mut tabulated = None;
    let (kind, ndf, queue) = match &brdf.ndf {
        Ndf::Analytic(a) => {
            gpu.ndf_kind = NdfTag::from(a.kind) as u32;
            (gpu.alpha_x, gpu.alpha_y) = (a.alpha_x as f32, a.alpha_y as f32);
            gpu.rotation = a.rotation as f32;
            gpu.roughness = (a.alpha_x * a.alpha_y).sqrt() as f32;
            (MaterialKind::Analytic, Some(a.kind), Queue::Analytic)
        }
        Ndf::Tabulated(tab) => {
            // The ray cone widens by the fit's GGX α where there is one.
            let cone_alpha = fit.record.ggx.as_ref().map_or(UNKNOWN_CONE_ALPHA, |p| {
                (p.alpha_x * p.alpha_y).sqrt() as f32
            });
            let s = &tab.stretch;
            (gpu.alpha_x, gpu.alpha_y) = (s.alpha_x as f32, s.alpha_y as f32);
            gpu.rotation = s.rotation as f32;
            gpu.roughness = cone_alpha * (s.alpha_x * s.alpha_y).sqrt() as f32;
            tabulated = Some(tab.as_ref());
            (MaterialKind::Tabulated, None, Queue::Tabulated)
        }
    };
    MaterialPlan {
        slot: MaterialSlot::new(gpu, kind, ndf, queue),
        fresnel: Some(fresnel),
        tabulated,
        glint: None,
        measured: None,
        coat: None,
    }
}

/// The plan of a measured material: a MERL-grid table with its fit's tabulated model (for
/// sampling and the lobe choice), or an RGL file alone. The table's offset is set when it is
/// placed.
fn plan_measured<'a>(
    gpu: GpuMaterial,
    m: &Material,
    measured: &'a MeasuredMaterial,
) -> Result<MaterialPlan<'a>, RenderError> {
    let mut plan = match (&*measured.data, &measured.fit) {
        (Measurement::Merl(_), None) => {
            return Err(RenderError::Scene(format!(
                "material `{}`: the MERL-grid measurement {} has no fit to be sampled by: name \
                 one beside it (`extras.facet.fit`, or a fit JSON as the source), \
                 or fit it before building the scene (`Scene::fit_measured`, as `facet render` does)",
                m.name, measured.source
            )));
        }
        (Measurement::Merl(_), Some(fit)) => {
            let mut plan = plan_model(gpu, &fit.tabulated, fit);
            plan.slot = MaterialSlot::new(plan.slot.gpu, MaterialKind::Measured, None, Queue::Merl);
            plan
        }
        (Measurement::Rgl(_), _) => {
            // The file states no α.
            let gpu = GpuMaterial {
                roughness: UNKNOWN_CONE_ALPHA,
                ..gpu
            };
            MaterialPlan {
                slot: MaterialSlot::new(gpu, MaterialKind::Measured, None, Queue::Rgl),
                fresnel: None,
                tabulated: None,
                glint: None,
                measured: None,
                coat: None,
            }
        }
    };
    plan.measured = Some(&measured.data);
    Ok(plan)
}
