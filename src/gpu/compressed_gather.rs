//! The gather B = S·E on the GPU straight from the compressed transport
//! (`shaders/gather_compressed.wgsl`): hardware BC sampling when the adapter has
//! `TEXTURE_COMPRESSION_BC` (BC1, BC6H), WGSL block decoders over a storage buffer otherwise
//! (BC1, BC4, F16, F32). Both paths are selectable and tested against `compress::gather`.
//! BC6H without hardware support is decoded once at load into F16 layers (lossless: BC6H
//! decodes to half floats).

use super::{compute, Gpu};
use crate::compress::{DenseEncoding, EncodedTransport};
use crate::error::{Error, Result};
use wgpu::util::DeviceExt;

/// How the dense part is decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum DecodePath {
    /// The texture unit decodes BC blocks (needs `TEXTURE_COMPRESSION_BC`; BC1 and BC6H).
    Hardware,
    /// WGSL decoders over a storage buffer (any adapter; BC1, BC4, F16, F32).
    Shader,
}

impl DecodePath {
    /// The best path for `encoding` on this adapter.
    pub fn best(gpu: &Gpu, encoding: DenseEncoding) -> DecodePath {
        let hw = matches!(encoding, DenseEncoding::Bc1Log | DenseEncoding::Bc6h);
        if hw && gpu.info.bc_textures {
            DecodePath::Hardware
        } else {
            DecodePath::Shader
        }
    }
}

/// The `GatherParams` uniform of `gather_compressed.wgsl` (public for the layout test in
/// tests/gpu/layout.rs).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Params {
    pub n: u32,
    pub padded: u32,
    pub channels: u32,
    pub encoding: u32,
    pub hardware: u32,
    pub layer_words: u32,
    pub log_range: f32,
    pub pad: u32,
    pub scale: [f32; 4],
    pub lut: [[f32; 4]; 192],
}

/// GPU state of the compressed gather.
pub struct CompressedGather {
    pipeline: wgpu::ComputePipeline,
    group: wgpu::BindGroup,
    block_rows: u32,
    /// The path in use.
    pub path: DecodePath,
    /// Bytes of the dense part on the GPU (texture or storage buffer).
    pub dense_bytes: u64,
}

impl CompressedGather {
    /// Upload `t` and bind it to `exitance` (E, vec4 per patch, original order) and `indirect`
    /// (B, vec4 per patch, written).
    pub fn new(
        gpu: &Gpu,
        t: &EncodedTransport,
        path: DecodePath,
        exitance: &wgpu::Buffer,
        indirect: &wgpu::Buffer,
    ) -> Result<Self> {
        let tex = &t.dense;
        let mut enc = tex.encoding;
        if path == DecodePath::Hardware && !gpu.info.bc_textures {
            return Err(Error::Gpu(
                "hardware BC decoding asked for, but the adapter lacks TEXTURE_COMPRESSION_BC"
                    .into(),
            ));
        }
        if path == DecodePath::Hardware
            && !matches!(enc, DenseEncoding::Bc1Log | DenseEncoding::Bc6h)
        {
            return Err(Error::knob(format!(
                "no hardware decode path for {} (use the shader path)",
                enc.name()
            )));
        }
        if path == DecodePath::Hardware && tex.padded as u32 > gpu.info.max_texture_dimension_2d {
            return Err(Error::limit(format!(
                "the transport texture is {0}x{0}, over the adapter's {1} limit; use the shader path",
                tex.padded, gpu.info.max_texture_dimension_2d
            )));
        }
        // Storage-buffer words of the dense part (empty for the hardware path).
        let (words, layer_words): (Vec<u32>, usize) = if path == DecodePath::Shader {
            let layers: Vec<Vec<u8>> = if enc == DenseEncoding::Bc6h {
                enc = DenseEncoding::F16;
                bc6h_to_f16_layers(t)
            } else {
                tex.layers.clone()
            };
            let layer_words = layers[0].len().div_ceil(4);
            let mut words = vec![0u32; layer_words * layers.len()];
            for (l, layer) in layers.iter().enumerate() {
                let dst: &mut [u8] =
                    bytemuck::cast_slice_mut(&mut words[l * layer_words..(l + 1) * layer_words]);
                dst[..layer.len()].copy_from_slice(layer);
            }
            (words, layer_words)
        } else {
            (Vec::new(), 0)
        };
        let dense_bytes = if path == DecodePath::Shader {
            words.len() as u64 * 4
        } else {
            tex.layers[0].len() as u64
        };
        if dense_bytes > gpu.info.max_storage_buffer_binding_size {
            return Err(Error::limit(format!(
                "the dense transport needs {} MiB, over the adapter's {} MiB storage binding limit",
                dense_bytes >> 20,
                gpu.info.max_storage_buffer_binding_size >> 20
            )));
        }
        let blocks = compute::storage(gpu, "transport blocks", &words);
        let texture = upload_texture(gpu, t, path)?;
        let view = texture.create_view(&Default::default());

        let mut p = Params {
            n: tex.n as u32,
            padded: tex.padded as u32,
            channels: tex.channels as u32,
            encoding: match enc {
                DenseEncoding::Bc1Log => 0,
                DenseEncoding::Bc4Log => 1,
                DenseEncoding::Bc6h => 2,
                DenseEncoding::F16 => 3,
                DenseEncoding::F32 => 4,
            },
            hardware: (path == DecodePath::Hardware) as u32,
            layer_words: layer_words as u32,
            log_range: tex.maps[0].range,
            pad: 0,
            scale: [0.0; 4],
            lut: [[0.0; 4]; 192],
        };
        for (c, m) in tex.maps.iter().enumerate() {
            p.scale[c] = m.scale;
            let lut = m.lut();
            for (q, v) in lut.iter().enumerate() {
                let k = 256 * c + q;
                p.lut[k / 4][k % 4] = *v;
            }
        }
        let params = compute::uniform(gpu, "gather params", &p);
        let perm = compute::storage(gpu, "permutation", &t.perm);
        let side = &t.sidecar;
        let rows = compute::storage(gpu, "sidecar rows", &side.row_ptr);
        let cols = compute::storage(gpu, "sidecar cols", &side.cols);
        let vals = compute::storage(gpu, "sidecar values", &side.values);
        let pipeline = compute::pipeline(gpu, "gather_compressed.wgsl", "main")?;
        let group = compute::bind(
            gpu,
            &pipeline,
            &[
                params.as_entire_binding(),
                blocks.as_entire_binding(),
                wgpu::BindingResource::TextureView(&view),
                perm.as_entire_binding(),
                exitance.as_entire_binding(),
                rows.as_entire_binding(),
                cols.as_entire_binding(),
                vals.as_entire_binding(),
                indirect.as_entire_binding(),
            ],
        );
        Ok(CompressedGather {
            pipeline,
            group,
            block_rows: (tex.padded / 4) as u32,
            path,
            dense_bytes,
        })
    }

    /// Record the gather pass.
    pub fn record(&self, enc: &mut wgpu::CommandEncoder, timer: &mut super::timing::PassTimer) {
        let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("gather"),
            timestamp_writes: timer.compute("gather"),
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.dispatch_workgroups(self.block_rows.max(1), 1, 1);
    }
}

/// The BC texture for the hardware path, or a 4x4 placeholder for the shader path.
fn upload_texture(gpu: &Gpu, t: &EncodedTransport, path: DecodePath) -> Result<wgpu::Texture> {
    let tex = &t.dense;
    let (format, size, data): (wgpu::TextureFormat, u32, &[u8]) = match (path, tex.encoding) {
        (DecodePath::Hardware, DenseEncoding::Bc1Log) => (
            wgpu::TextureFormat::Bc1RgbaUnorm,
            tex.padded as u32,
            &tex.layers[0],
        ),
        (DecodePath::Hardware, DenseEncoding::Bc6h) => (
            wgpu::TextureFormat::Bc6hRgbUfloat,
            tex.padded as u32,
            &tex.layers[0],
        ),
        _ => (wgpu::TextureFormat::Rgba8Unorm, 4, &[0u8; 64]),
    };
    let block_bytes = format.block_copy_size(None).unwrap_or(4);
    let (bw, bh) = format.block_dimensions();
    Ok(gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some("transport"),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        {
            debug_assert_eq!(data.len() as u32, (size / bw) * (size / bh) * block_bytes);
            data
        },
    ))
}

/// BC6H blocks decoded once into F16 texel layers (row-major, one layer per channel, values
/// relative to each channel's scale) for adapters without BC textures.
fn bc6h_to_f16_layers(t: &EncodedTransport) -> Vec<Vec<u8>> {
    let tex = &t.dense;
    let p = tex.padded;
    let bw = p / 4;
    let mut layers = vec![vec![0u8; p * p * 2]; tex.channels];
    let src = if tex.channels == 1 { 1 } else { 0 };
    for by in 0..bw {
        for bx in 0..bw {
            let k = (by * bw + bx) * 16;
            let texels = crate::compress::bc6h::bc6h_decode_block(&tex.layers[0][k..k + 16]);
            for (ti, texel) in texels.iter().enumerate() {
                let (x, y) = (4 * bx + ti % 4, 4 * by + ti / 4);
                for (c, layer) in layers.iter_mut().enumerate() {
                    let v = texel[if tex.channels == 1 { src } else { c }];
                    let h = half::f16::from_f32(v).to_le_bytes();
                    layer[2 * (y * p + x)..2 * (y * p + x) + 2].copy_from_slice(&h);
                }
            }
        }
    }
    layers
}
