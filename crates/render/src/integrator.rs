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
use crate::gpu_types::{GpuFrame, PATH_REGIONS};
use crate::limits::{DeviceLimits, Planned, product};
use crate::queues::Queue;
use crate::resources::SceneResources;
use crate::stages::{Layouts, Stage, queue_args};
use facet_gpu::{Gpu, buffer, shader};
use std::time::Instant;

/// How direct light is estimated. Every choice converges to the same image; [`Strategy::Mis`]
/// has the least noise, the others are for checking it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u32)]
pub enum Strategy {
    /// Light sampling and BSDF sampling, combined by the power heuristic (Veach 1997).
    #[default]
    Mis = 0,
    /// Light sampling alone: emission that a BSDF-sampled ray finds counts only when light
    /// sampling could not have found it.
    Light = 1,
    /// BSDF sampling alone: only delta lights (point, spot, directional) are sampled.
    Bsdf = 2,
}

/// Settings of one render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderConfig {
    pub width: u32,
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Bounces after the camera ray (1: direct lighting only).
    pub max_depth: u32,
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
    pub strategy: Strategy,
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
        }
    }
}

/// What a render did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderStats {
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

    /// Renders `config.spp` samples per pixel (or fewer under a time limit); `progress` gets the
    /// fraction done after every tile.
    pub fn render(
        &self,
        gpu: &Gpu,
        scene: &SceneResources,
        camera: &CameraFrame,
        config: &RenderConfig,
        progress: &mut dyn FnMut(f64),
    ) -> Result<(Image, RenderStats), RenderError> {
        let d = &gpu.device;
        if config.width == 0 || config.height == 0 || config.spp == 0 {
            return Err(RenderError::Scene(format!(
                "nothing to render: {}×{} at {} spp",
                config.width, config.height, config.spp
            )));
        }
        let pixels = config.width as u64 * config.height as u64;
        // One dispatch reaches 65 535 × 65 535 × 64 threads; queues index with u32.
        let wavefront = (config.wavefront.max(64) as u64).min(pixels).min(1 << 24) as u32;
        let w = wavefront as u64;
        let nq = self.n_queues as u64;
        let render_size = format!(
            "the render size (--width × --height = {} × {})",
            config.width, config.height
        );
        let slots = format!(
            "--wavefront and --width × --height ({wavefront} paths in flight for {} × {} pixels)",
            config.width, config.height
        );
        let film_bytes = product(&[pixels, 16]);
        DeviceLimits::of(d).check(&[
            Planned::storage("the path state", product(&[PATH_REGIONS, w, 16]), &slots),
            Planned::storage("the path info", product(&[w, 16]), &slots),
            Planned::storage("the queues", product(&[nq, w, 4]), &slots),
            Planned::storage("the film", film_bytes, &render_size),
            Planned::buffer("the film read-back", film_bytes, &render_size),
        ])?;
        let t0 = Instant::now();
        let (frame_buf, paths, info, counters, sizes, args, queues, film) = gpu.scoped(|| {
            (
                buffer::uniform(d, "frame", &GpuFrame::default()),
                buffer::storage_zeroed(d, "paths", PATH_REGIONS * w * 16),
                buffer::storage_zeroed(d, "path info", w * 16),
                buffer::storage_zeroed(d, "queue counters", nq * 4),
                buffer::storage_zeroed(d, "queue sizes", nq * 4),
                d.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("queue dispatch args"),
                    size: nq * 12,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
                    mapped_at_creation: false,
                }),
                buffer::storage_zeroed(d, "queues", nq * w * 4),
                buffer::storage_zeroed(d, "film", pixels * 16),
            )
        })?;
        let group = |layout: &wgpu::BindGroupLayout, label, res: &[wgpu::BindingResource]| {
            let entries: Vec<wgpu::BindGroupEntry> = res
                .iter()
                .enumerate()
                .map(|(i, r)| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: r.clone(),
                })
                .collect();
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout,
                entries: &entries,
            })
        };
        let frame_group = group(
            &self.layouts.frame,
            "frame",
            &[
                frame_buf.as_entire_binding(),
                paths.as_entire_binding(),
                info.as_entire_binding(),
                counters.as_entire_binding(),
                sizes.as_entire_binding(),
                queues.as_entire_binding(),
                film.as_entire_binding(),
            ],
        );
        let scene_group = group(
            &self.layouts.scene,
            "scene",
            &[
                scene.bvh.nodes.as_entire_binding(),
                scene.bvh.primitives.as_entire_binding(),
                scene.bvh.triangles.as_entire_binding(),
                scene.vertices.as_entire_binding(),
                scene.triangles.as_entire_binding(),
                scene.materials.as_entire_binding(),
                scene.textures.as_entire_binding(),
                scene.lights.as_entire_binding(),
                scene.tables.as_entire_binding(),
                scene.triangle_light.as_entire_binding(),
            ],
        );
        let glint_groups: Vec<wgpu::BindGroup> = scene
            .glints
            .iter()
            .map(|g| {
                group(
                    &self.layouts.glint,
                    "glint",
                    &[
                        g.field.as_entire_binding(),
                        g.params.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&g.level0),
                        wgpu::BindingResource::TextureView(&g.level1),
                    ],
                )
            })
            .collect();
        let args_group = group(
            &self.layouts.queue_args,
            "queue args",
            &[
                counters.as_entire_binding(),
                sizes.as_entire_binding(),
                args.as_entire_binding(),
            ],
        );

        let mut frame = camera.gpu_frame(config);
        frame.wavefront = wavefront;
        frame.n_vertices = scene.n_vertices;
        frame.n_lights = scene.n_lights;
        frame.light_cdf = scene.light_cdf;
        frame.env_kind = scene.env_kind;
        (frame.env_width, frame.env_height) = scene.env_size;
        (frame.env_texels, frame.env_marginal, frame.env_conditional) = scene.env_offsets;
        frame.env_color = scene.env_color;
        frame.scene_radius = scene.scene_radius;
        frame.strategy = config.strategy as u32;

        let tiles = pixels.div_ceil(w);
        let per_pass = config.spp_per_pass.max(1);
        let passes = config.spp.div_ceil(per_pass);
        let mut stats = RenderStats::default();
        let all_slots = facet_gpu::dispatch::workgroups(wavefront, self.wg);
        'passes: for pass in 0..passes {
            let begin = pass * per_pass;
            let end = (begin + per_pass).min(config.spp);
            for tile in 0..tiles {
                let base = tile * w;
                frame.tile_base = base as u32;
                frame.tile_pixels = (pixels - base).min(w) as u32;
                frame.sample_end = end;
                gpu.queue
                    .write_buffer(&frame_buf, 0, bytemuck::bytes_of(&frame));
                let start: Vec<[u32; 4]> = vec![[0, begin, 0, 0]; frame.tile_pixels as usize];
                gpu.queue
                    .write_buffer(&info, 0, bytemuck::cast_slice(&start));
                gpu.queue
                    .write_buffer(&counters, 0, &vec![0u8; (nq * 4) as usize]);
                loop {
                    let mut enc = d.create_command_encoder(&Default::default());
                    {
                        let mut pass = enc.begin_compute_pass(&Default::default());
                        for _ in 0..config.iterations_per_check {
                            self.iteration(
                                &mut pass,
                                &frame_group,
                                &scene_group,
                                &glint_groups,
                                &args_group,
                                &args,
                                all_slots,
                            );
                        }
                    }
                    gpu.queue.submit([enc.finish()]);
                    stats.iterations += config.iterations_per_check as u64;
                    let s: Vec<u32> = buffer::read(d, &gpu.queue, &sizes, nq as usize)?;
                    gpu.check_lost()?;
                    // Nothing traced in the last iteration: every slot is idle.
                    if s[Queue::Extend.index() as usize] == 0 {
                        break;
                    }
                }
                stats.samples += frame.tile_pixels as u64 * (end - begin) as u64;
                let done = (pass as u64 * tiles + tile + 1) as f64 / (passes as u64 * tiles) as f64;
                progress(done);
            }
            stats.spp = end;
            if let Some(limit) = config.time_limit
                && t0.elapsed().as_secs_f64() >= limit
            {
                break 'passes;
            }
        }
        let film: Vec<[f32; 4]> = buffer::read(d, &gpu.queue, &film, pixels as usize)?;
        gpu.check_lost()?;
        stats.ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok((Image::from_film(config.width, config.height, &film), stats))
    }

    /// One iteration of the stage loop, encoded into `pass`.
    #[allow(clippy::too_many_arguments)]
    fn iteration(
        &self,
        pass: &mut wgpu::ComputePass,
        frame_group: &wgpu::BindGroup,
        scene_group: &wgpu::BindGroup,
        glint_groups: &[wgpu::BindGroup],
        args_group: &wgpu::BindGroup,
        args: &wgpu::Buffer,
        all_slots: (u32, u32),
    ) {
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
        run(pass, &self.logic);
        close(pass, &self.close_gen);
        run(pass, &self.generate);
        close(pass, &self.close_extend);
        run(pass, &self.extend);
        close(pass, &self.close_shade);
        for s in &self.shade {
            run(pass, s);
        }
        close(pass, &self.close_shadow);
        run(pass, &self.connect);
    }
}
