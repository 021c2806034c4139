//! Shading of a freeform cast on wgpu (`shaders/freeform_shade.wgsl`; CPU twin
//! `render::freeform_shade::shade32`): from the cast's hits and shadow state into an RGBA8
//! storage target.

use super::compute;
use super::freeform_caster::GpuCast;
use super::Gpu;
use crate::error::Result;
use crate::freeform::twin::View32;
use crate::render::freeform_shade::Shading;

/// The kernel's `ShadeFrame` uniform.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadeFrameU {
    pub forward: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub sun: [f32; 4],
    pub background: [f32; 4],
    pub size: [u32; 4],
}

pub struct FreeformShader {
    pipeline: wgpu::ComputePipeline,
}

impl FreeformShader {
    pub fn new(gpu: &Gpu) -> Result<FreeformShader> {
        Ok(FreeformShader {
            pipeline: compute::pipeline(gpu, "freeform_shade.wgsl", "shade")?,
        })
    }

    /// Shade `cast` (of `view`) into `target` (a storage-capable RGBA8 view of the view's size).
    pub fn shade(
        &self,
        gpu: &Gpu,
        cast: &GpuCast,
        view: &View32,
        s: &Shading,
        target: &wgpu::TextureView,
    ) {
        let u = ShadeFrameU {
            forward: [
                view.forward[0],
                view.forward[1],
                view.forward[2],
                view.tan_x,
            ],
            right: [view.right[0], view.right[1], view.right[2], view.tan_y],
            up: [view.up[0], view.up[1], view.up[2], s.exposure],
            sun: [s.sun[0], s.sun[1], s.sun[2], s.ambient],
            background: [s.background[0], s.background[1], s.background[2], 0.0],
            size: [view.width, view.height, u32::from(s.shadows), 0],
        };
        let ub = compute::uniform(gpu, "freeform shade", &u);
        let group = compute::bind(
            gpu,
            &self.pipeline,
            &[
                ub.as_entire_binding(),
                cast.leaves.as_entire_binding(),
                cast.hits.as_entire_binding(),
                cast.state.as_entire_binding(),
                wgpu::BindingResource::TextureView(target),
            ],
        );
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(view.width.div_ceil(8), view.height.div_ceil(8), 1);
        }
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
    }
}
