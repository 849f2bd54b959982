//! Host driver of `shaders/fit/kernel.wgsl` and the normalisation's two passes,
//! `shaders/fit/normalise_reduce.wgsl` and `normalise_rescale.wgsl`.
//!
//! Iterations run in batches of [`BATCH`] per submission: kernel (y = K v), reduce (λ and the
//! residual into `stats`, on the GPU), rescale (v = y / λ). Only the batch's `stats` come back,
//! so convergence is checked without a read-back per iteration.

use super::{GpuFitter, GpuNode, GpuState, gpu_error};
use crate::error::FitError;
use crate::extract::{Eigen, Problem, Solver, Stopping};
use facet_gpu::{Gpu, GpuError, buffer, dispatch, shader};

/// Iterations per submission.
const BATCH: usize = 8;
/// The smallest residual f32 iteration reaches reliably (~10 ulps of the L1 norm, which is 1):
/// a tighter tolerance is taken as this one on the GPU.
const F32_RESIDUAL_FLOOR: f64 = 1e-6;

/// The power iteration and the D / G1 table integrals on the GPU (`shaders/fit/kernel.wgsl`, `normalise_*.wgsl`).
pub struct PowerIteration {
    kernel_iso: wgpu::ComputePipeline,
    kernel_aniso: wgpu::ComputePipeline,
    reduce: wgpu::ComputePipeline,
    rescale: wgpu::ComputePipeline,
    /// Workgroup sizes, read from the shaders (written once, there).
    kernel_wg: u32,
    rescale_wg: u32,
}

/// The problem's nodes in the GPU layout.
fn gpu_nodes(p: &Problem) -> Vec<GpuNode> {
    (0..p.dirs.len())
        .map(|j| GpuNode {
            x: p.dirs[j][0] as f32,
            y: p.dirs[j][1] as f32,
            z: p.dirs[j][2] as f32,
            row_scale: p.row[j] as f32,
            col_weight: p.col[j] as f32,
            norm_weight: p.norm[j] as f32,
            ..Default::default()
        })
        .collect()
}

impl PowerIteration {
    /// Builds the pipelines on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        let k = "fit/kernel.wgsl";
        let (r, n) = ("fit/normalise_reduce.wgsl", "fit/normalise_rescale.wgsl");
        Ok(PowerIteration {
            kernel_iso: shader::compute_pipeline(device, k, "kernel", &[("ISOTROPIC", 1.0)])?,
            kernel_aniso: shader::compute_pipeline(device, k, "kernel", &[("ISOTROPIC", 0.0)])?,
            reduce: shader::compute_pipeline(device, r, "reduce", &[])?,
            rescale: shader::compute_pipeline(device, n, "rescale", &[])?,
            kernel_wg: shader::workgroup_size(k, "kernel")?,
            rescale_wg: shader::workgroup_size(n, "rescale")?,
        })
    }

    fn kernel(&self, isotropic: bool) -> &wgpu::ComputePipeline {
        if isotropic {
            &self.kernel_iso
        } else {
            &self.kernel_aniso
        }
    }

    fn kernel_bind_group(
        &self,
        gpu: &Gpu,
        isotropic: bool,
        nodes: &wgpu::Buffer,
        queries: &wgpu::Buffer,
        v: &wgpu::Buffer,
        y: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        let layout = self.kernel(isotropic).get_bind_group_layout(0);
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("kernel"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: nodes.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: queries.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: v.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: y.as_entire_binding(),
                },
            ],
        })
    }

    fn run(&self, gpu: &Gpu, p: &Problem, stopping: Stopping) -> Result<Eigen, GpuError> {
        let n = p.dirs.len();
        let nodes = gpu_nodes(p);
        buffer::check_binding(
            &gpu.device,
            "the quadrature nodes",
            (n * size_of::<GpuNode>()) as u64,
        )?;
        let (max_it, tol) = match stopping {
            Stopping::Converge {
                tolerance,
                max_iterations,
            } => (max_iterations, tolerance.max(F32_RESIDUAL_FLOOR)),
            Stopping::Fixed(k) => (k, -1.0),
        };
        let d = &gpu.device;
        let (nodes_buf, v_buf, y_buf, state_buf, stats_buf) = gpu.scoped(|| {
            let sum: f64 = p.norm.iter().sum();
            (
                buffer::storage(d, "nodes", &nodes),
                buffer::storage(d, "v", &vec![(1.0 / sum) as f32; n]),
                buffer::storage_zeroed(d, "y", (n * 4) as u64),
                buffer::storage(d, "state", &[GpuState::default()]),
                buffer::storage_zeroed(d, "stats", (max_it.max(1) * 8) as u64),
            )
        })?;
        let kernel_bg =
            self.kernel_bind_group(gpu, p.isotropic, &nodes_buf, &nodes_buf, &v_buf, &y_buf);
        // Layouts are derived from each entry point, which binds only what it uses:
        // reduce all five, rescale v, y and the state.
        let all = [&nodes_buf, &v_buf, &y_buf, &state_buf, &stats_buf];
        let bind = |pipeline: &wgpu::ComputePipeline, bindings: &[u32]| {
            let entries: Vec<wgpu::BindGroupEntry> = bindings
                .iter()
                .map(|&b| wgpu::BindGroupEntry {
                    binding: b,
                    resource: all[b as usize].as_entire_binding(),
                })
                .collect();
            d.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("normalise"),
                layout: &pipeline.get_bind_group_layout(0),
                entries: &entries,
            })
        };
        let reduce_bg = bind(&self.reduce, &[0, 1, 2, 3, 4]);
        let rescale_bg = bind(&self.rescale, &[1, 2, 3]);
        let (kx, ky) = dispatch::workgroups(n as u32, self.kernel_wg);
        let (rx, ry) = dispatch::workgroups(n as u32, self.rescale_wg);
        let (mut done, mut last, mut best) = (0usize, (0.0f32, f32::INFINITY), f32::INFINITY);
        while done < max_it {
            let batch = BATCH.min(max_it - done);
            let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("power iteration"),
            });
            for _ in 0..batch {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("iteration"),
                    timestamp_writes: None,
                });
                pass.set_pipeline(self.kernel(p.isotropic));
                pass.set_bind_group(0, &kernel_bg, &[]);
                pass.dispatch_workgroups(kx, ky, 1);
                pass.set_pipeline(&self.reduce);
                pass.set_bind_group(0, &reduce_bg, &[]);
                pass.dispatch_workgroups(1, 1, 1);
                pass.set_pipeline(&self.rescale);
                pass.set_bind_group(0, &rescale_bg, &[]);
                pass.dispatch_workgroups(rx, ry, 1);
            }
            gpu.queue.submit([enc.finish()]);
            let stats: Vec<[f32; 2]> = buffer::read(d, &gpu.queue, &stats_buf, done + batch)?;
            gpu.check_lost()?;
            let batch_stats = &stats[done..done + batch];
            let converged = batch_stats.iter().position(|s| (s[1] as f64) < tol);
            let used = converged.map_or(batch, |k| k + 1);
            last = (stats[done + used - 1][0], stats[done + used - 1][1]);
            done += batch;
            // Converged, or stalled at f32 precision: a whole batch without halving the residual.
            let batch_best = batch_stats
                .iter()
                .map(|s| s[1])
                .fold(f32::INFINITY, f32::min);
            let stalled = tol > 0.0 && batch_best > 0.5 * best && (batch_best as f64) < 1e-4;
            best = best.min(batch_best);
            if converged.is_some() || stalled {
                // The batch may run past convergence: those iterations only refine v further.
                break;
            }
        }
        let v: Vec<f32> = buffer::read(d, &gpu.queue, &v_buf, n)?;
        Ok(Eigen {
            v: v.into_iter().map(f64::from).collect(),
            lambda: last.0 as f64,
            iterations: done,
            residual: last.1 as f64,
        })
    }

    fn integrals(
        &self,
        gpu: &Gpu,
        p: &Problem,
        v: &[f64],
        queries: &[[f64; 3]],
    ) -> Result<Vec<f64>, GpuError> {
        let d = &gpu.device;
        let to_node = |q: &[f64; 3], j: Option<usize>| GpuNode {
            x: q[0] as f32,
            y: q[1] as f32,
            z: q[2] as f32,
            row_scale: 1.0,
            col_weight: j.map_or(0.0, |j| p.col[j] as f32),
            ..Default::default()
        };
        let nodes: Vec<GpuNode> = p
            .dirs
            .iter()
            .enumerate()
            .map(|(j, q)| to_node(q, Some(j)))
            .collect();
        let qs: Vec<GpuNode> = queries.iter().map(|q| to_node(q, None)).collect();
        let vf: Vec<f32> = v.iter().map(|&x| x as f32).collect();
        let (nb, qb, vb, yb) = gpu.scoped(|| {
            (
                buffer::storage(d, "nodes", &nodes),
                buffer::storage(d, "queries", &qs),
                buffer::storage(d, "v", &vf),
                buffer::storage_zeroed(d, "integrals", (qs.len() * 4) as u64),
            )
        })?;
        let bg = self.kernel_bind_group(gpu, p.isotropic, &nb, &qb, &vb, &yb);
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("integrals"),
        });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("integrals"),
                timestamp_writes: None,
            });
            pass.set_pipeline(self.kernel(p.isotropic));
            pass.set_bind_group(0, &bg, &[]);
            let (x, y) = dispatch::workgroups(qs.len() as u32, self.kernel_wg);
            pass.dispatch_workgroups(x, y, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let out: Vec<f32> = buffer::read(d, &gpu.queue, &yb, qs.len())?;
        Ok(out.into_iter().map(f64::from).collect())
    }
}

impl PowerIteration {
    /// Milliseconds of one kernel–vector product (GPU timestamps, median of `reps` passes);
    /// `None` when the adapter has no timestamp queries.
    pub fn time_kernel(&self, gpu: &Gpu, p: &Problem, reps: u32) -> Result<Option<f64>, GpuError> {
        let d = &gpu.device;
        let Some(mut timer) = facet_gpu::timer::GpuTimer::new(d, &gpu.queue, reps) else {
            return Ok(None);
        };
        let n = p.dirs.len();
        let nodes = gpu_nodes(p);
        let (nb, vb, yb) = gpu.scoped(|| {
            (
                buffer::storage(d, "nodes", &nodes),
                buffer::storage(d, "v", &vec![1.0f32; n]),
                buffer::storage_zeroed(d, "y", (n * 4) as u64),
            )
        })?;
        let bg = self.kernel_bind_group(gpu, p.isotropic, &nb, &nb, &vb, &yb);
        let (x, y) = dispatch::workgroups(n as u32, self.kernel_wg);
        let mut enc = d.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("time kernel"),
        });
        for _ in 0..reps {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("kernel"),
                timestamp_writes: timer.pass(),
            });
            pass.set_pipeline(self.kernel(p.isotropic));
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(x, y, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let mut ms = timer.read_ms(d, &gpu.queue)?;
        ms.sort_by(f64::total_cmp);
        Ok(ms.get(ms.len() / 2).copied())
    }
}

impl Solver for GpuFitter<'_> {
    fn iterate(&self, p: &Problem, stopping: Stopping) -> Result<Eigen, FitError> {
        self.power
            .run(self.gpu, p, stopping)
            .map_err(|e| gpu_error("power iteration", e))
    }

    fn integrals(
        &self,
        p: &Problem,
        v: &[f64],
        queries: &[[f64; 3]],
    ) -> Result<Vec<f64>, FitError> {
        self.power
            .integrals(self.gpu, p, v, queries)
            .map_err(|e| gpu_error("NDF and G1 tables", e))
    }

    fn name(&self) -> String {
        self.gpu.describe()
    }
}
