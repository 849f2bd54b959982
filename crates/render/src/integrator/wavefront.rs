//! The integrator's GPU state for one image — path state, queues, counters, film and their
//! bind groups — made once by [`Integrator::wavefront`](crate::Integrator::wavefront) and reused
//! by every render of that image, and the film's read-back. The loop that runs the stages over
//! it is the integrator's ([`Integrator::render_more`](crate::Integrator::render_more)); the
//! film accumulates, continuing each pixel's sample indices, so 4 calls of 2 spp give the
//! pixels of one 8 spp render with the same seed.

use crate::error::RenderError;
use crate::integrator::config::ImageConfig;
use crate::integrator::stages::Layouts;
use crate::layout::bindings::{Group, bind_group};
use crate::layout::gpu_types::{GpuFrame, GpuSceneInfo, PATH_REGIONS};
use crate::layout::limits::{DeviceLimits, Planned, product};
use crate::layout::tags::SlotState;
use crate::output::film::{Image, to_f32_saturated};
use crate::output::tonemap::ToneMap;
use crate::resources::SceneResources;
use facet_gpu::{Gpu, buffer};

/// Paths in flight and film for one image, bound to one scene's resources.
pub struct Wavefront {
    width: u32,
    height: u32,
    /// Paths in flight; the image is rendered in tiles of this many pixels.
    slots: u32,
    n_queues: u32,
    /// The scene's part of the frame uniform, copied from the scene the groups bind.
    scene_info: GpuSceneInfo,
    /// Whether the film keeps Σ L² per pixel too.
    moments: bool,
    buffers: Buffers,
    groups: Groups,
    /// The sample indices in the film: [first, next) of every pixel.
    samples: std::ops::Range<u32>,
    /// The tone-mapping pass, made on first use.
    tone_map: Option<ToneMap>,
}

/// The wavefront's buffers.
struct Buffers {
    frame: wgpu::Buffer,
    /// One vec4 per slot and path-state region.
    paths: wgpu::Buffer,
    /// Per slot: state, next sample, depth.
    info: wgpu::Buffer,
    counters: wgpu::Buffer,
    sizes: wgpu::Buffer,
    /// The queues' indirect dispatch arguments, 12 bytes a queue.
    args: wgpu::Buffer,
    queues: wgpu::Buffer,
    film: wgpu::Buffer,
    /// Σ L² per pixel when `moments`, else one texel.
    film_sq: wgpu::Buffer,
}

/// The bind groups of the stages (groups 0, 1 and a glint stage's 2) and of the queue closes.
pub(crate) struct Groups {
    /// Group 0: frame, path state, queues, film.
    pub frame: wgpu::BindGroup,
    /// Group 1: the scene.
    pub scene: wgpu::BindGroup,
    /// Group 2 of glint material k's stage.
    pub glint: Vec<wgpu::BindGroup>,
    /// The queue closes' group: counters, sizes, dispatch arguments.
    pub args: wgpu::BindGroup,
}

impl Wavefront {
    /// GPU state for `image` (its paths in flight clamped to 64 … min(pixels, 2^24)), with
    /// `n_queues` queues, bound to `scene` (whose buffers `update_material` rewrites in place;
    /// another scene needs another wavefront) through the stages' `layouts`.
    pub(crate) fn build(
        gpu: &Gpu,
        layouts: &Layouts,
        n_queues: u32,
        scene: &SceneResources,
        image: ImageConfig,
        moments: bool,
    ) -> Result<Self, RenderError> {
        let ImageConfig { width, height, .. } = image;
        if width == 0 || height == 0 {
            return Err(RenderError::Scene(format!(
                "nothing to render: {width}×{height}"
            )));
        }
        let slots = slots_for(image);
        check_limits(&gpu.device, image, slots, n_queues)?;
        let buffers = Buffers::new(gpu, image, slots, n_queues, moments)?;
        let groups = Groups::new(&gpu.device, layouts, &buffers, scene);
        Ok(Wavefront {
            width,
            height,
            slots,
            n_queues,
            scene_info: scene.scene_info,
            moments,
            buffers,
            groups,
            samples: 0..0,
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
        self.samples.len() as u32
    }

    /// The sample indices in the film, the same for every pixel: [first, next). The next
    /// [`Integrator::render_more`](crate::Integrator::render_more) continues from `next`.
    pub fn sample_range(&self) -> std::ops::Range<u32> {
        self.samples.clone()
    }

    /// Whether the film keeps Σ L² per pixel ([`Wavefront::variance`]).
    pub fn has_variance(&self) -> bool {
        self.moments
    }

    /// Queues of the integrator it was made for.
    pub(crate) fn n_queues(&self) -> u32 {
        self.n_queues
    }

    /// The scene's part of the frame uniform.
    pub(crate) fn scene_info(&self) -> &GpuSceneInfo {
        &self.scene_info
    }

    pub(crate) fn groups(&self) -> &Groups {
        &self.groups
    }

    /// The queues' indirect dispatch arguments.
    pub(crate) fn args(&self) -> &wgpu::Buffer {
        &self.buffers.args
    }

    /// Records that the film now holds the samples up to index `next` (exclusive).
    pub(crate) fn set_next_sample(&mut self, next: u32) {
        debug_assert!(next >= self.samples.end, "sample indices only grow");
        self.samples.end = next;
    }

    /// Starts a tile: the frame uniform `frame`, every slot of the tile at
    /// [`SlotState::Start`] with its next sample `first_sample`, the queue counters at 0.
    pub(crate) fn start_tile(&self, queue: &wgpu::Queue, frame: &GpuFrame, first_sample: u32) {
        let b = &self.buffers;
        queue.write_buffer(&b.frame, 0, bytemuck::bytes_of(frame));
        let start = [SlotState::Start as u32, first_sample, 0, 0];
        let info = vec![start; frame.tile_pixels as usize];
        queue.write_buffer(&b.info, 0, bytemuck::cast_slice(&info));
        queue.write_buffer(&b.counters, 0, &vec![0u8; self.n_queues as usize * 4]);
    }

    /// The queue sizes of the last iteration, read back.
    pub(crate) fn read_sizes(&self, gpu: &Gpu) -> Result<Vec<u32>, RenderError> {
        let sizes = buffer::read(
            &gpu.device,
            &gpu.queue,
            &self.buffers.sizes,
            self.n_queues as usize,
        )?;
        gpu.check_lost()?;
        Ok(sizes)
    }

    /// Empties the film: the next samples start a new image (sample indices from 0).
    pub fn clear(&mut self, gpu: &Gpu) {
        self.start_at(gpu, 0);
    }

    /// Empties the film and starts it at sample index `first`: the next
    /// [`Integrator::render_more`](crate::Integrator::render_more) takes samples `first`,
    /// `first + 1`, … of every pixel, the ones a render from 0 would take there. A shard of a
    /// render is [`Wavefront::start_at`] its range's start, then its count.
    pub fn start_at(&mut self, gpu: &Gpu, first: u32) {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.buffers.film, 0, None);
        enc.clear_buffer(&self.buffers.film_sq, 0, None);
        gpu.queue.submit([enc.finish()]);
        self.samples = first..first;
    }

    /// The film read back: the mean of the samples so far.
    pub fn image(&self, gpu: &Gpu) -> Result<Image, RenderError> {
        let film = self.read_film(gpu, &self.buffers.film)?;
        Ok(Image::from_film(self.width, self.height, &film))
    }

    /// Per pixel, the variance of its mean (the estimate the image shows): the samples' unbiased
    /// variance over n, (r² − m²) / (n − 1) from their mean m and root mean square r (in f64),
    /// 0 with fewer than two samples, at most `f32::MAX` (an image holds no more: a variance
    /// past it, from radiance past 1.8e19, is saturated, [`crate::output::film::saturated_count`] counts them).
    /// `None` unless made by
    /// [`Integrator::wavefront_with_variance`](crate::Integrator::wavefront_with_variance).
    pub fn variance(&self, gpu: &Gpu) -> Result<Option<Image>, RenderError> {
        if !self.moments {
            return Ok(None);
        }
        let film = self.read_film(gpu, &self.buffers.film)?;
        let rms = self.read_film(gpu, &self.buffers.film_sq)?;
        let var = film
            .iter()
            .zip(&rms)
            .map(|(f, r)| {
                let n = f[3] as f64;
                std::array::from_fn(|c| {
                    if n < 2.0 {
                        return 0.0;
                    }
                    let (m, r) = (f[c] as f64, r[c] as f64);
                    to_f32_saturated(((r * r - m * m) / (n - 1.0)).max(0.0))
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
            let t = ToneMap::new(gpu, &self.buffers.film, self.width, self.height)?;
            self.tone_map = Some(t);
        }
        let t = self.tone_map.as_ref().expect("made above");
        t.run(gpu, exposure)
    }

    /// One vec4 per pixel of `film` (the film or its squares), read back.
    fn read_film(&self, gpu: &Gpu, film: &wgpu::Buffer) -> Result<Vec<[f32; 4]>, RenderError> {
        let pixels = self.width as usize * self.height as usize;
        let texels = buffer::read(&gpu.device, &gpu.queue, film, pixels)?;
        gpu.check_lost()?;
        Ok(texels)
    }
}

/// The paths in flight for `image`: its `wavefront` within 64 … min(pixels, 2^24) (one dispatch
/// reaches 65 535 × 65 535 × 64 threads; queues index with u32).
fn slots_for(image: ImageConfig) -> u32 {
    let pixels = image.width as u64 * image.height as u64;
    (image.wavefront.max(64) as u64).min(pixels).min(1 << 24) as u32
}

/// The wavefront's buffers within the device's limits, or an error that names the option that
/// sets each size.
fn check_limits(
    device: &wgpu::Device,
    image: ImageConfig,
    slots: u32,
    n_queues: u32,
) -> Result<(), RenderError> {
    let ImageConfig { width, height, .. } = image;
    let pixels = width as u64 * height as u64;
    let (w, nq) = (slots as u64, n_queues as u64);
    let render_size = format!("the render size (--width × --height = {width} × {height})");
    let slots_by = format!(
        "--wavefront and --width × --height ({slots} paths in flight for {width} × {height} pixels)"
    );
    let film_bytes = product(&[pixels, 16]);
    DeviceLimits::of(device).check(&[
        Planned::storage("the path state", product(&[PATH_REGIONS, w, 16]), &slots_by),
        Planned::storage("the path info", product(&[w, 16]), &slots_by),
        Planned::storage("the queues", product(&[nq, w, 4]), &slots_by),
        Planned::storage("the film", film_bytes, &render_size),
        Planned::buffer("the film read-back", film_bytes, &render_size),
    ])?;
    Ok(())
}

impl Buffers {
    fn new(
        gpu: &Gpu,
        image: ImageConfig,
        slots: u32,
        n_queues: u32,
        moments: bool,
    ) -> Result<Self, RenderError> {
        let d = &gpu.device;
        let pixels = image.width as u64 * image.height as u64;
        let (w, nq) = (slots as u64, n_queues as u64);
        let film_sq_bytes = if moments { pixels * 16 } else { 16 };
        let buffers = gpu.scoped(|| Buffers {
            frame: buffer::uniform(d, "frame", &GpuFrame::default()),
            paths: buffer::storage_zeroed(d, "paths", PATH_REGIONS * w * 16),
            info: buffer::storage_zeroed(d, "path info", w * 16),
            counters: buffer::storage_zeroed(d, "queue counters", nq * 4),
            sizes: buffer::storage_zeroed(d, "queue sizes", nq * 4),
            args: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some("queue dispatch args"),
                size: nq * 12,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
                mapped_at_creation: false,
            }),
            queues: buffer::storage_zeroed(d, "queues", nq * w * 4),
            film: buffer::storage_zeroed(d, "film", pixels * 16),
            film_sq: buffer::storage_zeroed(d, "film squares", film_sq_bytes),
        })?;
        Ok(buffers)
    }
}

impl Groups {
    fn new(d: &wgpu::Device, layouts: &Layouts, b: &Buffers, scene: &SceneResources) -> Self {
        let group = |g: Group, named: &[(&str, wgpu::BindingResource)]| {
            bind_group(d, layouts.of(g), g, named)
        };
        let frame = group(
            Group::Frame,
            &[
                ("frame", b.frame.as_entire_binding()),
                ("paths", b.paths.as_entire_binding()),
                ("info", b.info.as_entire_binding()),
                ("counters", b.counters.as_entire_binding()),
                ("sizes", b.sizes.as_entire_binding()),
                ("queues", b.queues.as_entire_binding()),
                ("film", b.film.as_entire_binding()),
                ("film_sq", b.film_sq.as_entire_binding()),
            ],
        );
        let args = group(
            Group::QueueArgs,
            &[
                ("counters", b.counters.as_entire_binding()),
                ("sizes", b.sizes.as_entire_binding()),
                ("args", b.args.as_entire_binding()),
            ],
        );
        Groups {
            frame,
            scene: group(Group::Scene, &scene.bindings()),
            glint: scene
                .glints
                .iter()
                .map(|g| group(Group::Glint, &g.bindings()))
                .collect(),
            args,
        }
    }
}
