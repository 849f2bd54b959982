//! GPU timestamps around compute passes, where the adapter supports them.

use crate::error::GpuError;

/// Up to `capacity` (begin, end) pairs of timestamps.
pub struct GpuTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    capacity: u32,
    used: u32,
    period_ns: f32,
}

impl GpuTimer {
    /// `None` when the device has no timestamp queries.
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, capacity: u32) -> Option<Self> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let set = device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("timer"),
            ty: wgpu::QueryType::Timestamp,
            count: 2 * capacity,
        });
        let resolve = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("timer resolve"),
            size: 16 * capacity as u64,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        Some(GpuTimer {
            set,
            resolve,
            capacity,
            used: 0,
            period_ns: queue.get_timestamp_period(),
        })
    }

    /// Timestamp writes for the next pass (none once the capacity is used up).
    pub fn pass(&mut self) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        if self.used >= self.capacity {
            return None;
        }
        let i = self.used;
        self.used += 1;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Forgets the passes timed so far: the next [`GpuTimer::pass`] takes the first pair again.
    pub fn reset(&mut self) {
        self.used = 0;
    }

    /// Milliseconds of each timed pass.
    pub fn read_ms(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<f64>, GpuError> {
        if self.used == 0 {
            return Ok(Vec::new());
        }
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("timer"),
        });
        encoder.resolve_query_set(&self.set, 0..2 * self.used, &self.resolve, 0);
        queue.submit([encoder.finish()]);
        let ticks: Vec<u64> =
            crate::buffer::read(device, queue, &self.resolve, 2 * self.used as usize)?;
        Ok(ticks
            .chunks(2)
            .map(|t| t[1].saturating_sub(t[0]) as f64 * self.period_ns as f64 * 1e-6)
            .collect())
    }
}
