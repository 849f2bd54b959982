//! The wavefront path tracer (Laine, Karras, Aila 2013; pbrt-v4's wavefront integrator): path
//! state lives in GPU buffers, each iteration runs the stages
//!
//!   logic → generate → extend → shade (one pass per material class) → connect
//!
//! as separate compute dispatches, each over the queue the previous one filled (indirect
//! dispatch; `queue_args.wgsl` closes a queue and writes the arguments). A slot owns one pixel
//! for a whole tile and takes its samples one after the other (regeneration in the logic
//! stage), so the film needs no atomics and the same seed gives the same image.

use crate::camera::CameraFrame;
use crate::error::RenderError;
use crate::film::Image;
use crate::queues::Queue;
use crate::resources::SceneResources;
use crate::stages::{Layouts, Stage, queue_args};
use crate::wavefront::Wavefront;
use facet_gpu::{Gpu, shader};
use std::time::Instant;

pub use crate::tags::{NdfSampling, Strategy};

/// Encodes one stage into the pass it is given.
pub(crate) type EncodeStage<'a> = dyn FnMut(&mut wgpu::ComputePass) + 'a;

/// Settings of one render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderConfig {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Bounces after the camera ray (1: direct lighting only).
    pub max_depth: u32,
    /// Seed of the per-pixel random numbers.
    pub seed: u32,
    /// Depth from which Russian roulette plays.
    pub rr_depth: u32,
    /// Paths in flight (slots); the image is rendered in tiles of this many pixels.
    pub wavefront: u32,
    /// Samples per pixel taken per pass over the image (progress and time-limit granularity).
    pub spp_per_pass: u32,
    /// Stop after the pass during which this many seconds have passed.
    pub time_limit: Option<f64>,
    /// Iterations submitted between checks for completion.
    pub iterations_per_check: u32,
    /// How direct lighting is sampled.
    pub strategy: Strategy,
    /// How the normals of microfacet lobes are sampled.
    pub ndf_sampling: NdfSampling,
}

impl RenderConfig {
    /// 1280 × 720, 64 spp, depth 5.
    pub const fn standard() -> Self {
        RenderConfig {
            width: 1280,
            height: 720,
            spp: 64,
            max_depth: 5,
            seed: 0,
            rr_depth: 3,
            wavefront: 1 << 20,
            spp_per_pass: 4,
            time_limit: None,
            iterations_per_check: 8,
            strategy: Strategy::Mis,
            ndf_sampling: NdfSampling::Visible,
        }
    }

    /// 320 × 180, 8 spp: tests and quick looks.
    pub const fn preview() -> Self {
        RenderConfig {
            width: 320,
            height: 180,
            spp: 8,
            max_depth: 5,
            seed: 0,
            rr_depth: 3,
            wavefront: 1 << 16,
            spp_per_pass: 4,
            time_limit: None,
            iterations_per_check: 8,
            strategy: Strategy::Mis,
            ndf_sampling: NdfSampling::Visible,
        }
    }
}

/// What a render did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
    /// Wall-clock time, milliseconds.
    pub ms: f64,
    /// Samples taken (all pixels).
    pub samples: u64,
    /// Iterations of the stage loop.
    pub iterations: u64,
    /// Samples per pixel of the finished passes (fewer than asked under a time limit).
    pub spp: u32,
}

/// The stage pipelines for one scene: only the shading stages of the classes it uses.
pub struct Integrator {
    layouts: Layouts,
    logic: Stage,
    generate: Stage,
    extend: Stage,
    shade: Vec<Stage>,
    connect: Stage,
    /// queue_args for Generate, Extend, the shading queues, Shadow.
    close_gen: wgpu::ComputePipeline,
    close_extend: wgpu::ComputePipeline,
    close_shade: wgpu::ComputePipeline,
    close_shadow: wgpu::ComputePipeline,
    n_queues: u32,
    /// Workgroup size of the stages (read from their WGSL).
    wg: u32,
}

impl Integrator {
    /// The pipelines for the material classes of `scene`.
    pub fn new(device: &wgpu::Device, scene: &SceneResources) -> Result<Self, RenderError> {
        let layouts = Layouts::new(device);
        let stage = |file: &str, entry: &'static str, queue, extra: &[(&str, f64)]| {
            Stage::new(device, &layouts, file, entry, queue, extra)
        };
        let mut shade = Vec::new();
        for &q in &scene.queues_used {
            let q_shade = [("Q_SHADE", q.index() as f64)];
            let s = match q {
                Queue::Diffuse => stage(
                    "render/shade_diffuse.wgsl",
                    "shade_diffuse",
                    Some(q),
                    &q_shade,
                )?,
                Queue::Analytic | Queue::Tabulated => stage(
                    "render/shade_microfacet.wgsl",
                    "shade_microfacet",
                    Some(q),
                    &[
                        q_shade[0],
                        ("TABULATED", (q == Queue::Tabulated) as u32 as f64),
                    ],
                )?,
                Queue::Glint(_) => {
                    let mut c = facet_glint::gpu::flake_constants();
                    c.push(q_shade[0]);
                    stage("render/shade_glint.wgsl", "shade_glint", Some(q), &c)?
                }
                _ => continue,
            };
            shade.push(s);
        }
        let n_queues = Queue::count(scene.glints.len() as u32);
        let wg = shader::workgroup_size("render/extend.wgsl", "extend")?;
        Ok(Integrator {
            logic: stage("render/logic.wgsl", "logic", None, &[])?,
            generate: stage(
                "render/generate.wgsl",
                "generate",
                Some(Queue::Generate),
                &[],
            )?,
            extend: stage("render/extend.wgsl", "extend", Some(Queue::Extend), &[])?,
            connect: stage("render/connect.wgsl", "connect", Some(Queue::Shadow), &[])?,
            close_gen: queue_args(device, &layouts, Queue::Generate.index(), 1, wg)?,
            close_extend: queue_args(device, &layouts, Queue::Extend.index(), 1, wg)?,
            close_shade: queue_args(
                device,
                &layouts,
                Queue::Diffuse.index(),
                n_queues - Queue::Diffuse.index(),
                wg,
            )?,
            close_shadow: queue_args(device, &layouts, Queue::Shadow.index(), 1, wg)?,
            shade,
            layouts,
            n_queues,
            wg,
        })
    }

    /// Names of the stages built (shading stages once per class).
    pub fn stage_names(&self) -> Vec<&'static str> {
        let mut v = vec![self.logic.name, self.generate.name, self.extend.name];
        v.extend(self.shade.iter().map(|s| s.name));
        v.push(self.connect.name);
        v
    }

    /// Renders `config.spp` samples per pixel (or fewer under a time limit) into a fresh
    /// [`Wavefront`]; `progress` gets the fraction done after every tile. Renders that repeat
    /// (a viewer, a benchmark) keep a `Wavefront` and call its `render_more` instead.
    pub fn render(
        &self,
        gpu: &Gpu,
        scene: &SceneResources,
        camera: &CameraFrame,
        config: &RenderConfig,
        progress: &mut dyn FnMut(f64),
    ) -> Result<(Image, RenderStats), RenderError> {
        if config.width == 0 || config.height == 0 || config.spp == 0 {
            return Err(RenderError::Scene(format!(
                "nothing to render: {}×{} at {} spp",
                config.width, config.height, config.spp
            )));
        }
        let t0 = Instant::now();
        let mut wavefront = Wavefront::new(
            gpu,
            self,
            scene,
            config.width,
            config.height,
            config.wavefront,
        )?;
        let mut stats = wavefront.render_more(gpu, self, scene, camera, config, progress)?;
        let image = wavefront.image(gpu)?;
        stats.ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((image, stats))
    }

    pub(crate) fn layouts(&self) -> &Layouts {
        &self.layouts
    }

    /// Queues of the scene the integrator was built for.
    pub(crate) fn n_queues(&self) -> u32 {
        self.n_queues
    }

    /// Workgroup size of the stages.
    pub(crate) fn workgroup(&self) -> u32 {
        self.wg
    }

    /// One iteration of the stage loop over `wf`'s paths, encoded into `pass`.
    pub(crate) fn iteration(
        &self,
        pass: &mut wgpu::ComputePass,
        wf: &Wavefront,
        all_slots: (u32, u32),
    ) {
        self.iteration_by_stage(wf, all_slots, &mut |_, encode| encode(pass));
    }

    /// One iteration, stage by stage: `each(name, encode)` gets every stage (the queue closes
    /// too) in order and encodes it into a pass of its choice — one shared pass, or one pass
    /// per stage for timing. Names: "logic", "generate", "extend", "shade <class>", "connect",
    /// and "close <queue>" for the queue closes.
    pub(crate) fn iteration_by_stage(
        &self,
        wf: &Wavefront,
        all_slots: (u32, u32),
        each: &mut dyn FnMut(&str, &mut EncodeStage),
    ) {
        let (frame_group, scene_group, glint_groups) =
            (&wf.frame_group, &wf.scene_group, &wf.glint_groups);
        let (args_group, args) = (&wf.args_group, wf.args());
        let close = |pass: &mut wgpu::ComputePass, p: &wgpu::ComputePipeline| {
            pass.set_pipeline(p);
            pass.set_bind_group(0, args_group, &[]);
            pass.dispatch_workgroups(1, 1, 1);
        };
        let run = |pass: &mut wgpu::ComputePass, s: &Stage| {
            pass.set_pipeline(&s.pipeline);
            pass.set_bind_group(0, frame_group, &[]);
            pass.set_bind_group(1, scene_group, &[]);
            match s.queue {
                Some(q) => {
                    if let Queue::Glint(k) = q {
                        pass.set_bind_group(2, &glint_groups[k as usize], &[]);
                    }
                    pass.dispatch_workgroups_indirect(args, 12 * q.index() as u64);
                }
                None => pass.dispatch_workgroups(all_slots.0, all_slots.1, 1),
            }
        };
        each("logic", &mut |p| run(p, &self.logic));
        each("close generate", &mut |p| close(p, &self.close_gen));
        each("generate", &mut |p| run(p, &self.generate));
        each("close extend", &mut |p| close(p, &self.close_extend));
        each("extend", &mut |p| run(p, &self.extend));
        each("close shade", &mut |p| close(p, &self.close_shade));
        for s in &self.shade {
            let name = match s.queue {
                Some(Queue::Glint(k)) => format!("shade glint {k}"),
                Some(q) => format!("shade {}", q.class_name()),
                None => s.name.to_string(),
            };
            each(&name, &mut |p| run(p, s));
        }
        each("close shadow", &mut |p| close(p, &self.close_shadow));
        each("connect", &mut |p| run(p, &self.connect));
    }
}
