//! Host driver of `shaders/fit/fresnel.wgsl`: over a source's grid samples uploaded once
//! ([`GpuSamples`]), one dispatch (a workgroup per θd bin) per model.

use super::GpuSamples;
use super::grid::grid_constants;
use crate::metric::grid::GridSamples;
use crate::metric::iso_tables::{IsoTables, fresnel_from_sums};
use crate::model::rgb::Rgb;
use facet_gpu::{Gpu, GpuError, shader};

/// The Fresnel average over the MERL grid on the GPU (`shaders/fit/fresnel.wgsl`).
pub struct FresnelAverage {
    pipeline: wgpu::ComputePipeline,
    /// `@workgroup_size` of the shader, read by naga (written once, there).
    workgroup_size: u32,
}

impl FresnelAverage {
    /// Builds the pipeline on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        Ok(FresnelAverage {
            pipeline: shader::compute_pipeline(
                device,
                "fit/fresnel.wgsl",
                "fresnel_sums",
                &grid_constants(),
            )?,
            workgroup_size: shader::workgroup_size("fit/fresnel.wgsl", "fresnel_sums")?,
        })
    }

    /// F per θd bin and channel for a model given as tables: Σ x_data / Σ x_ideal, the
    /// denominators summed on the GPU, the numerators (per-row sums of the source, kept by the
    /// set) on the CPU. `samples` is `set` uploaded.
    pub fn average(
        &self,
        gpu: &Gpu,
        samples: &GpuSamples,
        set: &GridSamples,
        model: &IsoTables,
    ) -> Result<Vec<Rgb>, GpuError> {
        let pass = (&self.pipeline, "fresnel", self.workgroup_size);
        let raw = samples.bin_sums(gpu, pass, model, &[])?;
        let iso = set.iso.as_ref().expect("an uploaded set is isotropic");
        let acc: Vec<([f64; 3], f64)> = iso
            .fresnel_numerators(model)
            .into_iter()
            .zip(raw.iter().map(|&s| s as f64))
            .collect();
        Ok(fresnel_from_sums(&acc))
    }
}
