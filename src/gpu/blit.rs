//! Copy a rendered RGBA8 target onto a window surface of any colour format (`shaders/blit.wgsl`).

use super::Gpu;
use crate::error::Result;

/// The blit pipeline for one surface format.
pub struct Blit {
    pipeline: wgpu::RenderPipeline,
}

impl Blit {
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> Result<Blit> {
        let module = gpu.shader("blit.wgsl")?;
        let pipeline = gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("blit"),
                layout: None,
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            });
        Ok(Blit { pipeline })
    }

    /// Draw `source` onto `target` and submit.
    pub fn draw(&self, gpu: &Gpu, source: &wgpu::TextureView, target: &wgpu::TextureView) {
        let group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(source),
            }],
        });
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("blit"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.draw(0..3, 0..1);
        }
        gpu.queue.submit([enc.finish()]);
    }
}

/// CPU twin of `blit.wgsl`: texel (x, y) of a `width`×`height` target is the source texel at
/// (x, y) clamped to the source's last row and column (a plain copy when the sizes agree).
pub fn blit_reference(source: &image::RgbaImage, width: u32, height: u32) -> image::RgbaImage {
    let (sw, sh) = (source.width().max(1), source.height().max(1));
    image::RgbaImage::from_fn(width, height, |x, y| {
        *source.get_pixel(x.min(sw - 1), y.min(sh - 1))
    })
}
