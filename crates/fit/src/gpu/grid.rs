//! The isotropic MERL grid on the GPU (`shaders/fit/grid.inc.wgsl`) as the CPU passes hold it
//! (`merl_geometry.rs`, `iso/`): its geometry uploaded once per fitter, a source's
//! ln(1 + x) and validity flags once per source, read in place by the passes over the grid.

use crate::metric::grid::GridSamples;
use crate::metric::iso::PADDED;
use crate::metric::iso_tables::IsoTables;
use crate::metric::merl_geometry::{ROW, ROWS, merl_geometry};
use crate::model::merl_grid::THETA_D_RES;
use facet_gpu::{Gpu, GpuError, buffer, dispatch};

/// The overrides of `grid.inc.wgsl`, for the pipelines that include it.
pub(super) fn grid_constants() -> [(&'static str, f64); 3] {
    [
        ("ROW", ROW as f64),
        ("PADDED", PADDED as f64),
        ("THETA_D", THETA_D_RES as f64),
    ]
}

/// The grid's geometry on the GPU: each row's cosines and its bins' λ(φ) (12 MB).
pub struct GpuGrid {
    mu: wgpu::Buffer,
    corr: wgpu::Buffer,
}

impl GpuGrid {
    /// Uploads the geometry (built on first use in the process).
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let g = merl_geometry();
        buffer::check_binding(
            &gpu.device,
            "the MERL grid's cosines",
            (g.mu.len() * 4) as u64,
        )?;
        gpu.scoped(|| GpuGrid {
            mu: buffer::storage(&gpu.device, "grid cosines", &g.mu),
            corr: buffer::storage(&gpu.device, "grid correlations", &g.corr),
        })
    }
}

/// A source's samples on the GPU, beside the grid's geometry.
pub struct GpuSamples {
    pub(super) mu: wgpu::Buffer,
    pub(super) corr: wgpu::Buffer,
    /// ln(1 + x/ε) of every row and channel, as the CPU stores it.
    pub(super) log_x: wgpu::Buffer,
    /// 1/ε of the metric ([`crate::metric::Metric`]): a model's F and ρd/π are multiplied by
    /// it before a pass forms ln(1 + x_model/ε).
    pub(super) scale: f32,
    /// One bit a bin, ceil(PADDED / 32) words a row.
    pub(super) valid: wgpu::Buffer,
    /// Valid samples: the metric's divisor over three channels.
    pub(super) count: usize,
}

impl GpuSamples {
    /// Uploads an isotropic source's samples (the whole grid; the GPU passes cover isotropic
    /// sources only).
    pub fn upload(gpu: &Gpu, grid: &GpuGrid, set: &GridSamples) -> Result<Self, GpuError> {
        let iso = set
            .iso
            .as_ref()
            .expect("the GPU grid passes take isotropic sample sets");
        let (log_x, flags) = iso.whole_grid().expect("the whole grid's samples");
        debug_assert_eq!(log_x.len(), 3 * ROWS * PADDED);
        let words = PADDED.div_ceil(32);
        let mut valid = vec![0u32; ROWS * words];
        for (r, row) in flags.chunks_exact(PADDED).enumerate() {
            for (k, _) in row.iter().enumerate().filter(|(_, v)| **v) {
                valid[r * words + k / 32] |= 1 << (k % 32);
            }
        }
        buffer::check_binding(
            &gpu.device,
            "the MERL grid samples",
            std::mem::size_of_val(log_x) as u64,
        )?;
        gpu.scoped(|| GpuSamples {
            mu: grid.mu.clone(),
            corr: grid.corr.clone(),
            log_x: buffer::storage(&gpu.device, "grid ln(1 + x)", log_x),
            valid: buffer::storage(&gpu.device, "grid validity", &valid),
            scale: set.scale(),
            count: iso.count,
        })
    }

    /// One pass over the grid: `pipeline` (`@workgroup_size` `wg`) a workgroup per θd bin, with
    /// the bindings of `grid.inc.wgsl` (the geometry, the flags, the model's D and Λ cos θ
    /// tables), then `extra`, then the bins' sums, which it returns.
    pub(super) fn bin_sums(
        &self,
        gpu: &Gpu,
        (pipeline, label, wg): (&wgpu::ComputePipeline, &str, u32),
        model: &IsoTables,
        extra: &[wgpu::BindingResource],
    ) -> Result<Vec<f32>, GpuError> {
        let d = &gpu.device;
        let (ndf, lambda_cos, sums) = gpu.scoped(|| {
            (
                buffer::storage(d, "ndf per theta_h bin", model.d_table()),
                buffer::storage(d, "lambda cos", model.lambda_cos_table()),
                buffer::storage_zeroed(d, "sums per theta_d bin", (THETA_D_RES * 4) as u64),
            )
        })?;
        let mut resources = vec![
            self.mu.as_entire_binding(),
            self.corr.as_entire_binding(),
            self.valid.as_entire_binding(),
            ndf.as_entire_binding(),
            lambda_cos.as_entire_binding(),
        ];
        resources.extend_from_slice(extra);
        resources.push(sums.as_entire_binding());
        dispatch::run(
            d,
            &gpu.queue,
            pipeline,
            label,
            &resources,
            THETA_D_RES as u32 * wg,
            wg,
        );
        buffer::read(d, &gpu.queue, &sums, THETA_D_RES)
    }
}
