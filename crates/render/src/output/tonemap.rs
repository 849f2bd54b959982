//! The film tone mapped on the GPU (`shaders/render/tonemap.wgsl`), so that a preview reads
//! back 4 bytes a pixel instead of 16. The CPU twin is [`Image::tone_mapped`](crate::Image::tone_mapped).

use crate::error::RenderError;
use bytemuck::{Pod, Zeroable};
use facet_gpu::{Gpu, buffer, dispatch, shader};

/// WGSL `Params` of `render/tonemap.wgsl`.
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ToneMapParams {
    pub pixels: u32,
    /// 2^exposure.
    pub scale: f32,
    pub pad0: u32,
    pub pad1: u32,
}

/// The tone-mapping pass over one film: pipeline, parameters, output and bind group, reused.
pub struct ToneMap {
    pipeline: wgpu::ComputePipeline,
    params: wgpu::Buffer,
    out: wgpu::Buffer,
    group: wgpu::BindGroup,
    pixels: u32,
    wg: u32,
}

impl ToneMap {
    /// The tone-map pass over `film` (`width` × `height` pixels).
    pub fn new(
        gpu: &Gpu,
        film: &wgpu::Buffer,
        width: u32,
        height: u32,
    ) -> Result<Self, RenderError> {
        let d = &gpu.device;
        let pipeline = shader::compute_pipeline(d, "render/tonemap.wgsl", "tonemap", &[])?;
        let wg = shader::workgroup_size("render/tonemap.wgsl", "tonemap")?;
        let pixels = width * height;
        let (params, out) = gpu.scoped(|| {
            (
                buffer::uniform(d, "tone map params", &ToneMapParams::default()),
                buffer::storage_zeroed(d, "tone mapped", pixels as u64 * 4),
            )
        })?;
        let group = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tone map"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: params.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: film.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: out.as_entire_binding(),
                },
            ],
        });
        Ok(ToneMap {
            pipeline,
            params,
            out,
            group,
            pixels,
            wg,
        })
    }

    /// RGBA8 pixels (alpha 255) of the film at `exposure` stops.
    pub fn run(&self, gpu: &Gpu, exposure: f32) -> Result<Vec<[u8; 4]>, RenderError> {
        let p = ToneMapParams {
            pixels: self.pixels,
            scale: exposure.exp2(),
            ..Default::default()
        };
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&p));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            let (x, y) = dispatch::workgroups(self.pixels, self.wg);
            pass.dispatch_workgroups(x, y, 1);
        }
        gpu.queue.submit([enc.finish()]);
        let px: Vec<[u8; 4]> =
            buffer::read(&gpu.device, &gpu.queue, &self.out, self.pixels as usize)?;
        gpu.check_lost()?;
        Ok(px)
    }
}
