//! A mesh scene's materials on the GPU: every albedo and mask chain of
//! [`SceneMaps`](crate::render::material_maps::SceneMaps) uploaded with all its levels, one
//! bind group per material (`shaders/material.wgsl`, group 2), and an index buffer that orders
//! the triangle corners by material so that each material is one indexed draw.
//!
//! Corners keep their place in the vertex buffers (the per-corner indirect light is written by
//! the gather in corner order); only the index buffer is sorted. Opaque materials come first, so
//! the shadow pass draws all of them in one call with the plain depth pipeline and only the
//! alpha-masked ones with the pipeline that reads the mask. Materials cut away everywhere are
//! left out.

use super::Gpu;
use crate::render::material_maps::{Encoding, Lookup, MipChain, SceneMaps};
use crate::scene::texture::Wrap;
use crate::scene::Scene;
use wgpu::util::DeviceExt;

/// The `Material` uniform of `material.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialUniform {
    pub albedo_u: [f32; 4],
    pub albedo_v: [f32; 4],
    pub mask_u: [f32; 4],
    pub mask_v: [f32; 4],
    /// RGB albedo factor; alpha cutoff.
    pub factor: [f32; 4],
    /// `[0]`: bit 0 albedo texture, bit 1 alpha mask.
    pub flags: [u32; 4],
}

/// One material's corners in the index buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Draw {
    pub material: usize,
    pub first: u32,
    pub count: u32,
    pub masked: bool,
}

/// Materials uploaded for drawing.
pub struct GpuMaterials {
    pub layout: wgpu::BindGroupLayout,
    /// Per scene material.
    pub groups: Vec<wgpu::BindGroup>,
    /// Sorted corner indices (u32).
    pub index: wgpu::Buffer,
    /// In index-buffer order: opaque materials, then masked ones.
    pub draws: Vec<Draw>,
    /// Number of leading indices that belong to opaque materials.
    pub opaque_corners: u32,
    /// Bytes of texture memory uploaded (all levels).
    pub texture_bytes: u64,
}

impl GpuMaterials {
    /// Upload `maps` (built from `scene`) and order `scene`'s corners by material.
    pub fn new(gpu: &Gpu, scene: &Scene, maps: &SceneMaps) -> Self {
        let dev = &gpu.device;
        let layout = material_layout(gpu);
        let mut texture_bytes = 0u64;
        let mut upload = |chain: &MipChain, label: &str| {
            texture_bytes += chain
                .levels
                .iter()
                .map(|l| l.texels.len() as u64)
                .sum::<u64>();
            upload_chain(gpu, chain, label)
        };
        let albedo: Vec<wgpu::TextureView> = maps
            .albedo
            .iter()
            .map(|c| upload(c, "albedo map"))
            .collect();
        let masks: Vec<wgpu::TextureView> =
            maps.masks.iter().map(|c| upload(c, "alpha mask")).collect();
        let white = upload(&one_texel(Encoding::SrgbAlpha), "white");
        let opaque = upload(&one_texel(Encoding::Linear8), "opaque");
        let mut samplers: Vec<([Wrap; 2], wgpu::Sampler)> = Vec::new();
        let mut sampler = |wrap: [Wrap; 2]| -> wgpu::Sampler {
            if let Some((_, s)) = samplers.iter().find(|(w, _)| *w == wrap) {
                return s.clone();
            }
            let s = dev.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("material"),
                address_mode_u: address(wrap[0]),
                address_mode_v: address(wrap[1]),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                anisotropy_clamp: anisotropy(gpu),
                ..Default::default()
            });
            samplers.push((wrap, s.clone()));
            s
        };
        let identity = Lookup {
            transform: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            wrap: [Wrap::Repeat; 2],
        };
        let groups = maps
            .materials
            .iter()
            .map(|m| {
                let (a_view, a_look) = match &m.albedo {
                    Some((i, l)) => (&albedo[*i], l),
                    None => (&white, &identity),
                };
                let (m_view, m_look, cutoff) = match &m.mask {
                    Some((i, l, c)) => (&masks[*i], l, *c),
                    None => (&opaque, &identity, 0.0),
                };
                let row = |l: &Lookup, r: usize| {
                    let t = l.transform[r];
                    [t[0], t[1], t[2], 0.0]
                };
                let u = MaterialUniform {
                    albedo_u: row(a_look, 0),
                    albedo_v: row(a_look, 1),
                    mask_u: row(m_look, 0),
                    mask_v: row(m_look, 1),
                    factor: [m.factor.x, m.factor.y, m.factor.z, cutoff],
                    flags: [
                        m.albedo.is_some() as u32 | (m.mask.is_some() as u32) << 1,
                        0,
                        0,
                        0,
                    ],
                };
                let buffer = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("material"),
                    contents: bytemuck::bytes_of(&u),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let (sa, sm) = (sampler(a_look.wrap), sampler(m_look.wrap));
                dev.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("material"),
                    layout: &layout,
                    entries: &[
                        wgpu::BindGroupEntry {
                            binding: 0,
                            resource: buffer.as_entire_binding(),
                        },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(a_view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::Sampler(&sa),
                        },
                        wgpu::BindGroupEntry {
                            binding: 3,
                            resource: wgpu::BindingResource::TextureView(m_view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 4,
                            resource: wgpu::BindingResource::Sampler(&sm),
                        },
                    ],
                })
            })
            .collect();
        let (indices, draws) = corner_order(scene, maps);
        let opaque_corners = draws.iter().filter(|d| !d.masked).map(|d| d.count).sum();
        let index = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("corners by material"),
            contents: bytemuck::cast_slice(if indices.is_empty() {
                &[0u32]
            } else {
                &indices
            }),
            usage: wgpu::BufferUsages::INDEX,
        });
        GpuMaterials {
            layout,
            groups,
            index,
            draws,
            opaque_corners,
            texture_bytes,
        }
    }
}

/// Corner indices sorted by material (opaque materials first, then masked ones, each by
/// material index; hidden materials left out) and the draw of each material.
pub fn corner_order(scene: &Scene, maps: &SceneMaps) -> (Vec<u32>, Vec<Draw>) {
    let mut by_material: Vec<Vec<u32>> = vec![Vec::new(); maps.materials.len()];
    for (t, &m) in scene.triangle_material.iter().enumerate() {
        let c = 3 * t as u32;
        by_material[m as usize].extend([c, c + 1, c + 2]);
    }
    let mut order: Vec<usize> = (0..maps.materials.len())
        .filter(|&m| !maps.materials[m].hidden && !by_material[m].is_empty())
        .collect();
    order.sort_by_key(|&m| (maps.materials[m].mask.is_some(), m));
    let mut indices = Vec::with_capacity(3 * scene.triangles.len());
    let mut draws = Vec::with_capacity(order.len());
    for m in order {
        draws.push(Draw {
            material: m,
            first: indices.len() as u32,
            count: by_material[m].len() as u32,
            masked: maps.materials[m].mask.is_some(),
        });
        indices.extend_from_slice(&by_material[m]);
    }
    (indices, draws)
}

/// The sampler's anisotropy: 16 on hardware; 1 (trilinear) on a software rasteriser, whose
/// anisotropic filter is slow and, on Mesa 22.3's lavapipe, departs from the isotropic result by
/// up to 102/255 even on magnified texels (measured with `tests/gpu/textures.rs`), where no
/// anisotropic filter should change anything.
pub fn anisotropy(gpu: &Gpu) -> u16 {
    if gpu.info.device_type == format!("{:?}", wgpu::DeviceType::Cpu) {
        1
    } else {
        16
    }
}

fn address(w: Wrap) -> wgpu::AddressMode {
    match w {
        Wrap::Repeat => wgpu::AddressMode::Repeat,
        Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
        Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
    }
}

fn one_texel(encoding: Encoding) -> MipChain {
    let texels = match encoding {
        Encoding::SrgbAlpha => vec![255; 4],
        Encoding::Linear8 => vec![255],
    };
    MipChain {
        encoding,
        levels: vec![crate::render::material_maps::Level {
            width: 1,
            height: 1,
            texels,
        }],
    }
}

/// Upload every level of `chain` into one texture.
fn upload_chain(gpu: &Gpu, chain: &MipChain, label: &str) -> wgpu::TextureView {
    let format = match chain.encoding {
        Encoding::SrgbAlpha => wgpu::TextureFormat::Rgba8UnormSrgb,
        Encoding::Linear8 => wgpu::TextureFormat::R8Unorm,
    };
    let base = &chain.levels[0];
    let tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: base.width,
            height: base.height,
            depth_or_array_layers: 1,
        },
        mip_level_count: chain.levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let bpp = chain.channels() as u32;
    for (l, level) in chain.levels.iter().enumerate() {
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &tex,
                mip_level: l as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &level.texels,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(bpp * level.width),
                rows_per_image: Some(level.height),
            },
            wgpu::Extent3d {
                width: level.width,
                height: level.height,
                depth_or_array_layers: 1,
            },
        );
    }
    tex.create_view(&Default::default())
}

/// The bind-group layout of `material.wgsl` (group 2).
pub fn material_layout(gpu: &Gpu) -> wgpu::BindGroupLayout {
    let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
    let texture = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vf,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    };
    let sampler = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vf,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    };
    gpu.device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("material"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: vf,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                texture(1),
                sampler(2),
                texture(3),
                sampler(4),
            ],
        })
}
