//! Host driver of `shaders/fit/fresnel.wgsl`: the source's grid samples uploaded once, then one
//! dispatch (a workgroup per θd bin) per model.

use super::GpuSample;
use crate::brdf::Rgb;
use crate::grid::{GridSamples, IsoTables, fresnel_from_sums, sample_geometry};
use crate::merl::THETA_D_RES;
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
        let mut order: Vec<usize> = (0..set.len()).collect();
        order.sort_by_key(|&k| set.samples[k].j);
        let samples: Vec<GpuSample> = order
            .iter()
            .map(|&k| {
                let s = &set.samples[k];
                let [gi, go, inv_cos_i, inv_cos_o, corr] = sample_geometry(s);
                GpuSample {
                    x: s.x,
                    i: s.i as u32,
                    gi,
                    go,
                    inv_cos_i,
                    inv_cos_o,
                    corr,
                    pad: [0.0; 3],
                }
            })
            .collect();
        let mut offsets = vec![0u32; THETA_D_RES + 1];
        for s in &set.samples {
            offsets[s.j as usize + 1] += 1;
        }
        for j in 0..THETA_D_RES {
            offsets[j + 1] += offsets[j];
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

    /// F per θd bin and channel for a model given as tables: Σ x_data / Σ x_ideal.
    pub fn average(
        &self,
        gpu: &Gpu,
        samples: &GpuSamples,
        model: &IsoTables,
    ) -> Result<Vec<Rgb>, GpuError> {
        let d = &gpu.device;
        let f32s = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
        let (ndf, lambda_cos, sums) = gpu.scoped(|| {
            (
                buffer::storage(d, "ndf per theta_h bin", &f32s(model.d_table())),
                buffer::storage(d, "lambda cos", &f32s(model.lambda_cos_table())),
                buffer::storage_zeroed(d, "fresnel sums", (THETA_D_RES * 16) as u64),
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
        let raw: Vec<[f32; 4]> = buffer::read(d, &gpu.queue, &sums, THETA_D_RES)?;
        let acc: Vec<([f64; 3], f64)> = raw
            .iter()
            .map(|s| ([s[0] as f64, s[1] as f64, s[2] as f64], s[3] as f64))
            .collect();
        Ok(fresnel_from_sums(&acc))
    }
}
