//! The colour + depth target every frame renders into (mesh and terrain alike): created at a
//! size, cleared to the background by [`RenderTarget::begin_pass`], read back as an image for
//! headless frames and tests, or blitted to a window surface.

use super::timing::PassTimer;
use super::Gpu;
use crate::error::{Error, Result};

/// Colour format of the render target (tone mapping and sRGB encoding happen in the shader).
pub const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth format of the render target and the shadow maps.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A `width`×`height` RGBA8 colour texture with its depth buffer.
pub struct RenderTarget {
    texture: wgpu::Texture,
    /// The colour view (for presenting in a window).
    pub view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    pub width: u32,
    pub height: u32,
}

impl RenderTarget {
    /// A target of at least 1×1 pixels.
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Self {
        Self::with_usage(gpu, width, height, wgpu::TextureUsages::empty())
    }

    /// A target compute kernels can also write (`texture_storage_2d<rgba8unorm, write>`).
    pub fn new_storage(gpu: &Gpu, width: u32, height: u32) -> Self {
        Self::with_usage(gpu, width, height, wgpu::TextureUsages::STORAGE_BINDING)
    }

    fn with_usage(gpu: &Gpu, width: u32, height: u32, extra: wgpu::TextureUsages) -> Self {
        let (width, height) = (width.max(1), height.max(1));
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, usage| {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour = texture(
            "target",
            TARGET_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::COPY_SRC
                | wgpu::TextureUsages::TEXTURE_BINDING
                | extra,
        );
        let depth = texture(
            "depth",
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        RenderTarget {
            view: colour.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            texture: colour,
            width,
            height,
        }
    }

    /// Begin a render pass named `label` (its timestamps under that name) that clears colour
    /// to `background` and depth to 1.
    pub fn begin_pass<'e>(
        &self,
        enc: &'e mut wgpu::CommandEncoder,
        label: &'static str,
        background: [f32; 3],
        timer: &mut PassTimer,
    ) -> wgpu::RenderPass<'e> {
        let [r, g, b] = background.map(f64::from);
        enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some(label),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: timer.render(label),
            occlusion_query_set: None,
            multiview_mask: None,
        })
    }

    /// The rendered image as tightly packed RGBA8 rows.
    pub fn read_image(&self, gpu: &Gpu) -> Result<image::RgbaImage> {
        let px = super::readback::read_texture_4bpp(gpu, &self.texture)?;
        image::RgbaImage::from_raw(self.width, self.height, px)
            .ok_or_else(|| Error::Internal("readback size".into()))
    }
}
