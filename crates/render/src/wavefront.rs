//! The integrator's GPU state for one image size — path state, queues, counters, film and their
//! bind groups — made once and reused by every render of that size. The film accumulates:
//! [`Wavefront::render_more`] adds samples to what is there, continuing each pixel's sample
//! indices, so 4 calls of 2 spp give the pixels of one 8 spp render with the same seed.

use crate::camera::CameraFrame;
use crate::error::RenderError;
use crate::film::Image;
use crate::gpu_types::{GpuFrame, PATH_REGIONS};
use crate::integrator::{Integrator, RenderConfig, RenderStats};
use crate::limits::{DeviceLimits, Planned, product};
use crate::queues::Queue;
use crate::resources::SceneResources;
use crate::tags::SlotState;
use crate::tonemap::ToneMap;
use facet_gpu::timer::GpuTimer;
use facet_gpu::{Gpu, buffer};
use std::time::Instant;

/// Paths in flight and film for one image size, bound to one scene's resources.
pub struct Wavefront {
    width: u32,
    height: u32,
    /// Paths in flight; the image is rendered in tiles of this many pixels.
    slots: u32,
    n_queues: u32,
    frame_buf: wgpu::Buffer,
    info: wgpu::Buffer,
    counters: wgpu::Buffer,
    sizes: wgpu::Buffer,
    args: wgpu::Buffer,
    film: wgpu::Buffer,
    /// Σ L² per pixel when `moments`, else one texel.
    film_sq: wgpu::Buffer,
    moments: bool,
    // Bound by the groups below; kept so that their owner is plain.
    _paths: wgpu::Buffer,
    _queues: wgpu::Buffer,
    pub(crate) frame_group: wgpu::BindGroup,
    pub(crate) scene_group: wgpu::BindGroup,
    pub(crate) glint_groups: Vec<wgpu::BindGroup>,
    pub(crate) args_group: wgpu::BindGroup,
    /// Samples per pixel in the film.
    spp: u32,
    /// The tone-mapping pass, made on first use.
    tone_map: Option<ToneMap>,
}

/// The time one batch of a progressive preview aims at, ms (a frame at 60 Hz).
pub const FRAME_MS: f64 = 16.0;
/// The most samples per pixel in one preview batch.
pub const MAX_SPP_PER_FRAME: u32 = 64;

/// The next preview batch (spp): the last one, which took `ms`, scaled toward FRAME_MS, at
/// most doubling or halving, within 1 … MAX_SPP_PER_FRAME.
pub fn next_batch(spp: u32, ms: f64) -> u32 {
    let scale = (FRAME_MS / ms.max(1e-3)).clamp(0.5, 2.0);
    ((spp as f64 * scale).floor() as u32).clamp(1, MAX_SPP_PER_FRAME)
}

/// One stage's share of one iteration.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    /// `logic`, `generate`, `extend`, `shade <class>`, `connect`, `close <queue>`.
    pub stage: String,
    /// Milliseconds.
    pub ms: f64,
}

/// How [`Wavefront::profile_iteration`] timed the stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StageClock {
    /// GPU timestamps at the boundaries of one pass per stage.
    Timestamps,
    /// The wall clock around one submission per stage (no timestamp queries): includes the
    /// submission and the wait, an upper bound.
    Wall,
}

/// The frame uniform, assembled here only: the camera, the image, the scene's lights and
/// environment, the tile being rendered (set per tile by `render_more`).
pub fn frame_uniform(
    scene: &SceneResources,
    camera: &CameraFrame,
    config: &RenderConfig,
    slots: u32,
) -> GpuFrame {
    let tan_half = (0.5 * camera.yfov).tan();
    let aspect = config.width as f32 / config.height as f32;
    // The ray cone's pixel spread angle (Akenine-Möller et al. 2019): atan(2 tan(yfov/2) / h).
    let spread = (2.0 * tan_half / config.height as f32).atan();
    GpuFrame {
        width: config.width,
        height: config.height,
        tile_base: 0,
        tile_pixels: 0,
        wavefront: slots,
        sample_end: 0,
        max_depth: config.max_depth,
        seed: config.seed,
        rr_depth: config.rr_depth,
        ray_epsilon: 1e-5,
        strategy: config.strategy as u32,
        ndf_sampling: config.ndf_sampling as u32,
        scene: scene.scene_info,
        cam_pos: camera.position.extend(tan_half).to_array(),
        cam_forward: camera.forward.extend(aspect).to_array(),
        cam_up: camera.up.extend(spread).to_array(),
        cam_right: camera.right.extend(0.0).to_array(),
        ..Default::default()
    }
}

impl Wavefront {
    /// GPU state for `width × height` images with `wavefront` paths in flight (clamped to
    /// 64 … min(pixels, 2^24)), bound to `scene` (whose buffers `update_material` rewrites in
    /// place; another scene needs another wavefront).
    pub fn new(
        gpu: &Gpu,
        integrator: &Integrator,
        scene: &SceneResources,
        width: u32,
        height: u32,
        wavefront: u32,
    ) -> Result<Self, RenderError> {
        Self::build(gpu, integrator, scene, (width, height), wavefront, false)
    }

    /// [`Wavefront::new`] whose film also keeps Σ L² per pixel, for [`Wavefront::variance`]
    /// (16 more bytes a pixel, one more add per sample).
    pub fn with_variance(
        gpu: &Gpu,
        integrator: &Integrator,
        scene: &SceneResources,
        width: u32,
        height: u32,
        wavefront: u32,
    ) -> Result<Self, RenderError> {
        Self::build(gpu, integrator, scene, (width, height), wavefront, true)
    }

    fn build(
        gpu: &Gpu,
        integrator: &Integrator,
        scene: &SceneResources,
        (width, height): (u32, u32),
        wavefront: u32,
        moments: bool,
    ) -> Result<Self, RenderError> {
        let d = &gpu.device;
        if width == 0 || height == 0 {
            return Err(RenderError::Scene(format!(
                "nothing to render: {width}×{height}"
            )));
        }
        let pixels = width as u64 * height as u64;
        // One dispatch reaches 65 535 × 65 535 × 64 threads; queues index with u32.
        let slots = (wavefront.max(64) as u64).min(pixels).min(1 << 24) as u32;
        let w = slots as u64;
        let n_queues = integrator.n_queues();
        let nq = n_queues as u64;
        let render_size = format!("the render size (--width × --height = {width} × {height})");
        let slots_by = format!(
            "--wavefront and --width × --height ({slots} paths in flight for {width} × {height} pixels)"
        );
        let film_bytes = product(&[pixels, 16]);
        DeviceLimits::of(d).check(&[
            Planned::storage("the path state", product(&[PATH_REGIONS, w, 16]), &slots_by),
            Planned::storage("the path info", product(&[w, 16]), &slots_by),
            Planned::storage("the queues", product(&[nq, w, 4]), &slots_by),
            Planned::storage("the film", film_bytes, &render_size),
            Planned::buffer("the film read-back", film_bytes, &render_size),
        ])?;
        let film_sq_bytes = if moments { pixels * 16 } else { 16 };
        let (frame_buf, paths, info, counters, sizes, args, queues, film, film_sq) =
            gpu.scoped(|| {
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
                    buffer::storage_zeroed(d, "film squares", film_sq_bytes),
                )
            })?;
        let layouts = integrator.layouts();
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
            &layouts.frame,
            "frame",
            &[
                frame_buf.as_entire_binding(),
                paths.as_entire_binding(),
                info.as_entire_binding(),
                counters.as_entire_binding(),
                sizes.as_entire_binding(),
                queues.as_entire_binding(),
                film.as_entire_binding(),
                film_sq.as_entire_binding(),
            ],
        );
        let scene_group = group(
            &layouts.scene,
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
        let glint_groups = scene
            .glints
            .iter()
            .map(|g| {
                group(
                    &layouts.glint,
                    "glint",
                    &[
                        g.field.as_entire_binding(),
                        g.params.as_entire_binding(),
                        wgpu::BindingResource::TextureView(&g.level0),
                        wgpu::BindingResource::TextureView(&g.level1),
                        g.split_table.as_entire_binding(),
                    ],
                )
            })
            .collect();
        let args_group = group(
            &layouts.queue_args,
            "queue args",
            &[
                counters.as_entire_binding(),
                sizes.as_entire_binding(),
                args.as_entire_binding(),
            ],
        );
        Ok(Wavefront {
            width,
            height,
            slots,
            n_queues,
            frame_buf,
            info,
            counters,
            sizes,
            args,
            film,
            film_sq,
            moments,
            _paths: paths,
            _queues: queues,
            frame_group,
            scene_group,
            glint_groups,
            args_group,
            spp: 0,
            tone_map: None,
        })
    }

    /// (width, height) of the images.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Paths in flight.
    pub fn slots(&self) -> u32 {
        self.slots
    }

    /// Samples per pixel accumulated in the film.
    pub fn spp(&self) -> u32 {
        self.spp
    }

    pub(crate) fn args(&self) -> &wgpu::Buffer {
        &self.args
    }

    /// Empties the film: the next samples start a new image (sample indices from 0).
    pub fn clear(&mut self, gpu: &Gpu) {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.film, 0, None);
        enc.clear_buffer(&self.film_sq, 0, None);
        gpu.queue.submit([enc.finish()]);
        self.spp = 0;
    }

    /// Adds `config.spp` samples per pixel to the film (fewer under `config.time_limit`: whole
    /// passes of `spp_per_pass`), continuing each pixel's sample indices; `progress` gets the
    /// fraction done after every tile. `config.width` and `height` must be the wavefront's;
    /// its `wavefront` is ignored (the wavefront's own slots are used).
    pub fn render_more(
        &mut self,
        gpu: &Gpu,
        integrator: &Integrator,
        scene: &SceneResources,
        camera: &CameraFrame,
        config: &RenderConfig,
        progress: &mut dyn FnMut(f64),
    ) -> Result<RenderStats, RenderError> {
        let d = &gpu.device;
        if (config.width, config.height) != (self.width, self.height) || config.spp == 0 {
            return Err(RenderError::Scene(format!(
                "a {}×{} wavefront cannot render {}×{} at {} spp",
                self.width, self.height, config.width, config.height, config.spp
            )));
        }
        let t0 = Instant::now();
        let pixels = self.width as u64 * self.height as u64;
        let w = self.slots as u64;
        let nq = self.n_queues as u64;
        let mut frame = frame_uniform(scene, camera, config, self.slots);
        frame.moments = self.moments as u32;
        let tiles = pixels.div_ceil(w);
        let per_pass = config.spp_per_pass.max(1);
        let (first, last) = (self.spp, self.spp.saturating_add(config.spp));
        let passes = config.spp.div_ceil(per_pass);
        let mut stats = RenderStats::default();
        let all_slots = facet_gpu::dispatch::workgroups(self.slots, integrator.workgroup());
        'passes: for pass in 0..passes {
            let begin = first + pass * per_pass;
            let end = (begin + per_pass).min(last);
            for tile in 0..tiles {
                let base = tile * w;
                frame.tile_base = base as u32;
                frame.tile_pixels = (pixels - base).min(w) as u32;
                frame.sample_end = end;
                gpu.queue
                    .write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
                let start: Vec<[u32; 4]> = vec![[SlotState::Start as u32, begin, 0, 0]; frame.tile_pixels as usize];
                gpu.queue
                    .write_buffer(&self.info, 0, bytemuck::cast_slice(&start));
                gpu.queue
                    .write_buffer(&self.counters, 0, &vec![0u8; (nq * 4) as usize]);
                loop {
                    let mut enc = d.create_command_encoder(&Default::default());
                    {
                        let mut cpass = enc.begin_compute_pass(&Default::default());
                        for _ in 0..config.iterations_per_check {
                            integrator.iteration(&mut cpass, self, all_slots);
                        }
                    }
                    gpu.queue.submit([enc.finish()]);
                    stats.iterations += config.iterations_per_check as u64;
                    let s: Vec<u32> = buffer::read(d, &gpu.queue, &self.sizes, nq as usize)?;
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
            self.spp = end;
            stats.spp = end - first;
            if let Some(limit) = config.time_limit
                && t0.elapsed().as_secs_f64() >= limit
            {
                break 'passes;
            }
        }
        stats.ms = t0.elapsed().as_secs_f64() * 1e3;
        Ok(stats)
    }

    /// The film read back: the mean of the samples so far.
    pub fn image(&self, gpu: &Gpu) -> Result<Image, RenderError> {
        let pixels = self.width as usize * self.height as usize;
        let film: Vec<[f32; 4]> = buffer::read(&gpu.device, &gpu.queue, &self.film, pixels)?;
        gpu.check_lost()?;
        Ok(Image::from_film(self.width, self.height, &film))
    }

    /// Per pixel, the variance of its mean (the estimate the image shows): the samples' unbiased
    /// variance over n, (Σ L² − n m²) / (n (n − 1)), 0 with fewer than two samples. `None`
    /// unless made [`Wavefront::with_variance`].
    pub fn variance(&self, gpu: &Gpu) -> Result<Option<Image>, RenderError> {
        if !self.moments {
            return Ok(None);
        }
        let pixels = self.width as usize * self.height as usize;
        let film: Vec<[f32; 4]> = buffer::read(&gpu.device, &gpu.queue, &self.film, pixels)?;
        let sq: Vec<[f32; 4]> = buffer::read(&gpu.device, &gpu.queue, &self.film_sq, pixels)?;
        gpu.check_lost()?;
        let var = film
            .iter()
            .zip(&sq)
            .map(|(s, q)| {
                let n = s[3] as f64;
                std::array::from_fn(|c| {
                    if n < 2.0 {
                        return 0.0;
                    }
                    let m = s[c] as f64 / n;
                    (((q[c] as f64 - n * m * m) / (n * (n - 1.0))).max(0.0)) as f32
                })
            })
            .collect();
        Ok(Some(Image {
            width: self.width,
            height: self.height,
            pixels: var,
            samples: film.iter().map(|s| s[3] as u32).collect(),
        }))
    }

    /// The film tone mapped on the GPU (`film`'s tone map at `exposure`), RGBA8 with alpha 255:
    /// a quarter of the film's bytes cross back to the CPU.
    pub fn tone_mapped(&mut self, gpu: &Gpu, exposure: f32) -> Result<Vec<[u8; 4]>, RenderError> {
        if self.tone_map.is_none() {
            self.tone_map = Some(ToneMap::new(gpu, &self.film, self.width, self.height)?);
        }
        let t = self.tone_map.as_ref().expect("made above");
        t.run(gpu, exposure)
    }

    /// Times each stage of one iteration in the middle of a render of the first tile: `warm`
    /// iterations fill the queues, then one runs with every stage in its own pass, timed by GPU
    /// timestamps where the device has them, else by the wall clock. The film is cleared after.
    pub fn profile_iteration(
        &mut self,
        gpu: &Gpu,
        integrator: &Integrator,
        scene: &SceneResources,
        camera: &CameraFrame,
        config: &RenderConfig,
        warm: u32,
    ) -> Result<(Vec<StageTime>, StageClock), RenderError> {
        let (d, q) = (&gpu.device, &gpu.queue);
        let pixels = self.width as u64 * self.height as u64;
        let mut frame = frame_uniform(scene, camera, config, self.slots);
        frame.tile_pixels = pixels.min(self.slots as u64) as u32;
        frame.sample_end = config.spp.max(1);
        q.write_buffer(&self.frame_buf, 0, bytemuck::bytes_of(&frame));
        let start: Vec<[u32; 4]> = vec![[SlotState::Start as u32, 0, 0, 0]; frame.tile_pixels as usize];
        q.write_buffer(&self.info, 0, bytemuck::cast_slice(&start));
        q.write_buffer(&self.counters, 0, &vec![0u8; self.n_queues as usize * 4]);
        let all_slots = facet_gpu::dispatch::workgroups(self.slots, integrator.workgroup());
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            for _ in 0..warm {
                integrator.iteration(&mut pass, self, all_slots);
            }
        }
        q.submit([enc.finish()]);
        let mut names = Vec::new();
        let result = match GpuTimer::new(d, q, 64) {
            Some(mut timer) => {
                let mut enc = d.create_command_encoder(&Default::default());
                integrator.iteration_by_stage(self, all_slots, &mut |name, encode| {
                    names.push(name.to_string());
                    let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                        label: None,
                        timestamp_writes: timer.pass(),
                    });
                    encode(&mut pass);
                });
                q.submit([enc.finish()]);
                (timer.read_ms(d, q)?, StageClock::Timestamps)
            }
            None => {
                d.poll(wgpu::PollType::wait_indefinitely())
                    .map_err(|e| RenderError::Scene(format!("GPU wait: {e}")))?;
                let mut ms = Vec::new();
                let mut failed = None;
                integrator.iteration_by_stage(self, all_slots, &mut |name, encode| {
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
                (ms, StageClock::Wall)
            }
        };
        gpu.check_lost()?;
        self.clear(gpu);
        let times = names
            .into_iter()
            .zip(result.0)
            .map(|(stage, ms)| StageTime { stage, ms })
            .collect();
        Ok((times, result.1))
    }
}
