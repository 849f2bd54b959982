//! Host driver of `shaders/glint/dpf_build.wgsl`: the DPF levels built on the GPU and stored as
//! one 3D texture per level (R32Float, x = Δφ, y = θi, z = θo, values at cell centres).

use crate::cone_rule::{ConeRule, LevelRule, Ring, lobe_width};
use crate::dpf::{DpfConfig, DpfPyramid, DpfTable, LEVELS_DEG};
use crate::lobe_rule::{LOBE_EPS, TAIL_START, TOUCH_MERGE};
use crate::tags::NdfTag;
use bytemuck::{Pod, Zeroable};
use facet_brdf::model::geometry::spherical;
use facet_brdf::model::microfacet::Ndf;
use facet_gpu::{Gpu, GpuError, buffer, dispatch, shader};

/// Uniforms of the build (WGSL `Params`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DpfParams {
    pub n_theta: u32,
    pub n_dphi: u32,
    pub n_rings: u32,
    /// An [`NdfTag`]: GGX, Beckmann or the table.
    pub ndf_kind: u32,
    pub alpha_x: f32,
    pub alpha_y: f32,
    pub rotation: f32,
    pub table_nu: u32,
    pub table_nphi: u32,
    pub n_radial: u32,
    pub n_angular: u32,
    pub n_tail_angular: u32,
    pub gamma: f32,
    pub lobe_width: f32,
    pub pad0: u32,
    pub pad1: u32,
}

/// Resolution of the NDF table for tabulated (or stretched) NDFs on the GPU.
const NDF_TABLE_NU: usize = 1024;

/// The NDF as the shader takes it: analytic parameters, or D sampled on a (u, φ) grid.
fn ndf_upload(ndf: &Ndf) -> (DpfParams, Vec<f32>) {
    match ndf {
        Ndf::Analytic(a) => {
            let p = DpfParams {
                ndf_kind: NdfTag::from(a.kind) as u32,
                alpha_x: a.alpha_x as f32,
                alpha_y: a.alpha_y as f32,
                rotation: a.rotation as f32,
                table_nu: 2,
                table_nphi: 1,
                ..Default::default()
            };
            (p, vec![0.0])
        }
        Ndf::Tabulated(t) => {
            let nphi = if t.is_isotropic() { 1 } else { 128 };
            let table = (0..NDF_TABLE_NU * nphi)
                .map(|kl| {
                    let u = (kl / nphi) as f64 / (NDF_TABLE_NU - 1) as f64;
                    let phi = (kl % nphi) as f64 / nphi as f64 * 2.0 * std::f64::consts::PI;
                    t.d(spherical(u * u * std::f64::consts::FRAC_PI_2, phi)) as f32
                })
                .collect();
            let p = DpfParams {
                ndf_kind: NdfTag::Tabulated as u32,
                table_nu: NDF_TABLE_NU as u32,
                table_nphi: nphi as u32,
                alpha_x: 1.0,
                alpha_y: 1.0,
                ..Default::default()
            };
            (p, table)
        }
    }
}

/// The pyramid built on the GPU: the tables (read back) and one 3D texture per level.
pub struct GpuDpf {
    /// The tables, read back from the GPU.
    pub pyramid: DpfPyramid,
    /// One 3D texture per level.
    pub textures: Vec<wgpu::Texture>,
}

/// Builds the nine levels on the GPU.
pub fn build_pyramid(gpu: &Gpu, ndf: &Ndf, config: DpfConfig) -> Result<GpuDpf, GpuError> {
    build_levels(gpu, ndf, config, &[0, 1, 2, 3, 4, 5, 6, 7, 8])
}

/// Builds the listed levels (indices into [`LEVELS_DEG`]) with the [`ConeRule::fast`] rule;
/// `textures` holds them in order.
pub fn build_levels(
    gpu: &Gpu,
    ndf: &Ndf,
    config: DpfConfig,
    which: &[usize],
) -> Result<GpuDpf, GpuError> {
    build_levels_with(gpu, ndf, config, which, &ConeRule::fast())
}

/// Builds the listed levels with the cone rule `rule` (the CPU's [`DpfPyramid::build_levels_with`]
/// on the same rings).
pub fn build_levels_with(
    gpu: &Gpu,
    ndf: &Ndf,
    config: DpfConfig,
    which: &[usize],
    rule: &ConeRule,
) -> Result<GpuDpf, GpuError> {
    let d = &gpu.device;
    // One pipeline per rule a level takes (the WGSL's RULE), built when first needed.
    let mut pipelines: [Option<wgpu::ComputePipeline>; 2] = [None, None];
    let wg = shader::workgroup_size("glint/dpf_build.wgsl", "dpf_build")?;
    let (base, table) = ndf_upload(ndf);
    let width = lobe_width(ndf);
    let cells = config.n_theta * config.n_theta * config.n_dphi;
    let table_buf = gpu.scoped(|| buffer::storage(d, "ndf table", &table))?;
    let mut levels = vec![None; LEVELS_DEG.len()];
    let mut textures = Vec::new();
    for (k, &deg) in LEVELS_DEG
        .iter()
        .enumerate()
        .filter(|(k, _)| which.contains(k))
    {
        let gamma = deg.to_radians();
        let mut params = DpfParams {
            n_theta: config.n_theta as u32,
            n_dphi: config.n_dphi as u32,
            gamma: gamma as f32,
            ..base
        };
        // The buffers of the rule not taken hold one unused element.
        let level = rule.level(gamma, width);
        let rule_code = matches!(level, LevelRule::Lobe { .. }) as usize;
        let pipeline = match &mut pipelines[rule_code] {
            Some(p) => &*p,
            slot => slot.insert(shader::compute_pipeline(
                d,
                "glint/dpf_build.wgsl",
                "dpf_build",
                &[
                    ("LOBE_EPS", LOBE_EPS),
                    ("TOUCH_MERGE", TOUCH_MERGE),
                    ("TAIL_START", TAIL_START),
                    ("RULE", rule_code as f64),
                ],
            )?),
        };
        let (rings, nodes) = match level {
            LevelRule::Rings(rings) => {
                params.n_rings = rings.len() as u32;
                (rings, vec![[0.0f32; 2]])
            }
            LevelRule::Lobe { rule, width } => {
                params.n_radial = rule.radial as u32;
                params.n_angular = rule.angular as u32;
                params.n_tail_angular = rule.tail_angular as u32;
                params.lobe_width = width as f32;
                (vec![Ring::default()], rule.nodes())
            }
        };
        let (pb, gb, nb, ob) = gpu.scoped(|| {
            (
                buffer::uniform(d, "dpf params", &params),
                buffer::storage(d, "cone rings", &rings),
                buffer::storage(d, "lobe rule nodes", &nodes),
                buffer::storage_zeroed(d, "dpf level", (cells * 4) as u64),
            )
        })?;
        let resources = [
            pb.as_entire_binding(),
            gb.as_entire_binding(),
            table_buf.as_entire_binding(),
            ob.as_entire_binding(),
            nb.as_entire_binding(),
        ];
        dispatch::run(
            d,
            &gpu.queue,
            pipeline,
            "dpf build",
            &resources,
            cells as u32,
            wg,
        );
        let values: Vec<f32> = buffer::read(d, &gpu.queue, &ob, cells)?;
        gpu.check_lost()?;
        let texture = level_texture(gpu, config, &values);
        textures.push(texture);
        levels[k] = Some(DpfTable {
            gamma,
            config,
            values,
        });
    }
    Ok(GpuDpf {
        pyramid: DpfPyramid { levels },
        textures,
    })
}

/// One level's values as a 3D R32Float texture: Δφ across, θi down, θo in depth.
fn level_texture(gpu: &Gpu, config: DpfConfig, values: &[f32]) -> wgpu::Texture {
    let d = &gpu.device;
    let size = wgpu::Extent3d {
        width: config.n_dphi as u32,
        height: config.n_theta as u32,
        depth_or_array_layers: config.n_theta as u32,
    };
    let texture = d.create_texture(&wgpu::TextureDescriptor {
        label: Some("dpf level"),
        size,
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_DST
            | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        texture.as_image_copy(),
        bytemuck::cast_slice(values),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * config.n_dphi as u32),
            rows_per_image: Some(config.n_theta as u32),
        },
        size,
    );
    texture
}

/// The flake field as `shaders/glint/glint_count.wgsl` takes it (WGSL `Field`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GlintField {
    pub density: f32,
    pub seed: u32,
    pub root_count: u32,
    pub filtered: u32,
    pub threshold: f32,
    pub blend: u32,
    pub table_levels: u32,
    pub pad: u32,
}

/// Two glint queries sharing a footprint (WGSL `Query`): the footprint, the P of each (0: no
/// query) and their half vectors' direction coordinates ([`crate::flakes::direction_coords`]).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GlintQuery {
    pub center: [f32; 2],
    pub a: [f32; 2],
    pub b: [f32; 2],
    pub p: [f32; 2],
    pub coords0: [f32; 2],
    pub coords1: [f32; 2],
}

impl GlintQuery {
    /// The pair of queries over footprint `fp` with DPF values `p` at direction coordinates
    /// `coords`.
    pub fn pair(fp: &crate::flakes::Footprint, p: [f64; 2], coords: [glam::DVec2; 2]) -> Self {
        GlintQuery {
            center: fp.center.as_vec2().to_array(),
            a: fp.a.as_vec2().to_array(),
            b: fp.b.as_vec2().to_array(),
            p: p.map(|x| x as f32),
            coords0: coords[0].as_vec2().to_array(),
            coords1: coords[1].as_vec2().to_array(),
        }
    }

    /// One query (the second one empty).
    pub fn new(fp: &crate::flakes::Footprint, p: f64, coords: glam::DVec2) -> Self {
        Self::pair(fp, [p, 0.0], [coords, coords])
    }
}

/// The override constants of the flake shaders (the hashes and the quadtree), from Rust.
pub fn flake_constants() -> Vec<(&'static str, f64)> {
    use crate::flakes::{BINOMIAL_EXACT_MAX, LEAF_FLAKES, MAX_DEPTH, POSITION_SALT, SPLIT_SALT};
    use crate::lit::{BLEND_BAND, LIT_EXACT_MEAN, SPLIT_EXACT_MAX};
    let mut constants: Vec<(&str, f64)> = crate::tea::pipeline_constants().to_vec();
    constants.extend([
        ("LEAF_FLAKES", LEAF_FLAKES as f64),
        ("MAX_DEPTH", MAX_DEPTH as f64),
        ("BINOMIAL_EXACT_MAX", BINOMIAL_EXACT_MAX as f64),
        ("SPLIT_SALT", SPLIT_SALT as f64),
        ("POSITION_SALT", POSITION_SALT as f64),
        ("LIT_EXACT_MEAN", LIT_EXACT_MEAN),
        ("SPLIT_EXACT_MAX", SPLIT_EXACT_MAX as f64),
        ("BLEND_BAND", BLEND_BAND),
    ]);
    constants
}

impl GlintField {
    /// The uniform of `field` counted under `cfg`, its top levels' counts in `table`
    /// ([`crate::flakes::FlakeField::split_table`]).
    pub fn new(
        field: &crate::flakes::FlakeField,
        cfg: &crate::glint_brdf::GlintConfig,
        table: &crate::flakes::SplitTable,
    ) -> Self {
        GlintField {
            density: field.density as f32,
            seed: field.seed,
            root_count: field.root_count() as u32,
            filtered: cfg.filtered as u32,
            threshold: cfg.threshold as f32,
            blend: cfg.blend as u32,
            table_levels: table.levels,
            pad: 0,
        }
    }
}

/// Host driver of `shaders/glint/glint_count.wgsl`.
pub struct GlintCounter {
    pipeline: wgpu::ComputePipeline,
    /// `@workgroup_size` of the shader, read by naga.
    workgroup_size: u32,
}

impl GlintCounter {
    /// Builds the pipeline on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        let constants = flake_constants();
        Ok(GlintCounter {
            pipeline: shader::compute_pipeline(
                device,
                "glint/glint_count.wgsl",
                "glint_count",
                &constants,
            )?,
            workgroup_size: shader::workgroup_size("glint/glint_count.wgsl", "glint_count")?,
        })
    }

    /// Counts (or filtered means) of both queries of each pair.
    pub fn count(
        &self,
        gpu: &Gpu,
        field: &crate::flakes::FlakeField,
        cfg: &crate::glint_brdf::GlintConfig,
        queries: &[GlintQuery],
    ) -> Result<Vec<[f64; 2]>, GpuError> {
        let d = &gpu.device;
        let table = field.split_table();
        let uniform = GlintField::new(field, cfg, &table);
        let (ub, qb, cb, tb) = gpu.scoped(|| {
            (
                buffer::uniform(d, "glint field", &uniform),
                buffer::storage(d, "glint queries", queries),
                buffer::storage_zeroed(d, "glint counts", (queries.len() * 8) as u64),
                buffer::storage(d, "glint split table", &table.counts),
            )
        })?;
        let resources = [
            ub.as_entire_binding(),
            qb.as_entire_binding(),
            cb.as_entire_binding(),
            tb.as_entire_binding(),
        ];
        dispatch::run(
            d,
            &gpu.queue,
            &self.pipeline,
            "glint count",
            &resources,
            queries.len() as u32,
            self.workgroup_size,
        );
        let out: Vec<[f32; 2]> = buffer::read(d, &gpu.queue, &cb, queries.len())?;
        gpu.check_lost()?;
        Ok(out.into_iter().map(|c| c.map(f64::from)).collect())
    }
}

/// Uniforms of `shaders/glint/glint_eval.wgsl` (WGSL `EvalParams`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GlintEvalParams {
    pub gamma: f32,
    pub sigma: f32,
    pub sigma0: f32,
    pub sigma1: f32,
    pub level_t: f32,
    pub n_theta: u32,
    pub n_dphi: u32,
    /// An [`NdfTag`]; tabulated: the renderer's table (α and rotation: its stretch).
    pub ndf_kind: u32,
    pub alpha_x: f32,
    pub alpha_y: f32,
    pub rotation: f32,
    pub pad0: u32,
}

/// One evaluation (WGSL `EvalQuery`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GlintEvalQuery {
    pub wi: [f32; 4],
    pub wo: [f32; 4],
    pub center: [f32; 2],
    pub a: [f32; 2],
    pub b: [f32; 2],
    pub pad: [f32; 2],
}

impl GlintEvalQuery {
    /// The query for (ωi, ωo) over footprint `fp`.
    pub fn new(wi: glam::DVec3, wo: glam::DVec3, fp: &crate::flakes::Footprint) -> Self {
        GlintEvalQuery {
            wi: wi.as_vec3().extend(0.0).to_array(),
            wo: wo.as_vec3().extend(0.0).to_array(),
            center: fp.center.as_vec2().to_array(),
            a: fp.a.as_vec2().to_array(),
            b: fp.b.as_vec2().to_array(),
            pad: [0.0; 2],
        }
    }
}

/// Host driver of `shaders/glint/glint_eval.wgsl`: the glint BRDF of an analytic NDF with a
/// Fresnel table, P from the pyramid's textures.
pub struct GlintEvaluator {
    pipeline: wgpu::ComputePipeline,
    /// `@workgroup_size` of the shader, read by naga.
    workgroup_size: u32,
}

impl GlintEvaluator {
    /// Builds the pipeline on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        let constants = flake_constants();
        Ok(GlintEvaluator {
            pipeline: shader::compute_pipeline(
                device,
                "glint/glint_eval.wgsl",
                "glint_eval",
                &constants,
            )?,
            workgroup_size: shader::workgroup_size("glint/glint_eval.wgsl", "glint_eval")?,
        })
    }

    /// f(ωi, ωo) per query. `dpf` must hold the two levels bracketing `cfg.gamma`.
    #[allow(clippy::too_many_arguments)]
    pub fn eval(
        &self,
        gpu: &Gpu,
        field: &crate::flakes::FlakeField,
        cfg: &crate::glint_brdf::GlintConfig,
        ndf: &facet_brdf::model::microfacet::AnalyticNdf,
        fresnel: &facet_brdf::model::fresnel::FresnelTable,
        dpf: &GpuDpf,
        queries: &[GlintEvalQuery],
    ) -> Result<Vec<[f64; 3]>, GpuError> {
        let d = &gpu.device;
        let (params, t0, t1) = eval_params(cfg, &Ndf::Analytic(*ndf), dpf)?;
        let table = field.split_table();
        let uniform = GlintField::new(field, cfg, &table);
        let f: Vec<[f32; 4]> = fresnel
            .rgb
            .iter()
            .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32, 0.0])
            .collect();
        let (fb, pb, frb, qb, ob, tb) = gpu.scoped(|| {
            (
                buffer::uniform(d, "glint field", &uniform),
                buffer::uniform(d, "glint eval params", &params),
                buffer::storage(d, "fresnel", &f),
                buffer::storage(d, "glint eval queries", queries),
                buffer::storage_zeroed(d, "glint values", (queries.len() * 16) as u64),
                buffer::storage(d, "glint split table", &table.counts),
            )
        })?;
        let (v0, v1) = (
            t0.create_view(&Default::default()),
            t1.create_view(&Default::default()),
        );
        let resources = [
            fb.as_entire_binding(),
            pb.as_entire_binding(),
            wgpu::BindingResource::TextureView(&v0),
            wgpu::BindingResource::TextureView(&v1),
            frb.as_entire_binding(),
            qb.as_entire_binding(),
            ob.as_entire_binding(),
            tb.as_entire_binding(),
        ];
        dispatch::run(
            d,
            &gpu.queue,
            &self.pipeline,
            "glint eval",
            &resources,
            queries.len() as u32,
            self.workgroup_size,
        );
        let out: Vec<[f32; 4]> = buffer::read(d, &gpu.queue, &ob, queries.len())?;
        gpu.check_lost()?;
        Ok(out
            .into_iter()
            .map(|v| [v[0] as f64, v[1] as f64, v[2] as f64])
            .collect())
    }
}

/// The WGSL `EvalParams` for γ = `cfg.gamma` and the two pyramid textures bracketing it (the same
/// one twice when γ is on a level). Fails when `dpf` lacks a level it needs.
pub fn eval_params<'a>(
    cfg: &crate::glint_brdf::GlintConfig,
    ndf: &Ndf,
    dpf: &'a GpuDpf,
) -> Result<(GlintEvalParams, &'a wgpu::Texture, &'a wgpu::Texture), GpuError> {
    use crate::dpf::cone_solid_angle;
    let ([k0, k1], t) = DpfPyramid::levels_for(cfg.gamma);
    // With no weight on the second level (γ on a level) only the first is needed.
    let k1 = if t > 0.0 { k1 } else { k0 };
    let level = |k: usize| -> Result<(&DpfTable, &wgpu::Texture), GpuError> {
        let built: Vec<usize> = (0..LEVELS_DEG.len())
            .filter(|&j| dpf.pyramid.levels[j].is_some())
            .collect();
        let pos = built.iter().position(|&j| j == k).ok_or_else(|| {
            GpuError::Validation(format!("DPF level {}° was not built", LEVELS_DEG[k]))
        })?;
        Ok((dpf.pyramid.levels[k].as_ref().unwrap(), &dpf.textures[pos]))
    };
    let ((l0, t0), (l1, t1)) = (level(k0)?, level(k1)?);
    // A tabulated NDF's parameters are its stretch (the table itself is the renderer's).
    let (alpha_x, alpha_y, rotation) = match ndf {
        Ndf::Analytic(a) => (a.alpha_x, a.alpha_y, a.rotation),
        Ndf::Tabulated(t) => (t.stretch.alpha_x, t.stretch.alpha_y, t.stretch.rotation),
    };
    let params = GlintEvalParams {
        gamma: cfg.gamma as f32,
        sigma: cone_solid_angle(cfg.gamma) as f32,
        sigma0: cone_solid_angle(l0.gamma) as f32,
        sigma1: cone_solid_angle(l1.gamma) as f32,
        level_t: t as f32,
        n_theta: l0.config.n_theta as u32,
        n_dphi: l0.config.n_dphi as u32,
        ndf_kind: NdfTag::of(ndf) as u32,
        alpha_x: alpha_x as f32,
        alpha_y: alpha_y as f32,
        rotation: rotation as f32,
        pad0: 0,
    };
    Ok((params, t0, t1))
}
