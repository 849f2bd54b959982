//! The wavefront path tracer (Laine, Karras, Aila 2013; pbrt-v4's wavefront integrator): path
//! state lives in GPU buffers, each iteration runs the stages
//!
//!   logic → generate → extend → shade (one pass per material class) → connect
//!
//! as separate compute dispatches, each over the queue the previous one filled (indirect
//! dispatch; `queue_args.wgsl` closes a queue and writes the arguments). A slot owns one pixel
//! for a whole tile and takes its samples one after the other (regeneration in the logic
//! stage), so the film needs no atomics and the same seed gives the same image.
//!
//! This file holds the pipelines and the loop (pbrt-v4's `integrator.cpp`); the state the loop
//! runs over — path state, queues, film and their bind groups — is a [`Wavefront`], which knows
//! nothing of the loop.

pub mod config;
pub mod pacing;
pub(crate) mod stages;
pub mod wavefront;

use crate::error::RenderError;
use crate::integrator::config::{ImageConfig, RenderConfig, SampleConfig};
use crate::integrator::stages::{Layouts, STAGE_WORKGROUP, Stage, queue_args};
use crate::integrator::wavefront::Wavefront;
use crate::layout::gpu_types::GpuFrame;
use crate::layout::queues::Queue;
use crate::output::film::Image;
use crate::resources::SceneResources;
use crate::scene::camera_frame::CameraFrame;
use facet_gpu::timer::GpuTimer;
use facet_gpu::{Gpu, GpuError};
use std::time::Instant;

/// Encodes one stage into the pass it is given.
pub(crate) type EncodeStage<'a> = dyn FnMut(&mut wgpu::ComputePass) + 'a;

/// The distance a ray starts off its surface (the frame's `ray_epsilon`).
const RAY_EPSILON: f32 = 1e-5;

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

/// One stage's share of one iteration.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    /// `logic`, `generate`, `extend`, `shade <class>`, `connect`, `close <queue>`.
    pub stage: String,
    /// Milliseconds.
    pub ms: f64,
}

/// How [`Integrator::profile_iteration`] timed the stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageClock {
    /// GPU timestamps at the boundaries of one pass per stage.
    Timestamps,
    /// The wall clock around one submission per stage (no timestamp queries): includes the
    /// submission and the wait, an upper bound.
    Wall,
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
    /// Workgroup size of the stages dispatched over every slot.
    wg: u32,
}

impl Integrator {
    /// The pipelines for the material classes of `scene`.
    pub fn new(device: &wgpu::Device, scene: &SceneResources) -> Result<Self, RenderError> {
        let layouts = Layouts::new(device);
        let stage = |file: &str, entry: &'static str, queue, extra: &[(&str, f64)]| {
            Stage::new(device, &layouts, file, entry, queue, extra)
        };
        let shade = shading_stages(device, &layouts, scene)?;
        let n_queues = Queue::count(scene.glints.len() as u32);
        let wg = STAGE_WORKGROUP;
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
                Queue::first_shade(),
                n_queues - Queue::first_shade(),
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

    /// GPU state for `image`, bound to `scene` (the scene this integrator was made for): the
    /// wavefront that [`Integrator::render_more`] adds samples to.
    pub fn wavefront(
        &self,
        gpu: &Gpu,
        scene: &SceneResources,
        image: ImageConfig,
    ) -> Result<Wavefront, RenderError> {
        Wavefront::build(gpu, &self.layouts, self.n_queues, scene, image, false)
    }

    /// [`Integrator::wavefront`] whose film also keeps Σ L² per pixel, for
    /// [`Wavefront::variance`] (16 more bytes a pixel, one more add per sample).
    pub fn wavefront_with_variance(
        &self,
        gpu: &Gpu,
        scene: &SceneResources,
        image: ImageConfig,
    ) -> Result<Wavefront, RenderError> {
        Wavefront::build(gpu, &self.layouts, self.n_queues, scene, image, true)
    }

    /// Renders `config.sampling.spp` samples per pixel (or fewer under a time limit) into a
    /// fresh [`Wavefront`] of `config.image`; `progress` gets the fraction done after every
    /// tile. Renders that repeat (a viewer, a benchmark) keep a `Wavefront` and call
    /// [`Integrator::render_more`] instead.
    pub fn render(
        &self,
        gpu: &Gpu,
        scene: &SceneResources,
        camera: &CameraFrame,
        config: &RenderConfig,
        progress: &mut dyn FnMut(f64),
    ) -> Result<(Image, RenderStats), RenderError> {
        let RenderConfig { image, sampling } = config;
        if image.width == 0 || image.height == 0 || sampling.spp == 0 {
            return Err(RenderError::Scene(format!(
                "nothing to render: {}×{} at {} spp",
                image.width, image.height, sampling.spp
            )));
        }
        let t0 = Instant::now();
        let mut wavefront = self.wavefront(gpu, scene, *image)?;
        let mut stats = self.render_more(gpu, &mut wavefront, camera, sampling, progress)?;
        let image = wavefront.image(gpu)?;
        stats.ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((image, stats))
    }

    /// Adds `sampling.spp` samples per pixel to `wf`'s film (fewer under
    /// `sampling.time_limit`: whole passes of `spp_per_pass`), continuing each pixel's sample
    /// indices; `progress` gets the fraction done after every tile. The image is the
    /// wavefront's own.
    pub fn render_more(
        &self,
        gpu: &Gpu,
        wf: &mut Wavefront,
        camera: &CameraFrame,
        sampling: &SampleConfig,
        progress: &mut dyn FnMut(f64),
    ) -> Result<RenderStats, RenderError> {
        debug_assert_eq!(wf.n_queues(), self.n_queues, "a wavefront of another scene");
        if sampling.spp == 0 {
            return Err(RenderError::Scene("nothing to render: 0 spp".into()));
        }
        let t0 = Instant::now();
        let (width, height) = wf.size();
        let pixels = width as u64 * height as u64;
        let w = wf.slots() as u64;
        let mut frame = frame_uniform(wf, camera, sampling);
        let tiles = pixels.div_ceil(w);
        let per_pass = sampling.spp_per_pass.max(1);
        let first = wf.sample_range().end;
        let last = first.saturating_add(sampling.spp);
        let passes = sampling.spp.div_ceil(per_pass);
        let mut stats = RenderStats::default();
        let all_slots = facet_gpu::dispatch::workgroups(wf.slots(), self.wg);
        'passes: for pass in 0..passes {
            let begin = first + pass * per_pass;
            let end = (begin + per_pass).min(last);
            for tile in 0..tiles {
                let base = tile * w;
                frame.tile_base = base as u32;
                frame.tile_pixels = (pixels - base).min(w) as u32;
                frame.sample_end = end;
                wf.start_tile(&gpu.queue, &frame, begin);
                stats.iterations += self.run_tile(gpu, wf, all_slots, sampling, end - begin)?;
                stats.samples += frame.tile_pixels as u64 * (end - begin) as u64;
                let done = (pass as u64 * tiles + tile + 1) as f64 / (passes as u64 * tiles) as f64;
                progress(done);
            }
            wf.set_next_sample(end);
            stats.spp = end - first;
            if let Some(limit) = sampling.time_limit
                && t0.elapsed().as_secs_f64() >= limit
            {
                break 'passes;
            }
        }
        stats.ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(stats)
    }

    /// Runs the stage loop over the tile `wf` was started on until every slot is idle,
    /// `iterations_per_check` iterations a submission; returns the iterations run. A slot takes
    /// at most max_depth + 2 iterations a sample (its bounces, the one that finishes it and
    /// starts the next), so a tile of `samples` samples a slot that runs twice as long has
    /// stopped making progress (a GPU fault): an error, not a hang.
    fn run_tile(
        &self,
        gpu: &Gpu,
        wf: &Wavefront,
        all_slots: (u32, u32),
        sampling: &SampleConfig,
        samples: u32,
    ) -> Result<u64, RenderError> {
        let checks = sampling.iterations_per_check as u64;
        let limit = 2 * samples as u64 * (sampling.max_depth as u64 + 2) + 2 * checks + 8;
        let mut iterations = 0;
        loop {
            if iterations > limit {
                return Err(facet_gpu::GpuError::Validation(format!(
                    "the wavefront made no progress in {iterations} iterations for {samples} \
                     sample(s) a pixel of depth {}",
                    sampling.max_depth
                ))
                .into());
            }
            let mut enc = gpu.device.create_command_encoder(&Default::default());
            {
                let mut cpass = enc.begin_compute_pass(&Default::default());
                for _ in 0..sampling.iterations_per_check {
                    self.iteration(&mut cpass, wf, all_slots);
                }
            }
            gpu.queue.submit([enc.finish()]);
            iterations += sampling.iterations_per_check as u64;
            let sizes = wf.read_sizes(gpu)?;
            // Nothing traced in the last iteration: every slot is idle.
            if sizes[Queue::Extend.index() as usize] == 0 {
                return Ok(iterations);
            }
        }
    }

    /// Times each stage of one iteration in the middle of a render of `wf`'s first tile: `warm`
    /// iterations fill the queues, then one runs with every stage in its own pass, timed by GPU
    /// timestamps where the device has them, else by the wall clock. The film is cleared after.
    pub fn profile_iteration(
        &self,
        gpu: &Gpu,
        wf: &mut Wavefront,
        camera: &CameraFrame,
        sampling: &SampleConfig,
        warm: u32,
    ) -> Result<(Vec<StageTime>, StageClock), RenderError> {
        let (d, q) = (&gpu.device, &gpu.queue);
        let (width, height) = wf.size();
        let mut frame = frame_uniform(wf, camera, sampling);
        frame.tile_pixels = (width as u64 * height as u64).min(wf.slots() as u64) as u32;
        frame.sample_end = sampling.spp.max(1);
        wf.start_tile(q, &frame, 0);
        let all_slots = facet_gpu::dispatch::workgroups(wf.slots(), self.wg);
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            for _ in 0..warm {
                self.iteration(&mut pass, wf, all_slots);
            }
        }
        q.submit([enc.finish()]);
        let mut names = Vec::new();
        let (ms, clock) = match GpuTimer::new(d, q, 64) {
            Some(timer) => (
                self.time_stages_on_gpu(gpu, wf, all_slots, timer, &mut names)?,
                StageClock::Timestamps,
            ),
            None => (
                self.time_stages_by_wall_clock(gpu, wf, all_slots, &mut names)?,
                StageClock::Wall,
            ),
        };
        gpu.check_lost()?;
        wf.clear(gpu);
        let times = names
            .into_iter()
            .zip(ms)
            .map(|(stage, ms)| StageTime { stage, ms })
            .collect();
        Ok((times, clock))
    }

    /// One iteration with every stage in its own pass between two GPU timestamps; the stages'
    /// names go to `names`, their milliseconds are returned.
    fn time_stages_on_gpu(
        &self,
        gpu: &Gpu,
        wf: &Wavefront,
        all_slots: (u32, u32),
        mut timer: GpuTimer,
        names: &mut Vec<String>,
    ) -> Result<Vec<f64>, RenderError> {
        let (d, q) = (&gpu.device, &gpu.queue);
        let mut enc = d.create_command_encoder(&Default::default());
        self.iteration_by_stage(wf, all_slots, &mut |name, encode| {
            names.push(name.to_string());
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: None,
                timestamp_writes: timer.pass(),
            });
            encode(&mut pass);
        });
        q.submit([enc.finish()]);
        Ok(timer.read_ms(d, q)?)
    }

    /// One iteration with every stage in its own submission, each waited for and timed by the
    /// wall clock; the stages' names go to `names`, their milliseconds are returned.
    fn time_stages_by_wall_clock(
        &self,
        gpu: &Gpu,
        wf: &Wavefront,
        all_slots: (u32, u32),
        names: &mut Vec<String>,
    ) -> Result<Vec<f64>, RenderError> {
        let (d, q) = (&gpu.device, &gpu.queue);
        d.poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Scene(format!("GPU wait: {e}")))?;
        let mut ms = Vec::new();
        let mut failed = None;
        self.iteration_by_stage(wf, all_slots, &mut |name, encode| {
            names.push(name.to_string());
            let t = Instant::now();
            let mut enc = d.create_command_encoder(&Default::default());
            encode(&mut enc.begin_compute_pass(&Default::default()));
            q.submit([enc.finish()]);
            if let Err(e) = d.poll(wgpu::PollType::wait_indefinitely()) {
                failed = Some(e);
            }
            ms.push(t.elapsed().as_secs_f64() * 1e3);
        });
        if let Some(e) = failed {
            return Err(RenderError::Scene(format!("GPU wait: {e}")));
        }
        Ok(ms)
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
        let groups = wf.groups();
        let (frame_group, scene_group, glint_groups) =
            (&groups.frame, &groups.scene, &groups.glint);
        let (args_group, args) = (&groups.args, wf.args());
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
                Some(q) => format!("shade {}", q.class().map_or("none", |k| k.name())),
                None => s.name.to_string(),
            };
            each(&name, &mut |p| run(p, s));
        }
        each("close shadow", &mut |p| close(p, &self.close_shadow));
        each("connect", &mut |p| run(p, &self.connect));
    }
}

/// The shading stages of `scene`'s material classes, in queue order: one per class, one per
/// glint material.
fn shading_stages(
    device: &wgpu::Device,
    layouts: &Layouts,
    scene: &SceneResources,
) -> Result<Vec<Stage>, GpuError> {
    let mut shade = Vec::new();
    for &q in &scene.queues_used {
        let Some(class) = q.class() else { continue };
        shade.push(Stage::shading(device, layouts, &class.stage(), q)?);
    }
    Ok(shade)
}

/// The frame uniform, assembled here only: the image and the scene's part from `wf`, the
/// camera, the sampling; the tile fields are set per tile by the loop.
fn frame_uniform(wf: &Wavefront, camera: &CameraFrame, sampling: &SampleConfig) -> GpuFrame {
    let (width, height) = wf.size();
    let tan_half = (0.5 * camera.yfov).tan();
    let aspect = width as f32 / height as f32;
    // The ray cone's pixel spread angle (Akenine-Möller et al. 2019): atan(2 tan(yfov/2) / h).
    let spread = (2.0 * tan_half / height as f32).atan();
    GpuFrame {
        width,
        height,
        tile_base: 0,
        tile_pixels: 0,
        wavefront: wf.slots(),
        sample_end: 0,
        max_depth: sampling.max_depth,
        seed: sampling.seed,
        rr_depth: sampling.rr_depth,
        ray_epsilon: RAY_EPSILON,
        strategy: sampling.strategy as u32,
        ndf_sampling: sampling.ndf_sampling as u32,
        moments: wf.has_variance() as u32,
        sequence: sampling.sequence as u32,
        scene: *wf.scene_info(),
        cam_pos: camera.position.extend(tan_half).to_array(),
        cam_forward: camera.forward.extend(aspect).to_array(),
        cam_up: camera.up.extend(spread).to_array(),
        cam_right: camera.right.extend(0.0).to_array(),
        ..Default::default()
    }
}
