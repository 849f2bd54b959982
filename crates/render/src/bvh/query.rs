//! Host driver of `shaders/render/trace_closest.wgsl` and `trace_any.wgsl`: closest-hit and any-hit queries for a batch of
//! rays against a [`GpuBvh`], one thread per ray, through the traversal the extend stage runs
//! (`bvh.inc.wgsl`). The CPU reference is [`Bvh::closest_hit`](crate::bvh::Bvh::closest_hit) /
//! [`Bvh::occluded`](crate::bvh::Bvh::occluded).

use crate::bvh::GpuBvh;
use bytemuck::{Pod, Zeroable};
use facet_gpu::timer::GpuTimer;
use facet_gpu::{GpuError, buffer, dispatch, shader};

/// The closest-hit pipeline's file, and the any-hit one's.
const CLOSEST: &str = "render/trace_closest.wgsl";
const ANY: &str = "render/trace_any.wgsl";

/// One ray (WGSL `Ray`, 32 bytes). `dir` need not be unit length: t is in units of `dir`.
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuRay {
    pub origin: [f32; 3],
    /// Unused, keep 0 (triangles count from t = 0, nodes from t = 1e-4, as in obvhs).
    pub tmin: f32,
    pub dir: [f32; 3],
    /// Hits count at t < tmax; `f32::INFINITY` for an unbounded ray.
    pub tmax: f32,
}

impl GpuRay {
    /// A ray from `origin` along `dir`, up to distance `tmax`.
    pub fn new(origin: glam::Vec3, dir: glam::Vec3, tmax: f32) -> Self {
        GpuRay {
            origin: origin.into(),
            tmin: 0.0,
            dir: dir.into(),
            tmax,
        }
    }
}

/// One closest hit (WGSL `Hit`, 16 bytes).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuHit {
    /// The hit's t; the ray's tmax on a miss.
    pub t: f32,
    /// Original triangle index, [`GpuHit::MISS`] on a miss.
    pub prim: u32,
    /// Barycentrics: p = (1−u−v)·v0 + u·v1 + v·v2.
    pub u: f32,
    pub v: f32,
}

impl GpuHit {
    /// `prim` of a ray that hit nothing.
    pub const MISS: u32 = u32::MAX;

    /// Whether the ray hit a triangle.
    pub fn is_hit(&self) -> bool {
        self.prim != Self::MISS
    }
}

/// Rays per dispatch when a batch is split: a multiple of 1024 keeps every sub-binding's offset
/// (32, 16 and 4 bytes per element) a multiple of the 256-byte storage offset alignment.
const CHUNK_ALIGN: u64 = 1024;

/// The traversal stack's depth: obvhs's `TRAVERSAL_STACK_SIZE`, under which
/// [`Bvh::validate`](crate::bvh::Bvh::validate) checks the tree's depth (WGSL `BVH_STACK_SIZE`).
pub const STACK_ENTRIES: u32 = 32;

/// Which query a batch answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceQuery {
    /// The nearest hit ([`GpuHit`] per ray).
    Closest,
    /// Whether anything is hit (a u32, 1 or 0, per ray).
    Any,
}

/// The two pipelines, `trace_closest.wgsl` and `trace_any.wgsl`.
pub struct RayTracer {
    closest: wgpu::ComputePipeline,
    any: wgpu::ComputePipeline,
    /// `@workgroup_size` of the shader, read by naga.
    workgroup_size: u32,
    /// Rays per dispatch.
    chunk: u64,
}

impl RayTracer {
    /// Builds the traversal pipelines on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        let pipeline = |file, entry| shader::compute_pipeline(device, file, entry, &[]);
        Ok(RayTracer {
            closest: pipeline(CLOSEST, "trace_closest_rays")?,
            any: pipeline(ANY, "trace_any_rays")?,
            // Both files take the batch's WG.
            workgroup_size: shader::workgroup_size(CLOSEST, "trace_closest_rays")?,
            chunk: Self::max_rays_per_dispatch(device),
        })
    }

    /// The same tracer splitting batches into dispatches of at most `rays` (rounded down to a
    /// multiple of 1024, at least 1024) rather than what the device's binding limit allows: for
    /// tests of the split.
    pub fn with_rays_per_dispatch(mut self, rays: u64) -> Self {
        self.chunk = self
            .chunk
            .min((rays / CHUNK_ALIGN * CHUNK_ALIGN).max(CHUNK_ALIGN));
        self
    }

    /// Most rays one dispatch takes: the ray binding (32 bytes a ray) within the device's
    /// storage binding limit, rounded down to `CHUNK_ALIGN`.
    pub fn max_rays_per_dispatch(device: &wgpu::Device) -> u64 {
        let limit = device.limits().max_storage_buffer_binding_size;
        (limit / size_of::<GpuRay>() as u64 / CHUNK_ALIGN * CHUNK_ALIGN).max(CHUNK_ALIGN)
    }

    /// Closest hits of `rays` (uploads, runs, reads back; batched past the binding limit).
    pub fn trace_closest(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        bvh: &GpuBvh,
        rays: &[GpuRay],
    ) -> Result<Vec<GpuHit>, GpuError> {
        self.trace_batches(device, queue, bvh, TraceQuery::Closest, rays)
    }

    /// 1 where a triangle lies at t < tmax along the ray, else 0.
    pub fn trace_any(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        bvh: &GpuBvh,
        rays: &[GpuRay],
    ) -> Result<Vec<u32>, GpuError> {
        self.trace_batches(device, queue, bvh, TraceQuery::Any, rays)
    }

    fn trace_batches<T: Pod>(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        bvh: &GpuBvh,
        query: TraceQuery,
        rays: &[GpuRay],
    ) -> Result<Vec<T>, GpuError> {
        // One upload per chunk keeps host-side buffers within the per-buffer limit too.
        let mut out = Vec::with_capacity(rays.len());
        for part in rays.chunks(self.chunk as usize) {
            let ray_buf = buffer::storage(device, "rays", part);
            let out_buf =
                buffer::storage_zeroed(device, "trace out", (part.len() * size_of::<T>()) as u64);
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("trace"),
            });
            let batch = TraceBatch {
                rays: &ray_buf,
                out: &out_buf,
                count: part.len() as u32,
            };
            self.encode(device, &mut encoder, bvh, query, batch, None);
            queue.submit([encoder.finish()]);
            out.extend(buffer::read::<T>(device, queue, &out_buf, part.len())?);
        }
        Ok(out)
    }

    /// Encodes closest-hit queries for the first `count` rays of `rays` (WGSL `Ray`s) into the
    /// first `count` entries of `hits` (WGSL `Hit`s), without submitting: for callers that keep
    /// rays on the GPU (benchmarks, the extend stage).
    pub fn encode_closest(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bvh: &GpuBvh,
        rays: &wgpu::Buffer,
        hits: &wgpu::Buffer,
        count: u32,
    ) {
        let batch = TraceBatch {
            rays,
            out: hits,
            count,
        };
        self.encode(device, encoder, bvh, TraceQuery::Closest, batch, None);
    }

    /// As [`RayTracer::encode_closest`] for any-hit queries: one u32 per ray into `occluded`.
    pub fn encode_any(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bvh: &GpuBvh,
        rays: &wgpu::Buffer,
        occluded: &wgpu::Buffer,
        count: u32,
    ) {
        let batch = TraceBatch {
            rays,
            out: occluded,
            count,
        };
        self.encode(device, encoder, bvh, TraceQuery::Any, batch, None);
    }

    /// Encodes `query` for `batch`, one compute pass per dispatch (several when the batch
    /// exceeds what one ray binding holds), each timed by `timer` when given. Layouts come from
    /// the shader, so a binding an entry point does not use (any-hit never reads
    /// `bvh_primitives`) is left out.
    pub fn encode(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        bvh: &GpuBvh,
        query: TraceQuery,
        batch: TraceBatch<'_>,
        mut timer: Option<&mut GpuTimer>,
    ) {
        let (pipeline, out_binding, out_size) = match query {
            TraceQuery::Closest => (&self.closest, 4, size_of::<GpuHit>()),
            TraceQuery::Any => (&self.any, 5, size_of::<u32>()),
        };
        let layout = pipeline.get_bind_group_layout(0);
        let mut start = 0u64;
        while start < batch.count as u64 {
            let n = self.chunk.min(batch.count as u64 - start);
            let mut entries = vec![
                entry(0, bvh.nodes.as_entire_binding()),
                entry(2, bvh.triangles.as_entire_binding()),
                entry(3, sub_range(batch.rays, start, n, size_of::<GpuRay>())),
                entry(out_binding, sub_range(batch.out, start, n, out_size)),
            ];
            if query == TraceQuery::Closest {
                entries.push(entry(1, bvh.primitives.as_entire_binding()));
            }
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("trace"),
                layout: &layout,
                entries: &entries,
            });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("trace"),
                timestamp_writes: timer.as_deref_mut().and_then(GpuTimer::pass),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            let (x, y) = dispatch::workgroups(n as u32, self.workgroup_size);
            pass.dispatch_workgroups(x, y, 1);
            drop(pass);
            start += n;
        }
    }
}

/// Rays on the GPU and where their answers go: the first `count` WGSL `Ray`s of `rays`, and as
/// many [`GpuHit`]s (closest hit) or u32s (any hit) of `out`.
#[derive(Clone, Copy)]
pub struct TraceBatch<'a> {
    /// The rays.
    pub rays: &'a wgpu::Buffer,
    /// The answers.
    pub out: &'a wgpu::Buffer,
    /// How many.
    pub count: u32,
}

fn entry(binding: u32, resource: wgpu::BindingResource<'_>) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry { binding, resource }
}

/// Elements [start, start + n) of a buffer of `size`-byte elements.
fn sub_range(buffer: &wgpu::Buffer, start: u64, n: u64, size: usize) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer,
        offset: start * size as u64,
        size: wgpu::BufferSize::new(n * size as u64),
    })
}
