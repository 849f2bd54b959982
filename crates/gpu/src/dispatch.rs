//! One compute pass over a 1-D range of invocations, the pattern every driver repeats.

/// (x, y) workgroup counts covering `threads` invocations within the 65,535-per-dimension
/// limit; shaders index with `gid.x + gid.y * num_workgroups.x * WG`.
pub fn workgroups(threads: u32, workgroup_size: u32) -> (u32, u32) {
    let groups = threads.div_ceil(workgroup_size).max(1);
    let x = groups.min(65_535);
    (x, groups.div_ceil(x))
}

/// Binds `resources` at bindings 0, 1, 2, … of group 0 (the pipeline's own layout) and runs
/// `pipeline` over `threads` invocations in one submission.
pub fn run(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipeline: &wgpu::ComputePipeline,
    label: &str,
    resources: &[wgpu::BindingResource],
    threads: u32,
    workgroup_size: u32,
) {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: r.clone(),
        })
        .collect();
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(label),
            timestamp_writes: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        let (x, y) = workgroups(threads, workgroup_size);
        pass.dispatch_workgroups(x, y, 1);
    }
    queue.submit([encoder.finish()]);
}
