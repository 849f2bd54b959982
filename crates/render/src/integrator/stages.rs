//! The integrator's stage pipelines (one WGSL file each under `shaders/render/`) and their
//! bind group layouts, built from the named lists of [`crate::layout::bindings`]. Group 0: frame, path
//! state, queues, film (`frame.inc.wgsl`); group 1: the scene (`scene.inc.wgsl`); group 2: one
//! glint material's field, parameters and DPF levels.

use crate::layout::bindings::{Group, pipeline_groups};
use crate::layout::queues::Queue;
use crate::materials::ShadeStage;
use facet_gpu::{GpuError, shader};

/// Threads per workgroup of every stage (WGSL override `WG`).
pub const STAGE_WORKGROUP: u32 = 64;

/// Bind group layouts shared by every stage, one per [`Group`].
pub struct Layouts {
    /// In the order of [`Group::ALL`].
    layouts: Vec<wgpu::BindGroupLayout>,
}

impl Layouts {
    pub fn new(device: &wgpu::Device) -> Self {
        Layouts {
            layouts: Group::ALL.iter().map(|g| g.layout(device)).collect(),
        }
    }

    /// The layout of `group`.
    pub fn of(&self, group: Group) -> &wgpu::BindGroupLayout {
        let i = Group::ALL.iter().position(|g| *g == group);
        &self.layouts[i.expect("every group has a layout")]
    }

    /// The layouts of pipeline file `file`'s groups, in group order.
    fn of_pipeline(&self, file: &str) -> Result<Vec<&wgpu::BindGroupLayout>, GpuError> {
        let groups = pipeline_groups(file).ok_or_else(|| {
            GpuError::Validation(format!(
                "{file} is not an integrator pipeline (facet_render::layout::bindings::PIPELINES)"
            ))
        })?;
        Ok(groups.iter().map(|g| self.of(*g)).collect())
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
    /// A stage of pipeline file `file` (one of `PIPELINES`).
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        file: &str,
        entry: &'static str,
        queue: Option<Queue>,
        extra_constants: &[(&str, f64)],
    ) -> Result<Stage, GpuError> {
        let groups = layouts.of_pipeline(file)?;
        Stage::with_groups(device, file, entry, &groups, queue, extra_constants)
    }

    /// The shading stage `spec` of a material class, consuming `queue`.
    pub fn shading(
        device: &wgpu::Device,
        layouts: &Layouts,
        spec: &ShadeStage,
        queue: Queue,
    ) -> Result<Stage, GpuError> {
        let groups: Vec<_> = spec.groups.iter().map(|g| layouts.of(*g)).collect();
        let mut constants = spec.constants.clone();
        constants.push(("Q_SHADE", queue.index() as f64));
        Stage::with_groups(
            device,
            spec.file,
            spec.entry,
            &groups,
            Some(queue),
            &constants,
        )
    }

    fn with_groups(
        device: &wgpu::Device,
        file: &str,
        entry: &'static str,
        groups: &[&wgpu::BindGroupLayout],
        queue: Option<Queue>,
        extra_constants: &[(&str, f64)],
    ) -> Result<Stage, GpuError> {
        let mut constants: Vec<(&str, f64)> = Queue::constants().to_vec();
        constants.push(("WG", STAGE_WORKGROUP as f64));
        constants.extend_from_slice(extra_constants);
        Ok(Stage {
            name: entry,
            pipeline: pipeline(device, file, entry, groups, &constants)?,
            queue,
        })
    }
}

/// `queue_args.wgsl` for queues [first, first + count), consumed by stages of `stage_wg`
/// threads a workgroup.
pub fn queue_args(
    device: &wgpu::Device,
    layouts: &Layouts,
    first: u32,
    count: u32,
    stage_wg: u32,
) -> Result<wgpu::ComputePipeline, GpuError> {
    let file = "render/queue_args.wgsl";
    pipeline(
        device,
        file,
        "queue_args",
        &layouts.of_pipeline(file)?,
        &[
            ("FIRST", first as f64),
            ("COUNT", count as f64),
            ("STAGE_WG", stage_wg as f64),
        ],
    )
}
