//! Copying GPU buffers and textures back to the CPU.

use super::Gpu;
use crate::error::{Error, Result};

/// Read a whole buffer (created with `COPY_SRC`) back as bytes.
pub fn read_buffer(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<u8>> {
    let size = buffer.size();
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    gpu.queue.submit([enc.finish()]);
    map_and_copy(gpu, &staging)
}

/// Read a buffer of `f32` back.
pub fn read_f32(gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<Vec<f32>> {
    Ok(bytemuck::cast_slice(&read_buffer(gpu, buffer)?).to_vec())
}

/// Read a 2D texture with 4 bytes per texel (RGBA8 / R32F / ...) back, rows tightly packed.
pub fn read_texture_4bpp(gpu: &Gpu, texture: &wgpu::Texture) -> Result<Vec<u8>> {
    read_texture_layer(gpu, texture, 4, 0, wgpu::TextureAspect::All)
}

/// Read one array layer (one aspect) of a 2D texture with `bytes_per_texel` bytes per texel
/// back, rows tightly packed.
pub fn read_texture_layer(
    gpu: &Gpu,
    texture: &wgpu::Texture,
    bytes_per_texel: u32,
    layer: u32,
    aspect: wgpu::TextureAspect,
) -> Result<Vec<u8>> {
    let (w, h) = (texture.width(), texture.height());
    let row = w * bytes_per_texel;
    let padded =
        row.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("texture readback"),
        size: padded as u64 * h as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d {
                x: 0,
                y: 0,
                z: layer,
            },
            aspect,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &staging,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(h),
            },
        },
        wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        },
    );
    gpu.queue.submit([enc.finish()]);
    let bytes = map_and_copy(gpu, &staging)?;
    let mut out = Vec::with_capacity((row * h) as usize);
    for r in bytes.chunks_exact(padded as usize) {
        out.extend_from_slice(&r[..row as usize]);
    }
    Ok(out)
}

fn map_and_copy(gpu: &Gpu, staging: &wgpu::Buffer) -> Result<Vec<u8>> {
    let (tx, rx) = std::sync::mpsc::channel();
    staging.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    gpu.wait();
    rx.recv()
        .map_err(|_| Error::Gpu("buffer mapping was dropped".into()))?
        .map_err(|e| Error::Gpu(format!("cannot map a buffer for reading: {e}")))?;
    let view = staging
        .get_mapped_range(..)
        .map_err(|e| Error::Gpu(format!("cannot read a mapped buffer: {e:?}")))?;
    let bytes = view.to_vec();
    drop(view);
    staging.unmap();
    Ok(bytes)
}
