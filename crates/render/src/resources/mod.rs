//! What the renderer builds on the GPU for one scene, and the record of it.
//!
//! Only what the scene uses is made: a shading pipeline per material class present, a DPF
//! pyramid (two levels) per glint material, the environment's tables only with an environment,
//! the per-triangle light index only when a triangle emits. [`Built`] records each of them so
//! callers (and tests) can see what a scene cost.

mod environment;
mod glints;
pub mod light_bvh;
mod lights;
mod textures;

pub use crate::materials::{FRESNEL_NODES, MaterialSlot};

use crate::bvh::{Bvh, BvhConfig, GpuBvh};
use crate::error::RenderError;
use crate::layout::gpu_types::{GpuLight, GpuSceneInfo};
use crate::layout::limits::{DeviceLimits, Planned, product};
use crate::layout::queues::Queue;
use crate::layout::tables::Tables;
use crate::materials;
use crate::materials::GpuMaterial;
use crate::scene::{Environment, GlintParams, Measurement, Scene};
use facet_brdf::model::microfacet::Ndf;
use facet_glint::dpf::DpfConfig;
use facet_glint::gpu::GpuDpf;
use facet_gpu::{Gpu, buffer};
use light_bvh::GpuLightNode;
pub use lights::LightSelection;
use lights::LightSet;
use std::sync::Arc;

/// The record of what was built for a scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Built {
    /// Material classes with a shading pipeline, by name ("diffuse", "analytic", "tabulated",
    /// "glint").
    pub classes: Vec<&'static str>,
    /// DPF pyramids (one per glint material) and their levels in degrees.
    pub glint_pyramids: Vec<Vec<f64>>,
    /// Textures uploaded.
    pub textures: usize,
    /// Whether the environment is a map (not a constant).
    pub environment_map: bool,
    /// Tabulated NDFs uploaded (one per fit, however many materials name it).
    pub tabulated_tables: usize,
    /// Measured tables uploaded (one per measurement, however many materials share it).
    pub measured_tables: usize,
    /// Triangles with emission.
    pub emissive_triangles: usize,
    /// Lights of every kind.
    pub lights: usize,
    /// Nodes of the CWBVH.
    pub bvh_nodes: usize,
    /// Time to build the BVH, milliseconds.
    pub bvh_build_ms: f64,
    /// Time to build the DPF pyramids, milliseconds.
    pub glint_build_ms: f64,
    /// The probability of picking each light (punctual, emissive triangles, environment) by
    /// the CDF; with [`LightSelection::Bvh`], of the lights outside the tree when the tree is
    /// not asked (the tree's own picks depend on the shading point).
    pub light_pmf: Vec<f32>,
    /// With [`LightSelection::Bvh`]: the probability of asking the light BVH.
    pub light_tree_share: f32,
    /// Nodes of the light BVH (0 without one).
    pub light_tree_nodes: usize,
    /// Time to build the light BVH, milliseconds.
    pub light_tree_ms: f64,
    /// Why the light BVH asked for was not used (over the adapter's storage binding limit):
    /// the lights are then picked by [`LightSelection::Robust`].
    pub light_tree_fallback: Option<String>,
}

/// One glint material's GPU resources (bind group 2 of its shading stage).
pub struct GlintResources {
    /// Its material index.
    pub material: u32,
    /// Its DPF pyramid on the GPU.
    pub dpf: GpuDpf,
    /// The flake field uniform.
    pub field: wgpu::Buffer,
    /// The flake counts of the top of its quadtree (`facet_glint::flakes::SplitTable`).
    pub split_table: wgpu::Buffer,
    /// The evaluation parameters uniform.
    pub params: wgpu::Buffer,
    /// The finer of the two pyramid levels bound.
    pub level0: wgpu::TextureView,
    /// The coarser of the two pyramid levels bound.
    pub level1: wgpu::TextureView,
}

/// The scene on the GPU (bind group 1 of every stage).
pub struct SceneResources {
    /// The CWBVH.
    pub bvh: GpuBvh,
    /// Vertex attributes.
    pub vertices: wgpu::Buffer,
    /// Triangle records.
    pub triangles: wgpu::Buffer,
    /// Material records.
    pub materials: wgpu::Buffer,
    /// Texels of every texture.
    pub textures: wgpu::Buffer,
    /// Punctual lights and emissive triangles as light records.
    pub lights: wgpu::Buffer,
    /// The scene tables (f32 words: Fresnel and NDF tables, the environment map and its CDFs, the light-selection CDF).
    pub tables: wgpu::Buffer,
    /// The light of each emissive triangle.
    pub triangle_light: wgpu::Buffer,
    /// The light BVH's nodes (one unused node without a tree).
    pub light_tree: wgpu::Buffer,
    /// The GPU state of each glint material.
    pub glints: Vec<GlintResources>,
    /// Which shading queues have hits routed to them.
    pub queues_used: Vec<Queue>,
    /// The scene's part of the frame uniform: sizes, the light-selection CDF, the environment.
    pub scene_info: GpuSceneInfo,
    /// What was built.
    pub built: Built,
    /// The materials as uploaded, with their class and queue (for
    /// [`SceneResources::update_material`]).
    pub material_slots: Vec<MaterialSlot>,
}

/// Settings of the resources that are not in the scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResourceConfig {
    /// How the BVH is built.
    pub bvh: BvhConfig,
    /// DPF table resolution of glint materials.
    pub dpf: DpfConfig,
    /// Whether the glint count may be replaced by its mean above the threshold.
    pub glint_filter: bool,
    /// How next-event estimation picks a light.
    pub light_selection: LightSelection,
}

impl ResourceConfig {
    /// The medium BVH, the standard DPF tables, the glint filter on, the light BVH.
    pub const fn standard() -> Self {
        ResourceConfig {
            bvh: BvhConfig::medium(),
            dpf: DpfConfig::standard(),
            glint_filter: true,
            light_selection: LightSelection::Bvh,
        }
    }
}

impl SceneResources {
    /// Uploads `scene` and `environment` to `gpu`.
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        environment: Option<&Environment>,
        config: ResourceConfig,
    ) -> Result<Self, RenderError> {
        validate(scene)?;
        let d = &gpu.device;
        let limits = DeviceLimits::of(d);
        let mut built = Built::default();
        let mut tables = Tables::default();

        let bvh = build_bvh(scene, config.bvh, &limits, &mut built)?;
        let gpu_bvh = GpuBvh::upload(d, &bvh)?;
        let (vertices, triangles) = geometry(scene);
        let (slots, glint_specs) = plan_materials(scene, &mut tables, &mut built)?;
        // Only materials some triangle uses decide which pipelines and pyramids are built.
        let mut used = vec![false; slots.len()];
        for &m in &scene.triangle_material {
            used[m as usize] = true;
        }
        let queues_used = queues_used(&slots, &used, &mut built);

        let t = std::time::Instant::now();
        let mut glints = Vec::new();
        for (mi, ndf, spec) in glint_specs {
            if used[mi as usize] {
                let (g, levels) = glints::build(gpu, &limits, &config, mi, ndf, spec)?;
                glints.push(g);
                built.glint_pyramids.push(levels);
            }
        }
        built.glint_build_ms = t.elapsed().as_secs_f64() * 1e3;

        let tex_words = textures::texture_words(&scene.textures);
        built.textures = scene.textures.len();

        let materials: Vec<GpuMaterial> = slots.iter().map(|s| *s.gpu()).collect();
        let (lo, hi) = scene.bounds();
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        let mut light_set = LightSet::new(scene, &bvh, &materials, radius);
        built.emissive_triangles = light_set.emissive_triangles();
        let env = environment::place(environment, &mut tables, &mut light_set, &limits, radius)?;
        built.environment_map = env.kind == crate::layout::tags::EnvKind::Map;
        let PlacedLights {
            lights,
            triangle_light,
            light_tree,
            light_cdf,
        } = place_lights(
            light_set,
            config.light_selection,
            &limits,
            &mut tables,
            &mut built,
        );
        if tables.words.is_empty() {
            tables.words.push(0.0);
        }
        check_buffers(
            &limits,
            scene,
            &built,
            Buffers {
                vertices: vertices.len(),
                triangles: triangles.len(),
                materials: materials.len(),
                texture_words: tex_words.len(),
                lights: lights.len(),
                tables: &tables,
                triangle_light: triangle_light.len(),
                light_tree: light_tree.len(),
            },
        )?;

        let res = gpu.scoped(|| SceneResources {
            vertices: buffer::storage(d, "vertices", &vertices),
            triangles: buffer::storage(d, "triangles", &triangles),
            materials: buffer::storage(d, "materials", &materials),
            material_slots: slots,
            textures: buffer::storage(d, "textures", &tex_words),
            lights: buffer::storage(d, "lights", &lights),
            tables: buffer::storage(d, "tables", &tables.words),
            triangle_light: buffer::storage(d, "triangle lights", &triangle_light),
            light_tree: buffer::storage(d, "light tree", &light_tree),
            bvh: gpu_bvh,
            glints,
            queues_used,
            scene_info: GpuSceneInfo {
                n_vertices: scene.positions.len() as u32,
                n_lights: built.lights as u32,
                light_cdf,
                env_kind: env.kind as u32,
                env_width: env.size.0,
                env_height: env.size.1,
                env_texels: env.offsets.0,
                env_marginal: env.offsets.1,
                env_conditional: env.offsets.2,
                scene_radius: radius,
                light_tree_share: built.light_tree_share,
                light_tree_nodes: built.light_tree_nodes as u32,
                env_color: env.color,
            },
            built,
        })?;
        Ok(res)
    }
}

/// The lights as uploaded: their records, the light of each triangle, the light BVH's nodes
/// (one unused node without a tree) and the word offset of the selection CDF in the tables.
struct PlacedLights {
    lights: Vec<GpuLight>,
    triangle_light: Vec<u32>,
    light_tree: Vec<GpuLightNode>,
    light_cdf: u32,
}

/// The lights of `light_set` picked by `selection`: its CDF placed in `tables`, the tree built
/// (or, over the device's storage binding limit, the robust selection instead, said in
/// `built`), every light's leaf recorded; never empty buffers.
fn place_lights(
    light_set: LightSet,
    selection: LightSelection,
    limits: &DeviceLimits,
    tables: &mut Tables,
    built: &mut Built,
) -> PlacedLights {
    let t = std::time::Instant::now();
    let mut picked = light_set.selection(selection);
    built.light_tree_ms = t.elapsed().as_secs_f64() * 1e3;
    let tree_bytes = product(&[
        picked.tree.nodes.len() as u64,
        std::mem::size_of::<GpuLightNode>() as u64,
    ]);
    if let Err(e) = limits.check(&[Planned::storage(
        "the light BVH",
        tree_bytes,
        format!("the scene's {} lights", light_set.lights.len()),
    )]) {
        built.light_tree_fallback = Some(format!("{e}; lights picked by the robust selection"));
        picked = light_set.selection(LightSelection::Robust);
    }
    let light_cdf = LightSet::place_cdf(&picked.cdf_pmf, tables);
    built.light_pmf = picked.cdf_pmf;
    built.light_tree_share = picked.tree_share;
    built.light_tree_nodes = picked.tree.nodes.len();
    let LightSet {
        mut lights,
        triangle_light,
        ..
    } = light_set;
    for (l, leaf) in lights.iter_mut().zip(&picked.tree.leaf_of) {
        l.leaf = *leaf;
    }
    built.lights = lights.len();
    if lights.is_empty() {
        lights.push(GpuLight::default());
    }
    let mut light_tree = picked.tree.nodes;
    if light_tree.is_empty() {
        light_tree.push(GpuLightNode::default());
    }
    PlacedLights {
        lights,
        triangle_light,
        light_tree,
        light_cdf,
    }
}

/// The scene's CWBVH, checked against the device's limits before it is uploaded.
fn build_bvh(
    scene: &Scene,
    config: BvhConfig,
    limits: &DeviceLimits,
    built: &mut Built,
) -> Result<Bvh, RenderError> {
    let t = std::time::Instant::now();
    let bvh = Bvh::build(&scene.positions, &scene.indices, config);
    built.bvh_build_ms = t.elapsed().as_secs_f64() * 1e3;
    built.bvh_nodes = bvh.cwbvh.nodes.len();
    let bvh_set_by = format!("the scene ({} triangles)", scene.indices.len());
    limits.check(&[
        Planned::storage(
            "the BVH nodes",
            product(&[bvh.cwbvh.nodes.len() as u64, 80]),
            &bvh_set_by,
        ),
        Planned::storage(
            "the BVH primitives",
            product(&[bvh.cwbvh.primitive_indices.len() as u64, 4]),
            &bvh_set_by,
        ),
        Planned::storage(
            "the BVH triangles",
            product(&[bvh.cwbvh.primitive_indices.len() as u64, 48]),
            &bvh_set_by,
        ),
    ])?;
    Ok(bvh)
}

/// The vertex records (four regions of n vectors: position, normal, tangent, uv) and the
/// triangle records (three indices and the material).
fn geometry(scene: &Scene) -> (Vec<[f32; 4]>, Vec<[u32; 4]>) {
    let n = scene.positions.len();
    let mut vertices: Vec<[f32; 4]> = Vec::with_capacity(4 * n);
    vertices.extend(scene.positions.iter().map(|p| p.extend(1.0).to_array()));
    vertices.extend(scene.normals.iter().map(|p| p.extend(0.0).to_array()));
    vertices.extend(scene.tangents.iter().map(|t| t.to_array()));
    vertices.extend(scene.uvs.iter().map(|u| [u.x, u.y, 0.0, 0.0]));
    let triangles: Vec<[u32; 4]> = scene
        .indices
        .iter()
        .zip(&scene.triangle_material)
        .map(|(i, m)| [i[0], i[1], i[2], *m])
        .collect();
    (vertices, triangles)
}

/// A glint material to build: its index, its NDF and its parameters.
type GlintSpec = (u32, Ndf, GlintParams);

/// The materials' slots with their Fresnel and NDF tables placed; glint materials get a queue
/// each, in material order, and are returned to be built.
fn plan_materials(
    scene: &Scene,
    tables: &mut Tables,
    built: &mut Built,
) -> Result<(Vec<MaterialSlot>, Vec<GlintSpec>), RenderError> {
    let mut slots = Vec::with_capacity(scene.materials.len());
    let mut glint_specs = Vec::new();
    // Each measurement's table, and each fit's tabulated NDF, once, however many materials
    // render it.
    let mut measured_at: Vec<(*const Measurement, u32)> = Vec::new();
    let mut ndfs_at = materials::tabulated::PlacedNdfs::new();
    for (mi, m) in scene.materials.iter().enumerate() {
        let mut plan = materials::plan(m)?;
        let what = match (&m.measured, &m.facet) {
            (Some(mm), _) => format!("the measurement {} of material `{}`", mm.source, m.name),
            (None, Some(f)) => format!("the fit {} of material `{}`", f.source.display(), m.name),
            (None, None) => String::new(),
        };
        if plan.place_tables(tables, &what, &mut ndfs_at) {
            built.tabulated_tables += 1;
        }
        if let Some(data) = plan.measured {
            let key = Arc::as_ptr(data);
            let offset = match measured_at.iter().find(|(k, _)| *k == key) {
                Some(&(_, at)) => at,
                None => {
                    let at = tables.push(&what, materials::measured_block(data));
                    built.measured_tables += 1;
                    measured_at.push((key, at));
                    at
                }
            };
            plan.set_measured_offset(offset);
        }
        if let Some((ndf, spec)) = plan.glint {
            plan.slot.set_queue(Queue::Glint(glint_specs.len() as u32));
            glint_specs.push((mi as u32, ndf, spec));
        }
        slots.push(plan.slot);
    }
    Ok((slots, glint_specs))
}

/// The shading queues the `used` materials route hits to, in queue order, once each; their
/// classes go to `built`.
fn queues_used(slots: &[MaterialSlot], used: &[bool], built: &mut Built) -> Vec<Queue> {
    let mut queues: Vec<Queue> = slots
        .iter()
        .zip(used)
        .filter(|(_, u)| **u)
        .map(|(m, _)| m.queue())
        .collect();
    queues.sort_by_key(|q| q.index());
    queues.dedup();
    built.classes = queues
        .iter()
        .filter_map(|q| q.class())
        .map(|k| k.name())
        .collect();
    built.classes.dedup();
    queues
}

/// The sizes of the scene's buffers, in records (words for the textures).
struct Buffers<'a> {
    vertices: usize,
    triangles: usize,
    materials: usize,
    texture_words: usize,
    lights: usize,
    tables: &'a Tables,
    triangle_light: usize,
    light_tree: usize,
}

/// Every scene buffer within the device's limits, or an error that names the input that set
/// its size.
fn check_buffers(
    limits: &DeviceLimits,
    scene: &Scene,
    built: &Built,
    b: Buffers,
) -> Result<(), RenderError> {
    let size_of = |n: usize, each: usize| product(&[n as u64, each as u64]);
    let n = scene.positions.len();
    let n_tri = scene.indices.len();
    let largest = scene
        .textures
        .iter()
        .max_by_key(|t| u64::from(t.width) * u64::from(t.height))
        .map_or(String::new(), |t| {
            format!("; the largest, {}, is {}×{}", t.name, t.width, t.height)
        });
    limits.check(&[
        Planned::storage(
            "the vertex buffer",
            size_of(b.vertices, 16),
            format!("the scene ({n} vertices)"),
        ),
        Planned::storage(
            "the triangle buffer",
            size_of(b.triangles, 16),
            format!("the scene ({n_tri} triangles)"),
        ),
        Planned::storage(
            "the material buffer",
            size_of(b.materials, std::mem::size_of::<GpuMaterial>()),
            format!("the scene ({} materials)", b.materials),
        ),
        Planned::storage(
            "the texture buffer",
            size_of(b.texture_words, 4),
            format!("the scene's {} textures{largest}", scene.textures.len()),
        ),
        Planned::storage(
            "the light buffer",
            size_of(b.lights, std::mem::size_of::<GpuLight>()),
            format!(
                "the scene ({} punctual lights, {} emissive triangles)",
                scene.lights.len(),
                built.emissive_triangles
            ),
        ),
        Planned::storage(
            "the scene tables",
            size_of(b.tables.words.len(), 4),
            b.tables.described(),
        ),
        Planned::storage(
            "the per-triangle light index",
            size_of(b.triangle_light, 4),
            format!("the scene ({n_tri} triangles)"),
        ),
        Planned::storage(
            "the light BVH",
            size_of(b.light_tree, std::mem::size_of::<GpuLightNode>()),
            format!(
                "the scene ({} punctual lights, {} emissive triangles)",
                scene.lights.len(),
                built.emissive_triangles
            ),
        ),
    ])?;
    Ok(())
}

impl GlintResources {
    /// Its bind group's resources, named as `shade_glint.wgsl` names them
    /// ([`Group::Glint`](crate::layout::bindings::Group::Glint)).
    pub fn bindings(&self) -> [(&'static str, wgpu::BindingResource<'_>); 5] {
        [
            ("field", self.field.as_entire_binding()),
            ("params", self.params.as_entire_binding()),
            ("level0", wgpu::BindingResource::TextureView(&self.level0)),
            ("level1", wgpu::BindingResource::TextureView(&self.level1)),
            ("split_table", self.split_table.as_entire_binding()),
        ]
    }
}

impl SceneResources {
    /// Its bind group's resources, named as `scene.inc.wgsl` names them
    /// ([`Group::Scene`](crate::layout::bindings::Group::Scene)).
    pub fn bindings(&self) -> [(&'static str, wgpu::BindingResource<'_>); 11] {
        [
            ("bvh_nodes", self.bvh.nodes.as_entire_binding()),
            ("bvh_primitives", self.bvh.primitives.as_entire_binding()),
            ("bvh_triangles", self.bvh.triangles.as_entire_binding()),
            ("vertices", self.vertices.as_entire_binding()),
            ("triangles", self.triangles.as_entire_binding()),
            ("materials", self.materials.as_entire_binding()),
            ("textures", self.textures.as_entire_binding()),
            ("lights", self.lights.as_entire_binding()),
            ("tables", self.tables.as_entire_binding()),
            ("triangle_light", self.triangle_light.as_entire_binding()),
            ("light_tree", self.light_tree.as_entire_binding()),
        ]
    }

    /// Rewrites material `index` in place from `scene.materials[index]`: its α, rotation,
    /// Fresnel table and diffuse albedo, at the offsets it already has. Edits that change
    /// the material's class, its NDF kind, its tables or its glint pyramids (another fit,
    /// glints on or off, a glint material's α or γ) return `Err`: those need new resources.
    pub fn update_material(
        &mut self,
        queue: &wgpu::Queue,
        scene: &Scene,
        index: usize,
    ) -> Result<(), RenderError> {
        let rebuild = |why: &str| Err(RenderError::Scene(format!("material {index}: {why}")));
        let (Some(m), Some(old)) = (scene.materials.get(index), self.material_slots.get(index))
        else {
            return rebuild("no such material");
        };
        let plan = materials::plan(m)?;
        if let Err(why) = plan.fits_in_place_of(old) {
            return rebuild(why);
        }
        // The new values at the old offsets, in the old queue.
        let slot = plan.slot.in_place_of(old);
        let g = slot.gpu();
        let fres = plan.fresnel.expect("checked by fits_in_place_of");
        queue.write_buffer(
            &self.tables,
            4 * materials::lobe::of(g).fresnel as u64,
            bytemuck::cast_slice(&fres),
        );
        queue.write_buffer(
            &self.materials,
            (index * std::mem::size_of::<GpuMaterial>()) as u64,
            bytemuck::bytes_of(g),
        );
        self.material_slots[index] = slot;
        Ok(())
    }
}

/// The invariants the GPU code relies on; a scene from the loader always meets them, one built in
/// code might not.
pub fn validate(scene: &Scene) -> Result<(), RenderError> {
    let n = scene.positions.len();
    let bad = |what: String| Err(RenderError::Scene(what));
    if scene.indices.is_empty() {
        return bad("the scene has no triangles".into());
    }
    if scene.normals.len() != n || scene.uvs.len() != n || scene.tangents.len() != n {
        return bad(format!(
            "{n} positions but {} normals, {} uvs, {} tangents",
            scene.normals.len(),
            scene.uvs.len(),
            scene.tangents.len()
        ));
    }
    if scene.triangle_material.len() != scene.indices.len() {
        return bad("one material per triangle is needed".into());
    }
    if let Some(i) = (0..n).find(|&i| {
        !(scene.positions[i].is_finite()
            && scene.normals[i].is_finite()
            && scene.uvs[i].is_finite()
            && scene.tangents[i].is_finite())
    }) {
        return bad(format!("vertex {i} is not finite"));
    }
    if let Some((t, _)) = scene
        .indices
        .iter()
        .enumerate()
        .find(|(_, tri)| tri.iter().any(|&i| i as usize >= n))
    {
        return bad(format!("triangle {t} indexes past the {n} vertices"));
    }
    if let Some(t) = scene
        .triangle_material
        .iter()
        .position(|&m| m as usize >= scene.materials.len())
    {
        return bad(format!("triangle {t} has no material"));
    }
    if let Some(m) = scene.materials.iter().find(|m| {
        [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.normal_texture,
            m.emissive_texture,
        ]
        .iter()
        .flatten()
        .any(|&t| t as usize >= scene.textures.len())
    }) {
        return bad(format!("material {:?} names a missing texture", m.name));
    }
    let glints = scene
        .materials
        .iter()
        .filter(|m| m.facet.as_ref().is_some_and(|f| f.glint.is_some()))
        .count();
    if glints > crate::layout::queues::MAX_GLINT_MATERIALS as usize {
        return bad(format!(
            "{glints} glint materials; at most {} are supported",
            crate::layout::queues::MAX_GLINT_MATERIALS
        ));
    }
    Ok(())
}
