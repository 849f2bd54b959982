//! Host driver of `shaders/render/trace.wgsl`: closest-hit and any-hit queries for a batch of
//! rays against a [`GpuBvh`], scheduled as a [`TraceVariant`] says (one thread per ray by
//! default). The CPU reference is [`Bvh::closest_hit`](crate::bvh::Bvh::closest_hit) /
//! [`Bvh::occluded`](crate::bvh::Bvh::occluded).

use crate::bvh::GpuBvh;
use bytemuck::{Pod, Zeroable};
use facet_gpu::shader::IncludeSwap;
use facet_gpu::timer::GpuTimer;
use facet_gpu::{GpuError, buffer, dispatch, shader};

const SHADER: &str = "render/trace.wgsl";

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

/// How the traversal kernel hands rays to threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceSchedule {
    /// One thread per ray, as many workgroups as the rays need.
    PerRay,
    /// Persistent threads (Aila & Laine 2009): at most `groups` workgroups loop, each taking
    /// the next workgroup-sized batch of rays with one atomic add until none are left.
    Persistent {
        /// Workgroups launched (fewer when the rays fill fewer batches).
        groups: u32,
    },
}

/// A traversal kernel's variant, chosen when its pipelines are built, each checked against obvhs
/// on the CPU (`crates/render/tests/bvh.rs`) and timed by `facet bench --variants`. The
/// traversal itself (Ylitie et al. 2017's compressed wide BVH, octant-ordered children, the
/// short stack of node groups) is the same in all of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceVariant {
    /// How rays reach threads.
    pub schedule: TraceSchedule,
    /// Threads per workgroup (WGSL override `WG`), 1 to the device's limit.
    pub workgroup: u32,
    /// Entries at the bottom of each thread's traversal stack kept in workgroup (shared)
    /// memory rather than in the thread's own array, which a GPU keeps in local memory when it
    /// is indexed at run time (WGSL override `BVH_WG_STACK`, 0 to [`STACK_ENTRIES`]; 0: none).
    /// A node group is 8 bytes: a workgroup takes `8 · wg_stack · workgroup` bytes.
    pub wg_stack: u32,
    /// Postponed triangle tests (Ylitie et al. 2017): a thread about to test triangles pushes
    /// them and visits nodes first while fewer than this percentage of its subgroup's threads
    /// are at their triangle tests (0: never, the default; 1 to 100). Needs a device with
    /// `wgpu::Features::SUBGROUP`; swaps [`POSTPONE_SWAP`] into the traversal.
    pub postpone: u32,
}

/// The include a [`TraceVariant`] with `postpone` swaps into the traversal: subgroup ballots in
/// place of the default's "never".
pub const POSTPONE_SWAP: IncludeSwap = (
    "render/bvh_postpone.inc.wgsl",
    "render/bvh_postpone_subgroup.inc.wgsl",
);

/// The traversal stack's depth (obvhs's `TRAVERSAL_STACK_SIZE`, WGSL `BVH_STACK_SIZE`).
pub const STACK_ENTRIES: u32 = 32;

impl TraceVariant {
    /// One thread per ray in workgroups of `workgroup`.
    pub const fn per_ray(workgroup: u32) -> Self {
        TraceVariant {
            schedule: TraceSchedule::PerRay,
            workgroup,
            wg_stack: 0,
            postpone: 0,
        }
    }

    /// Persistent threads: `groups` workgroups of `workgroup` threads.
    pub const fn persistent(workgroup: u32, groups: u32) -> Self {
        TraceVariant {
            schedule: TraceSchedule::Persistent { groups },
            workgroup,
            wg_stack: 0,
            postpone: 0,
        }
    }

    /// The same variant with the bottom `entries` of each thread's stack in workgroup memory.
    pub const fn with_wg_stack(self, entries: u32) -> Self {
        TraceVariant {
            wg_stack: entries,
            ..self
        }
    }

    /// The same variant with its triangle tests postponed below `percent` of a subgroup.
    pub const fn with_postpone(self, percent: u32) -> Self {
        TraceVariant {
            postpone: percent,
            ..self
        }
    }

    /// The override constants of its pipelines (`WG`, `BVH_WG_STACK`, and
    /// `BVH_POSTPONE_BELOW` where it postpones).
    pub fn constants(&self) -> Vec<(&'static str, f64)> {
        let mut c = vec![
            ("WG", self.workgroup as f64),
            ("BVH_WG_STACK", self.wg_stack as f64),
        ];
        if self.postpone > 0 {
            c.push(("BVH_POSTPONE_BELOW", self.postpone as f64));
        }
        c
    }

    /// The includes its pipelines swap.
    pub fn swaps(&self) -> &'static [IncludeSwap] {
        if self.postpone > 0 {
            &[POSTPONE_SWAP]
        } else {
            &[]
        }
    }

    /// Bytes of workgroup memory its stack takes.
    pub fn wg_stack_bytes(&self) -> u64 {
        8 * self.wg_stack as u64 * self.workgroup as u64
    }

    /// The kernel every other user of the traversal gets.
    pub const DEFAULT: TraceVariant = TraceVariant::per_ray(64);

    /// The variants `facet bench --only trace --variants` times side by side: workgroup
    /// sizes about the SIMD widths (32 on NVIDIA, 64 on AMD); persistent threads with one
    /// warp per workgroup (the paper's) at two occupancies of a large GPU (an H100 has 132
    /// SMs of 64 warps: 8448 warps) and with two warps; the stack's bottom 8 entries in
    /// workgroup memory (a descent pushes at most once a level, so 8 entries hold the first 8
    /// levels' pushes; 2 KiB a workgroup of 32), and the whole stack there (8 KiB a workgroup
    /// of 32, which bounds occupancy); triangle tests postponed below 20 % of a subgroup (one
    /// threshold to start from), alone and with the shared stack. A device without subgroup
    /// operations runs all but the postponing ones ([`TraceVariant::runnable`]).
    pub const ALL: [TraceVariant; 14] = [
        TraceVariant::DEFAULT,
        TraceVariant::per_ray(32),
        TraceVariant::per_ray(128),
        TraceVariant::per_ray(256),
        TraceVariant::persistent(32, 2048),
        TraceVariant::persistent(32, 8192),
        TraceVariant::persistent(64, 4096),
        TraceVariant::per_ray(32).with_wg_stack(8),
        TraceVariant::per_ray(64).with_wg_stack(8),
        TraceVariant::per_ray(32).with_wg_stack(STACK_ENTRIES),
        TraceVariant::persistent(32, 8192).with_wg_stack(8),
        TraceVariant::per_ray(64).with_postpone(20),
        TraceVariant::per_ray(32).with_postpone(20),
        TraceVariant::per_ray(32).with_wg_stack(8).with_postpone(20),
    ];

    /// The variants of [`TraceVariant::ALL`] that `device` can run.
    pub fn runnable(device: &wgpu::Device) -> Vec<TraceVariant> {
        Self::ALL
            .into_iter()
            .filter(|v| v.validate(device).is_ok())
            .collect()
    }

    /// A short name: `per-ray/64`, `persistent/32x2048`, `per-ray/32/wg-stack-8`,
    /// `per-ray/64/postpone-20`.
    pub fn key(&self) -> String {
        let mut key = match self.schedule {
            TraceSchedule::PerRay => format!("per-ray/{}", self.workgroup),
            TraceSchedule::Persistent { groups } => {
                format!("persistent/{}x{groups}", self.workgroup)
            }
        };
        if self.wg_stack > 0 {
            key += &format!("/wg-stack-{}", self.wg_stack);
        }
        if self.postpone > 0 {
            key += &format!("/postpone-{}", self.postpone);
        }
        key
    }

    /// An error naming the variant when `device` cannot run it.
    pub fn validate(&self, device: &wgpu::Device) -> Result<(), GpuError> {
        let limits = device.limits();
        let max = limits
            .max_compute_invocations_per_workgroup
            .min(limits.max_compute_workgroup_size_x);
        let bad = |problem: String| Err(GpuError::Validation(format!("{}: {problem}", self.key())));
        if !(1..=max).contains(&self.workgroup) {
            return bad(format!(
                "{} threads a workgroup, outside 1..={max}",
                self.workgroup
            ));
        }
        if self.schedule == (TraceSchedule::Persistent { groups: 0 }) {
            return bad("no workgroups".into());
        }
        if self.wg_stack > STACK_ENTRIES {
            return bad(format!(
                "{} stack entries in workgroup memory, past the stack's {STACK_ENTRIES}",
                self.wg_stack
            ));
        }
        if self.postpone > 100 {
            return bad(format!("postponed below {} % of a subgroup", self.postpone));
        }
        if self.postpone > 0 && !device.features().contains(wgpu::Features::SUBGROUP) {
            return bad("postponing needs subgroup operations, which the device lacks".into());
        }
        // The persistent schedule's batch start (4 bytes) beside the stack.
        let shared = self.wg_stack_bytes() + 4;
        if shared > limits.max_compute_workgroup_storage_size as u64 {
            return bad(format!(
                "{shared} bytes of workgroup memory, past the device's {}",
                limits.max_compute_workgroup_storage_size
            ));
        }
        Ok(())
    }
}

/// Which query a batch answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceQuery {
    /// The nearest hit ([`GpuHit`] per ray).
    Closest,
    /// Whether anything is hit (a u32, 1 or 0, per ray).
    Any,
}

/// The two pipelines of `trace.wgsl` in one [`TraceVariant`].
pub struct RayTracer {
    closest: wgpu::ComputePipeline,
    any: wgpu::ComputePipeline,
    variant: TraceVariant,
    /// The persistent schedule's ray counter (none for one thread per ray).
    next_ray: Option<wgpu::Buffer>,
    /// Rays per dispatch.
    chunk: u64,
}

impl RayTracer {
    /// Builds the traversal pipelines of [`TraceVariant::DEFAULT`] on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        Self::with_variant(device, TraceVariant::DEFAULT)
    }

    /// Builds the traversal pipelines of `variant` on `device`.
    pub fn with_variant(device: &wgpu::Device, variant: TraceVariant) -> Result<Self, GpuError> {
        variant.validate(device)?;
        let (closest, any) = match variant.schedule {
            TraceSchedule::PerRay => ("trace_closest_rays", "trace_any_rays"),
            TraceSchedule::Persistent { .. } => {
                ("trace_closest_persistent", "trace_any_persistent")
            }
        };
        let constants = variant.constants();
        let next_ray = matches!(variant.schedule, TraceSchedule::Persistent { .. }).then(|| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("next ray"),
                size: 4,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        });
        let pipeline = |entry| {
            let swaps = variant.swaps();
            shader::compute_pipeline_variant(device, SHADER, swaps, entry, None, &constants)
        };
        Ok(RayTracer {
            closest: pipeline(closest)?,
            any: pipeline(any)?,
            variant,
            next_ray,
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

    /// The variant its pipelines were built for.
    pub fn variant(&self) -> TraceVariant {
        self.variant
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
    /// `bvh_primitives`) is left out. A persistent schedule's counter is cleared before each
    /// dispatch.
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
        let wg = self.variant.workgroup;
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
            if let Some(next_ray) = &self.next_ray {
                encoder.clear_buffer(next_ray, 0, None);
                entries.push(entry(6, next_ray.as_entire_binding()));
            }
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("trace"),
                layout: &layout,
                entries: &entries,
            });
            let threads = match self.variant.schedule {
                TraceSchedule::PerRay => n as u32,
                // No more workgroups than batches.
                TraceSchedule::Persistent { groups } => groups.min((n as u32).div_ceil(wg)) * wg,
            };
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("trace"),
                timestamp_writes: timer.as_deref_mut().and_then(GpuTimer::pass),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            let (x, y) = dispatch::workgroups(threads, wg);
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
