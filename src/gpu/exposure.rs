//! Automatic exposure on the GPU: the log-luminance histogram of the frame in the display target
//! (`shaders/exposure_histogram.wgsl`), read back (512 bytes) for [`crate::render::exposure`] to
//! turn into the next exposure. The CPU twin is `render::exposure::histogram`.

use super::compute::{self, bind, pipeline};
use super::readback::read_buffer;
use super::Gpu;
use crate::error::Result;
use crate::render::exposure::{display_lut, BINS};

/// The histogram kernel and its buffers, built once per player.
pub struct ExposureMeter {
    pipeline: wgpu::ComputePipeline,
    lut: wgpu::Buffer,
    histogram: wgpu::Buffer,
}

impl ExposureMeter {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        Ok(ExposureMeter {
            pipeline: pipeline(gpu, "exposure_histogram.wgsl", "main")?,
            lut: compute::storage(gpu, "exposure lut", &display_lut()),
            histogram: compute::output(gpu, "exposure histogram", 4 * BINS as u64),
        })
    }

    /// The histogram of the `width`×`height` frame in `view` (an `Rgba8Unorm` target drawn with
    /// the display transform).
    pub fn histogram(
        &self,
        gpu: &Gpu,
        view: &wgpu::TextureView,
        width: u32,
        height: u32,
    ) -> Result<[u32; BINS]> {
        let group = bind(
            gpu,
            &self.pipeline,
            &[
                wgpu::BindingResource::TextureView(view),
                self.lut.as_entire_binding(),
                self.histogram.as_entire_binding(),
            ],
        );
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.histogram, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("exposure histogram"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(width.div_ceil(16), height.div_ceil(16), 1);
        }
        gpu.queue.submit([enc.finish()]);
        let bytes = read_buffer(gpu, &self.histogram)?;
        let counts: &[u32] = bytemuck::cast_slice(&bytes[..4 * BINS]);
        let mut h = [0u32; BINS];
        h.copy_from_slice(counts);
        Ok(h)
    }
}
