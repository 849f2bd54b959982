//! What the renderer builds on the GPU for one scene, and the record of it.
//!
//! Only what the scene uses is made: a shading pipeline per material class present, a DPF
//! pyramid (two levels) per glint material, the environment's tables only with an environment,
//! the per-triangle light index only when a triangle emits. [`Built`] records each of them so
//! callers (and tests) can see what a scene cost.

use crate::bvh::{Bvh, BvhConfig, GpuBvh};
use crate::error::RenderError;
use crate::gpu_types::{GpuLight, GpuMaterial, LightKind, MaterialKind, NONE};
use crate::limits::{DeviceLimits, Planned, product};
use crate::queues::Queue;
use crate::scene::{Environment, FacetModel, Light, Scene};
use crate::tags::EnvKind;
use facet_fit::microfacet::{Ndf, NdfKind};
use facet_glint::dpf::DpfConfig;
use facet_glint::gpu::{GlintEvalParams, GlintField, GpuDpf};
use facet_gpu::{Gpu, buffer};
use glam::Vec3;

/// Fresnel tables are resampled on this many θd nodes over [0, π/2], inclusive.
pub const FRESNEL_NODES: usize = 91;

/// The record of what was built for a scene.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Built {
    /// Material classes with a shading pipeline, by name ("diffuse", "analytic", "tabulated",
    /// "glint").
    pub classes: Vec<&'static str>,
    /// DPF pyramids (one per glint material) and their levels in degrees.
    pub glint_pyramids: Vec<Vec<f64>>,
    pub textures: usize,
    pub environment_map: bool,
    pub tabulated_tables: usize,
    pub emissive_triangles: usize,
    pub lights: usize,
    pub bvh_nodes: usize,
    pub bvh_build_ms: f64,
    pub glint_build_ms: f64,
}

/// One glint material's GPU resources (bind group 2 of its shading stage).
pub struct GlintResources {
    pub material: u32,
    pub dpf: GpuDpf,
    pub field: wgpu::Buffer,
    pub params: wgpu::Buffer,
    pub level0: wgpu::TextureView,
    pub level1: wgpu::TextureView,
}

/// The scene on the GPU (bind group 1 of every stage).
pub struct SceneResources {
    pub bvh: GpuBvh,
    pub vertices: wgpu::Buffer,
    pub triangles: wgpu::Buffer,
    pub materials: wgpu::Buffer,
    pub textures: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub tables: wgpu::Buffer,
    pub triangle_light: wgpu::Buffer,
    pub glints: Vec<GlintResources>,
    /// Which shading queues have hits routed to them.
    pub queues_used: Vec<Queue>,
    pub n_vertices: u32,
    pub n_lights: u32,
    pub light_cdf: u32,
    pub env_kind: u32,
    pub env_size: (u32, u32),
    pub env_offsets: (u32, u32, u32),
    pub env_color: [f32; 4],
    pub scene_radius: f32,
    pub built: Built,
    /// The materials as uploaded (for [`SceneResources::update_material`]).
    pub material_data: Vec<GpuMaterial>,
}

/// Settings of the resources that are not in the scene file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResourceConfig {
    pub bvh: BvhConfig,
    /// DPF table resolution of glint materials.
    pub dpf: DpfConfig,
    /// Whether the glint count may be replaced by its mean above the threshold.
    pub glint_filter: bool,
}

impl ResourceConfig {
    pub const fn standard() -> Self {
        ResourceConfig {
            bvh: BvhConfig::medium(),
            dpf: DpfConfig::standard(),
            glint_filter: true,
        }
    }
}

fn rgb(v: [f64; 3]) -> [f32; 3] {
    [v[0] as f32, v[1] as f32, v[2] as f32]
}

fn lum(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The `tables` buffer under construction: f32 words at offsets, and how many words each input
/// (a fit file, the environment map, the scene's lights) put there.
#[derive(Default)]
struct Tables {
    words: Vec<f32>,
    sources: Vec<(String, u64)>,
}

impl Tables {
    fn push(&mut self, source: &str, values: impl IntoIterator<Item = f32>) -> u32 {
        let at = self.words.len() as u32;
        self.words.extend(values);
        let added = self.words.len() as u64 - u64::from(at);
        match self.sources.iter_mut().find(|(s, _)| s == source) {
            Some((_, n)) => *n += added,
            None => self.sources.push((source.to_owned(), added)),
        }
        at
    }

    /// What filled the tables, largest first: "the environment map sky.exr (12582912 bytes), …".
    fn described(&self) -> String {
        let mut by_size = self.sources.clone();
        by_size.sort_by_key(|(_, n)| std::cmp::Reverse(*n));
        let parts: Vec<String> = by_size
            .iter()
            .take(4)
            .map(|(s, n)| format!("{s} ({} bytes)", 4 * n))
            .collect();
        let more = by_size.len().saturating_sub(parts.len());
        if more > 0 {
            format!("{} and {more} more", parts.join(", "))
        } else {
            parts.join(", ")
        }
    }
}

impl SceneResources {
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

        let t = std::time::Instant::now();
        let bvh = Bvh::build(&scene.positions, &scene.indices, config.bvh);
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
        let gpu_bvh = GpuBvh::upload(d, &bvh)?;

        // Vertices: four regions of n vectors (position, normal, tangent, uv).
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

        // Materials, their Fresnel and NDF tables, the glint pyramids.
        let mut materials = Vec::with_capacity(scene.materials.len());
        let mut glint_specs = Vec::new();
        let mut queues_used = Vec::new();
        for (mi, m) in scene.materials.iter().enumerate() {
            let tex = |t: Option<u32>| t.unwrap_or(NONE);
            let mut g = GpuMaterial {
                base_color: m.base_color.to_array(),
                emissive: m.emissive.extend(m.specular).to_array(),
                kind: MaterialKind::Gltf as u32,
                alpha_x: 1.0,
                alpha_y: 1.0,
                metallic: m.metallic,
                roughness: m.roughness,
                normal_scale: m.normal_scale,
                tex_base: tex(m.base_color_texture),
                tex_mr: tex(m.metallic_roughness_texture),
                tex_normal: tex(m.normal_texture),
                tex_emissive: tex(m.emissive_texture),
                queue: Queue::Diffuse.index(),
                ..Default::default()
            };
            if let Some(f) = &m.facet {
                let choice = match f.model {
                    FacetModel::Tabulated => facet_fit::material::ModelChoice::Tabulated,
                    FacetModel::Ggx => facet_fit::material::ModelChoice::Ggx,
                    FacetModel::Beckmann => facet_fit::material::ModelChoice::Beckmann,
                };
                let brdf = f.fit.model(choice).ok_or_else(|| {
                    RenderError::input(
                        &f.source,
                        format!("material {:?}: the fit has no {:?} model", m.name, f.model),
                    )
                })?;
                let fres: Vec<f32> = (0..FRESNEL_NODES)
                    .flat_map(|j| {
                        let theta_d =
                            j as f64 / (FRESNEL_NODES - 1) as f64 * std::f64::consts::FRAC_PI_2;
                        rgb(brdf.fresnel.eval(theta_d.cos()))
                    })
                    .collect();
                let fit_source = format!("the fit {} of material `{}`", f.source.display(), m.name);
                g.fresnel_offset = tables.push(&fit_source, fres);
                g.fresnel_count = FRESNEL_NODES as u32;
                g.diffuse = [
                    brdf.diffuse[0] as f32,
                    brdf.diffuse[1] as f32,
                    brdf.diffuse[2] as f32,
                    0.0,
                ];
                // The ray cone widens by the fit's GGX α where there is one.
                let cone_alpha = f
                    .fit
                    .record
                    .ggx
                    .as_ref()
                    .map_or(0.3, |p| (p.alpha_x * p.alpha_y).sqrt() as f32);
                match &brdf.ndf {
                    Ndf::Analytic(a) => {
                        g.kind = MaterialKind::Analytic as u32;
                        g.ndf_kind = match a.kind {
                            NdfKind::Ggx => 0,
                            NdfKind::Beckmann => 1,
                        };
                        g.alpha_x = a.alpha_x as f32;
                        g.alpha_y = a.alpha_y as f32;
                        g.rotation = a.rotation as f32;
                        g.roughness = (a.alpha_x * a.alpha_y).sqrt() as f32;
                        g.queue = Queue::Analytic.index();
                    }
                    Ndf::Tabulated(tab) => {
                        let tt = tab.tables();
                        let (cdf, cell_pdf) = tab.sampling_tables();
                        let header = [tt.nu as f32, tt.nphi as f32, tt.ng as f32, 0.0];
                        g.tab_offset = tables.push(&fit_source, header);
                        tables.push(&fit_source, tt.d.iter().map(|v| *v as f32));
                        tables.push(&fit_source, tt.g1.iter().map(|v| *v as f32));
                        tables.push(&fit_source, cdf.iter().map(|v| *v as f32));
                        tables.push(&fit_source, cell_pdf.iter().map(|v| *v as f32));
                        g.kind = MaterialKind::Tabulated as u32;
                        g.alpha_x = tab.stretch.alpha_x as f32;
                        g.alpha_y = tab.stretch.alpha_y as f32;
                        g.rotation = tab.stretch.rotation as f32;
                        g.roughness =
                            cone_alpha * (tab.stretch.alpha_x * tab.stretch.alpha_y).sqrt() as f32;
                        g.queue = Queue::Tabulated.index();
                        built.tabulated_tables += 1;
                    }
                }
                if let Some(glint) = f.glint {
                    let Ndf::Analytic(a) = brdf.ndf.clone() else {
                        return Err(RenderError::input(
                            &f.source,
                            format!(
                                "material {:?}: glints need the fit's GGX or Beckmann model, not the tabulated one",
                                m.name
                            ),
                        ));
                    };
                    g.kind = MaterialKind::Glint as u32;
                    g.queue = Queue::Glint(glint_specs.len() as u32).index();
                    glint_specs.push((mi as u32, a, glint));
                }
            }
            if !queues_used.contains(&Queue::from_index(g.queue)) {
                queues_used.push(Queue::from_index(g.queue));
            }
            materials.push(g);
        }
        // Only materials some triangle uses decide which pipelines are built.
        let mut used = vec![false; materials.len()];
        for &m in &scene.triangle_material {
            used[m as usize] = true;
        }
        queues_used.retain(|q| {
            materials
                .iter()
                .zip(&used)
                .any(|(m, u)| *u && Queue::from_index(m.queue) == *q)
        });
        queues_used.sort_by_key(|q| q.index());
        built.classes = queues_used.iter().map(|q| q.class_name()).collect();
        built.classes.dedup();

        // Glint pyramids: the two levels bracketing each material's γ.
        let t = std::time::Instant::now();
        let mut glints = Vec::new();
        for (mi, ndf, spec) in glint_specs {
            if !used[mi as usize] {
                continue;
            }
            let cfg = facet_glint::glint_brdf::GlintConfig {
                gamma: (spec.gamma_deg as f64).to_radians(),
                threshold: spec.threshold as f64,
                filtered: config.glint_filter,
            };
            let ([k0, k1], w) = facet_glint::dpf::DpfPyramid::levels_for(cfg.gamma);
            let which: Vec<usize> = if w > 0.0 { vec![k0, k1] } else { vec![k0] };
            let (nt, np) = (config.dpf.n_theta as u64, config.dpf.n_dphi as u64);
            let dpf_set_by =
                format!("the DPF resolution (ResourceConfig::dpf: n_theta {nt}, n_dphi {np})");
            let side = |x: u64| u32::try_from(x).unwrap_or(u32::MAX);
            limits.check(&[
                Planned::texture_3d(
                    "a DPF level texture",
                    [side(np), side(nt), side(nt)],
                    &dpf_set_by,
                ),
                Planned::storage("a DPF level buffer", product(&[nt, nt, np, 4]), &dpf_set_by),
            ])?;
            let dpf = facet_glint::gpu::build_levels(gpu, &Ndf::Analytic(ndf), config.dpf, &which)?;
            let (params, t0, t1): (GlintEvalParams, _, _) =
                facet_glint::gpu::eval_params(&cfg, &ndf, &dpf)?;
            let field = facet_glint::flakes::FlakeField {
                density: spec.density as f64,
                seed: mi,
            };
            let uniform = GlintField::new(&field, &cfg);
            let level0 = t0.create_view(&Default::default());
            let level1 = t1.create_view(&Default::default());
            built.glint_pyramids.push(
                which
                    .iter()
                    .map(|&k| facet_glint::dpf::LEVELS_DEG[k])
                    .collect(),
            );
            glints.push(GlintResources {
                material: mi,
                field: buffer::uniform(d, "glint field", &uniform),
                params: buffer::uniform(d, "glint params", &params),
                level0,
                level1,
                dpf,
            });
        }
        built.glint_build_ms = t.elapsed().as_secs_f64() * 1e3;

        // Textures: headers (offset, width, height, srgb) then texels, in u32 words.
        let mut tex_words: Vec<u32> = vec![0; 4 * scene.textures.len()];
        for (i, tex) in scene.textures.iter().enumerate() {
            let off = tex_words.len() as u32;
            tex_words[4 * i..4 * i + 4].copy_from_slice(&[
                off,
                tex.width,
                tex.height,
                tex.srgb as u32,
            ]);
            tex_words.extend(tex.texels.iter().map(|c| u32::from_le_bytes(*c)));
        }
        built.textures = scene.textures.len();

        // Lights: punctual ones, emissive triangles, the environment; chosen by estimated power.
        let (lo, hi) = scene.bounds();
        let radius = (0.5 * (hi - lo).length()).max(1e-3);
        let mut lights = Vec::new();
        let mut power = Vec::new();
        for l in &scene.lights {
            let (g, p) = match *l {
                Light::Point {
                    position,
                    intensity,
                } => (
                    GpuLight {
                        kind: LightKind::Point as u32,
                        position: position.extend(1.0).to_array(),
                        intensity: intensity.extend(0.0).to_array(),
                        ..Default::default()
                    },
                    4.0 * std::f32::consts::PI * lum(intensity),
                ),
                Light::Spot {
                    position,
                    direction,
                    intensity,
                    inner_cone,
                    outer_cone,
                } => (
                    GpuLight {
                        kind: LightKind::Spot as u32,
                        cos_inner: inner_cone.cos(),
                        cos_outer: outer_cone.cos(),
                        position: position.extend(1.0).to_array(),
                        direction: direction.extend(0.0).to_array(),
                        intensity: intensity.extend(0.0).to_array(),
                        ..Default::default()
                    },
                    2.0 * std::f32::consts::PI * (1.0 - outer_cone.cos()) * lum(intensity),
                ),
                Light::Directional {
                    direction,
                    irradiance,
                } => (
                    GpuLight {
                        kind: LightKind::Directional as u32,
                        direction: direction.extend(0.0).to_array(),
                        intensity: irradiance.extend(0.0).to_array(),
                        ..Default::default()
                    },
                    std::f32::consts::PI * radius * radius * lum(irradiance),
                ),
            };
            if p > 0.0 {
                lights.push(g);
                power.push(p);
            }
        }
        let mut triangle_light = Vec::new();
        for (ti, tri) in scene.indices.iter().enumerate() {
            let m = &materials[scene.triangle_material[ti] as usize];
            let le = Vec3::from_slice(&m.emissive[..3]);
            if lum(le) <= 0.0 {
                continue;
            }
            let [a, b, c] = tri.map(|i| scene.positions[i as usize]);
            let area = 0.5 * (b - a).cross(c - a).length();
            if triangle_light.is_empty() {
                triangle_light = vec![NONE; scene.indices.len()];
            }
            triangle_light[ti] = lights.len() as u32;
            lights.push(GpuLight {
                kind: LightKind::Triangle as u32,
                prim: ti as u32,
                ..Default::default()
            });
            power.push(std::f32::consts::PI * area * lum(le));
        }
        built.emissive_triangles = lights
            .iter()
            .filter(|l| l.kind == LightKind::Triangle as u32)
            .count();
        if triangle_light.is_empty() {
            triangle_light.push(NONE);
        }
        let (mut env_kind, mut env_size, mut env_offsets, mut env_color) =
            (EnvKind::None as u32, (1, 1), (0, 0, 0), [0.0; 4]);
        match environment {
            Some(Environment::Constant(c)) => {
                env_kind = EnvKind::Constant as u32;
                env_color = c.extend(0.0).to_array();
                if lum(*c) > 0.0 {
                    lights.push(GpuLight {
                        kind: LightKind::Environment as u32,
                        ..Default::default()
                    });
                    // Flux through the scene's bounding sphere: 4π · π r² · L.
                    power.push(4.0 * std::f32::consts::PI.powi(2) * radius * radius * lum(*c));
                }
            }
            Some(Environment::Map(map)) => {
                env_kind = EnvKind::Map as u32;
                env_size = (map.width, map.height);
                let source = format!("the environment map {}", map.path.display());
                // Checked before the copy into the tables: the map is the largest input.
                let words =
                    3 * map.texels.len() + map.marginal_cdf.len() + map.conditional_cdf.len();
                limits.check(&[Planned::storage(
                    "the scene tables",
                    4 * (tables.words.len() + words) as u64,
                    format!("{source} ({}×{})", map.width, map.height),
                )])?;
                let texels = tables.push(&source, map.texels.iter().flat_map(|t| t.to_array()));
                let marginal = tables.push(&source, map.marginal_cdf.iter().copied());
                let conditional = tables.push(&source, map.conditional_cdf.iter().copied());
                env_offsets = (texels, marginal, conditional);
                built.environment_map = true;
                let avg = map.texels.iter().map(|t| lum(*t)).sum::<f32>()
                    / map.texels.len().max(1) as f32;
                if avg > 0.0 {
                    lights.push(GpuLight {
                        kind: LightKind::Environment as u32,
                        ..Default::default()
                    });
                    power.push(4.0 * std::f32::consts::PI.powi(2) * radius * radius * avg);
                }
            }
            None => {}
        }
        let total: f32 = power.iter().sum();
        let mut acc = 0.0;
        let mut cdf = vec![0.0f32];
        for p in &power {
            acc += p / total;
            cdf.push(acc);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let light_cdf = tables.push("the scene's lights", cdf);
        built.lights = lights.len();
        if lights.is_empty() {
            lights.push(GpuLight::default());
        }
        if tables.words.is_empty() {
            tables.words.push(0.0);
        }
        let size_of = |n: usize, each: usize| product(&[n as u64, each as u64]);
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
                size_of(vertices.len(), 16),
                format!("the scene ({n} vertices)"),
            ),
            Planned::storage(
                "the triangle buffer",
                size_of(triangles.len(), 16),
                format!("the scene ({n_tri} triangles)"),
            ),
            Planned::storage(
                "the material buffer",
                size_of(materials.len(), std::mem::size_of::<GpuMaterial>()),
                format!("the scene ({} materials)", materials.len()),
            ),
            Planned::storage(
                "the texture buffer",
                size_of(tex_words.len(), 4),
                format!("the scene's {} textures{largest}", scene.textures.len()),
            ),
            Planned::storage(
                "the light buffer",
                size_of(lights.len(), std::mem::size_of::<GpuLight>()),
                format!(
                    "the scene ({} punctual lights, {} emissive triangles)",
                    scene.lights.len(),
                    built.emissive_triangles
                ),
            ),
            Planned::storage(
                "the scene tables",
                size_of(tables.words.len(), 4),
                tables.described(),
            ),
            Planned::storage(
                "the per-triangle light index",
                size_of(triangle_light.len(), 4),
                format!("the scene ({n_tri} triangles)"),
            ),
        ])?;

        let res = gpu.scoped(|| SceneResources {
            vertices: buffer::storage(d, "vertices", &vertices),
            triangles: buffer::storage(d, "triangles", &triangles),
            materials: buffer::storage(d, "materials", &materials),
            material_data: materials.clone(),
            textures: buffer::storage(
                d,
                "textures",
                if tex_words.is_empty() {
                    &[0u32][..]
                } else {
                    &tex_words
                },
            ),
            lights: buffer::storage(d, "lights", &lights),
            tables: buffer::storage(d, "tables", &tables.words),
            triangle_light: buffer::storage(d, "triangle lights", &triangle_light),
            bvh: gpu_bvh,
            glints,
            queues_used,
            n_vertices: n as u32,
            n_lights: built.lights as u32,
            light_cdf,
            env_kind,
            env_size,
            env_offsets,
            env_color,
            scene_radius: radius,
            built,
        })?;
        Ok(res)
    }
}

impl SceneResources {
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
        let (Some(m), Some(old)) = (scene.materials.get(index), self.material_data.get(index))
        else {
            return rebuild("no such material");
        };
        let Some(f) = &m.facet else {
            return rebuild("not a fitted material");
        };
        if f.glint.is_some() || old.kind == MaterialKind::Glint as u32 {
            return rebuild("glint materials are rebuilt");
        }
        let choice = match f.model {
            FacetModel::Tabulated => facet_fit::material::ModelChoice::Tabulated,
            FacetModel::Ggx => facet_fit::material::ModelChoice::Ggx,
            FacetModel::Beckmann => facet_fit::material::ModelChoice::Beckmann,
        };
        let Some(brdf) = f.fit.model(choice) else {
            return rebuild("the fit has no such model");
        };
        let mut g = *old;
        match &brdf.ndf {
            Ndf::Analytic(a) => {
                let kind = match a.kind {
                    NdfKind::Ggx => 0,
                    NdfKind::Beckmann => 1,
                };
                if old.kind != MaterialKind::Analytic as u32 || old.ndf_kind != kind {
                    return rebuild("the NDF class changed");
                }
                g.alpha_x = a.alpha_x as f32;
                g.alpha_y = a.alpha_y as f32;
                g.rotation = a.rotation as f32;
                g.roughness = (a.alpha_x * a.alpha_y).sqrt() as f32;
            }
            Ndf::Tabulated(tab) => {
                if old.kind != MaterialKind::Tabulated as u32 {
                    return rebuild("the NDF class changed");
                }
                let cone_alpha = f
                    .fit
                    .record
                    .ggx
                    .as_ref()
                    .map_or(0.3, |p| (p.alpha_x * p.alpha_y).sqrt() as f32);
                g.alpha_x = tab.stretch.alpha_x as f32;
                g.alpha_y = tab.stretch.alpha_y as f32;
                g.rotation = tab.stretch.rotation as f32;
                g.roughness =
                    cone_alpha * (tab.stretch.alpha_x * tab.stretch.alpha_y).sqrt() as f32;
            }
        }
        g.diffuse = [
            brdf.diffuse[0] as f32,
            brdf.diffuse[1] as f32,
            brdf.diffuse[2] as f32,
            0.0,
        ];
        let fres: Vec<f32> = (0..FRESNEL_NODES)
            .flat_map(|j| {
                let theta_d = j as f64 / (FRESNEL_NODES - 1) as f64 * std::f64::consts::FRAC_PI_2;
                rgb(brdf.fresnel.eval(theta_d.cos()))
            })
            .collect();
        queue.write_buffer(
            &self.tables,
            4 * g.fresnel_offset as u64,
            bytemuck::cast_slice(&fres),
        );
        queue.write_buffer(
            &self.materials,
            (index * std::mem::size_of::<GpuMaterial>()) as u64,
            bytemuck::bytes_of(&g),
        );
        self.material_data[index] = g;
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
    if glints > crate::queues::MAX_GLINT_MATERIALS as usize {
        return bad(format!(
            "{glints} glint materials; at most {} are supported",
            crate::queues::MAX_GLINT_MATERIALS
        ));
    }
    Ok(())
}
