//! Host driver of `shaders/fit/error.wgsl`: the error metric of a model over a source's grid
//! samples uploaded once ([`GpuSamples`]), one dispatch (a workgroup per θd bin) per model.

use super::GpuSamples;
use super::grid::grid_constants;
use crate::metric::iso_tables::IsoTables;
use facet_gpu::{Gpu, GpuError, buffer, shader};

/// The error metric over the MERL grid on the GPU (`shaders/fit/error.wgsl`).
pub struct ErrorMetric {
    pipeline: wgpu::ComputePipeline,
    /// `@workgroup_size` of the shader, read by naga (written once, there).
    workgroup_size: u32,
}

impl ErrorMetric {
    /// Builds the pipeline on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        Ok(ErrorMetric {
            pipeline: shader::compute_pipeline(
                device,
                "fit/error.wgsl",
                "error_sums",
                &grid_constants(),
            )?,
            workgroup_size: shader::workgroup_size("fit/error.wgsl", "error_sums")?,
        })
    }

    /// The mean of |ln(1 + x_model/ε) − ln(1 + x_data/ε)| over the samples and the three channels
    /// of a model given as tables (D, Λ cos θ, F per θd bin, ρd/π): the bins' sums on the GPU
    /// (f32), added on the CPU (f64).
    pub fn mean(
        &self,
        gpu: &Gpu,
        samples: &GpuSamples,
        model: &IsoTables,
    ) -> Result<f64, GpuError> {
        // F per θd bin, then ρd/π, over ε: the pass forms ln(1 + x_model/ε).
        let s = samples.scale as f64;
        let fresnel: Vec<[f32; 4]> = (model.fresnel.iter())
            .chain([&model.diffuse])
            .map(|f| [(f[0] * s) as f32, (f[1] * s) as f32, (f[2] * s) as f32, 0.0])
            .collect();
        let fresnel =
            gpu.scoped(|| buffer::storage(&gpu.device, "fresnel and diffuse", &fresnel))?;
        let pass = (&self.pipeline, "error", self.workgroup_size);
        let extra = [
            samples.log_x.as_entire_binding(),
            fresnel.as_entire_binding(),
        ];
        let raw = samples.bin_sums(gpu, pass, model, &extra)?;
        let total: f64 = raw.iter().map(|&s| s as f64).sum();
        Ok(total / (3 * samples.count.max(1)) as f64)
    }
}
