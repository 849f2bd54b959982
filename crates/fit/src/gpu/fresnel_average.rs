//! Host driver of `shaders/fit/fresnel.wgsl`: the source's grid samples uploaded once, then one
//! dispatch (a workgroup per θd bin) per model.

use super::GpuSample;
use crate::brdf::Rgb;
use crate::grid::{GridSamples, IsoTables, LAMBDA_TABLE, fresnel_from_sums};
use crate::merl::THETA_D_RES;
use crate::merl_geometry::{ROW, merl_geometry};
use facet_gpu::{Gpu, GpuError, buffer, dispatch, shader};

/// The Fresnel average over the MERL grid on the GPU (`shaders/fit/fresnel.wgsl`).
pub struct FresnelAverage {
    pipeline: wgpu::ComputePipeline,
    /// `@workgroup_size` of the shader, read by naga (written once, there).
    workgroup_size: u32,
}

/// A source's samples on the GPU, sorted by θd bin.
pub struct GpuSamples {
    samples: wgpu::Buffer,
    offsets: wgpu::Buffer,
}

impl FresnelAverage {
    /// Builds the pipeline on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Self, GpuError> {
        Ok(FresnelAverage {
            pipeline: shader::compute_pipeline(device, "fit/fresnel.wgsl", "fresnel_sums", &[])?,
            workgroup_size: shader::workgroup_size("fit/fresnel.wgsl", "fresnel_sums")?,
        })
    }

    /// Uploads an isotropic sample set (the GPU path covers isotropic sources only).
    pub fn upload(&self, gpu: &Gpu, set: &GridSamples) -> Result<GpuSamples, GpuError> {
        let iso = set
            .iso
            .as_ref()
            .expect("the GPU Fresnel average takes isotropic sample sets");
        let geo = merl_geometry();
        let scale = (LAMBDA_TABLE - 1) as f32;
        let mut samples = Vec::with_capacity(iso.count);
        let mut offsets = vec![0u32; THETA_D_RES + 1];
        // Sorted by θd bin: a workgroup per bin.
        for j in 0..THETA_D_RES {
            for &r in iso.rows.iter().filter(|&&r| r as usize % THETA_D_RES == j) {
                let r = r as usize;
                let (mu, corr) = (geo.mu_row(r), geo.corr_row(r));
                for k in (0..ROW).filter(|&k| iso.valid(r * ROW + k)) {
                    let (mu_i, mu_o) = (mu[ROW - k], mu[k]);
                    samples.push(GpuSample {
                        i: (r / THETA_D_RES) as u32,
                        gi: mu_i * scale,
                        go: mu_o * scale,
                        inv_cos_i: 1.0 / mu_i,
                        inv_cos_o: 1.0 / mu_o,
                        corr: corr[k],
                        pad: [0.0; 2],
                    });
                }
            }
            offsets[j + 1] = samples.len() as u32;
        }
        buffer::check_binding(
            &gpu.device,
            "the MERL grid samples",
            (samples.len() * size_of::<GpuSample>()) as u64,
        )?;
        gpu.scoped(|| GpuSamples {
            samples: buffer::storage(&gpu.device, "grid samples", &samples),
            offsets: buffer::storage(&gpu.device, "theta_d offsets", &offsets),
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
        let d = &gpu.device;
        let (ndf, lambda_cos, sums) = gpu.scoped(|| {
            (
                buffer::storage(d, "ndf per theta_h bin", model.d_table()),
                buffer::storage(d, "lambda cos", model.lambda_cos_table()),
                buffer::storage_zeroed(d, "fresnel sums", (THETA_D_RES * 4) as u64),
            )
        })?;
        let resources = [
            samples.samples.as_entire_binding(),
            samples.offsets.as_entire_binding(),
            ndf.as_entire_binding(),
            lambda_cos.as_entire_binding(),
            sums.as_entire_binding(),
        ];
        // One workgroup per θd bin: the shader strides over the bin's samples.
        let wg = self.workgroup_size;
        dispatch::run(
            d,
            &gpu.queue,
            &self.pipeline,
            "fresnel",
            &resources,
            THETA_D_RES as u32 * wg,
            wg,
        );
        let raw: Vec<f32> = buffer::read(d, &gpu.queue, &sums, THETA_D_RES)?;
        let iso = set.iso.as_ref().expect("an uploaded set is isotropic");
        let acc: Vec<([f64; 3], f64)> = iso
            .fresnel_numerators(model)
            .into_iter()
            .zip(raw.iter().map(|&s| s as f64))
            .collect();
        Ok(fresnel_from_sums(&acc))
    }
}
