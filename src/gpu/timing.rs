//! Per-pass GPU times from timestamp queries, when the adapter has them.

use super::Gpu;
use crate::error::Result;

/// A set of timestamp pairs, one pair per named pass.
pub struct PassTimer {
    set: Option<wgpu::QuerySet>,
    resolve: Option<wgpu::Buffer>,
    names: Vec<&'static str>,
    capacity: u32,
}

impl PassTimer {
    /// Room for `passes` passes; a no-op timer when the adapter lacks timestamp queries.
    pub fn new(gpu: &Gpu, passes: u32) -> Self {
        if !gpu.info.timestamps {
            return PassTimer {
                set: None,
                resolve: None,
                names: Vec::new(),
                capacity: 0,
            };
        }
        let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("pass timer"),
            ty: wgpu::QueryType::Timestamp,
            count: passes * 2,
        });
        let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pass timer resolve"),
            size: passes as u64 * 16,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        PassTimer {
            set: Some(set),
            resolve: Some(resolve),
            names: Vec::new(),
            capacity: passes,
        }
    }

    /// Forget the passes of the previous frame.
    pub fn reset(&mut self) {
        self.names.clear();
    }

    /// Timestamp writes for a compute pass named `name` (None when timing is unavailable).
    pub fn compute(&mut self, name: &'static str) -> Option<wgpu::ComputePassTimestampWrites<'_>> {
        let i = self.slot(name)?;
        Some(wgpu::ComputePassTimestampWrites {
            query_set: self.set.as_ref()?,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    /// Timestamp writes for a render pass named `name`.
    pub fn render(&mut self, name: &'static str) -> Option<wgpu::RenderPassTimestampWrites<'_>> {
        let i = self.slot(name)?;
        Some(wgpu::RenderPassTimestampWrites {
            query_set: self.set.as_ref()?,
            beginning_of_pass_write_index: Some(2 * i),
            end_of_pass_write_index: Some(2 * i + 1),
        })
    }

    fn slot(&mut self, name: &'static str) -> Option<u32> {
        self.set.as_ref()?;
        if self.names.len() as u32 >= self.capacity {
            return None;
        }
        self.names.push(name);
        Some(self.names.len() as u32 - 1)
    }

    /// Resolve the queries into the readback buffer (record before `finish`).
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        if let (Some(set), Some(buf)) = (&self.set, &self.resolve) {
            if !self.names.is_empty() {
                enc.resolve_query_set(set, 0..self.names.len() as u32 * 2, buf, 0);
            }
        }
    }

    /// Milliseconds per pass name of the last submitted frame, summed over passes that share a
    /// name, in order of first appearance (empty when unavailable).
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<(&'static str, f64)>> {
        let Some(buf) = &self.resolve else {
            return Ok(Vec::new());
        };
        if self.names.is_empty() {
            return Ok(Vec::new());
        }
        let bytes = super::readback::read_buffer(gpu, buf)?;
        let ticks: &[u64] = bytemuck::cast_slice(&bytes);
        let period = gpu.queue.get_timestamp_period() as f64;
        Ok(self
            .names
            .iter()
            .enumerate()
            .map(|(i, n)| {
                (
                    *n,
                    ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * period / 1e6,
                )
            })
            .collect())
    }
}
