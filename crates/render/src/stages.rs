//! The integrator's stage pipelines (one WGSL file each under `shaders/render/`) and their
//! bind group layouts. Group 0: frame, path state, queues, film (`frame.inc.wgsl`); group 1: the
//! scene (`scene.inc.wgsl`); group 2: one glint material's field, parameters and DPF levels.

use crate::queues::Queue;
use facet_gpu::{GpuError, shader};

/// Bind group layouts shared by every stage.
pub struct Layouts {
    pub frame: wgpu::BindGroupLayout,
    pub scene: wgpu::BindGroupLayout,
    pub glint: wgpu::BindGroupLayout,
    pub queue_args: wgpu::BindGroupLayout,
}

fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn uniform(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn texture_3d(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D3,
            multisampled: false,
        },
        count: None,
    }
}

impl Layouts {
    pub fn new(device: &wgpu::Device) -> Self {
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        Layouts {
            frame: layout(
                "frame",
                &[
                    uniform(0),
                    storage(1, false),
                    storage(2, false),
                    storage(3, false),
                    storage(4, true),
                    storage(5, false),
                    storage(6, false),
                    storage(7, false),
                ],
            ),
            scene: layout(
                "scene",
                &(0..10).map(|b| storage(b, true)).collect::<Vec<_>>(),
            ),
            glint: layout(
                "glint",
                &[
                    uniform(0),
                    uniform(1),
                    texture_3d(2),
                    texture_3d(3),
                    storage(4, true),
                ],
            ),
            queue_args: layout(
                "queue args",
                &[storage(0, false), storage(1, false), storage(2, false)],
            ),
        }
    }
}

/// One stage: its pipeline and the queue it consumes (None: one thread per slot).
pub struct Stage {
    pub name: &'static str,
    pub pipeline: wgpu::ComputePipeline,
    pub queue: Option<Queue>,
}

fn pipeline(
    device: &wgpu::Device,
    file: &str,
    entry: &str,
    groups: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> Result<wgpu::ComputePipeline, GpuError> {
    let groups: Vec<Option<&wgpu::BindGroupLayout>> = groups.iter().map(|g| Some(*g)).collect();
    // An adapter below the stage's needs (a GL adapter allows fewer storage buffers per stage
    // than Vulkan) is an error that says so, not wgpu's panic.
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(entry),
        bind_group_layouts: &groups,
        immediate_size: 0,
    });
    let built = shader::compute_pipeline_with_layout(device, file, entry, Some(&layout), constants);
    if let Some(e) = pollster::block_on(scope.pop()) {
        return Err(GpuError::Validation(format!(
            "the adapter cannot build the render stage {entry}: {e}"
        )));
    }
    built
}

impl Stage {
    /// A stage of `shaders/render/{entry}.wgsl` (shading stages name their file).
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        file: &str,
        entry: &'static str,
        queue: Option<Queue>,
        extra_constants: &[(&str, f64)],
    ) -> Result<Stage, GpuError> {
        let mut constants: Vec<(&str, f64)> = Queue::constants().to_vec();
        constants.extend_from_slice(extra_constants);
        let glint = matches!(queue, Some(Queue::Glint(_)));
        let groups: Vec<&wgpu::BindGroupLayout> = if glint {
            vec![&layouts.frame, &layouts.scene, &layouts.glint]
        } else {
            vec![&layouts.frame, &layouts.scene]
        };
        Ok(Stage {
            name: entry,
            pipeline: pipeline(device, file, entry, &groups, &constants)?,
            queue,
        })
    }
}

/// `queue_args.wgsl` for queues [first, first + count).
pub fn queue_args(
    device: &wgpu::Device,
    layouts: &Layouts,
    first: u32,
    count: u32,
    stage_wg: u32,
) -> Result<wgpu::ComputePipeline, GpuError> {
    pipeline(
        device,
        "render/queue_args.wgsl",
        "queue_args",
        &[&layouts.queue_args],
        &[
            ("FIRST", first as f64),
            ("COUNT", count as f64),
            ("STAGE_WG", stage_wg as f64),
        ],
    )
}
