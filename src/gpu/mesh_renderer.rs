//! Rasterising a mesh scene: one shadow-map layer per directional/spot light (six per point
//! light; alpha-masked materials through `shadow_masked.wgsl`), then `mesh_shade.wgsl` (direct
//! per pixel + indirect per corner + emission, albedo textures, alpha test, tone map) into an
//! RGBA8 target, one indexed draw per material ([`super::mesh_materials`]). The CPU twins are
//! `relume::render::mesh_reference` and `relume::render::material_maps`.

use super::mesh_materials::GpuMaterials;
use super::render_target::{RenderTarget, DEPTH_FORMAT, TARGET_FORMAT};
use super::timing::PassTimer;
use super::Gpu;
use crate::error::{Error, Result};
use crate::render::camera::Camera;
use crate::render::lights::{shadow_projections, GpuLight, MAX_LIGHTS, MAX_SHADOW_LAYERS};
use crate::render::material_maps::SceneMaps;
use crate::render::mesh_reference::{corner_uvs, corner_vertices, FrameSettings};
use crate::scene::Scene;
use wgpu::util::DeviceExt;

/// The lights uniform of `lighting.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LightsUniform {
    pub count: u32,
    pub shadow_bias: f32,
    pub pad: [u32; 2],
    pub lights: [GpuLight; MAX_LIGHTS],
    pub layer_view_proj: [[f32; 16]; MAX_SHADOW_LAYERS],
}

/// The `Frame` uniform of `mesh_shade.wgsl` (public for the layout test in tests/gpu/layout.rs).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniform {
    pub view_proj: [f32; 16],
    pub eye: [f32; 4],
    pub exposure: f32,
    pub emission_scale: f32,
    pub flags: u32,
    pub pad: u32,
}

/// GPU state for drawing one mesh scene.
pub struct MeshRenderer {
    shade: wgpu::RenderPipeline,
    shadow: wgpu::RenderPipeline,
    shadow_masked: wgpu::RenderPipeline,
    vertices: wgpu::Buffer,
    positions: wgpu::Buffer,
    uvs: wgpu::Buffer,
    /// Textures, per-material bind groups and the corners in material order.
    pub materials: GpuMaterials,
    /// Per-corner indirect exitance (3 × f32 per corner), written by the gather or by `set_indirect`.
    pub indirect: wgpu::Buffer,
    corners: u32,
    lights: wgpu::Buffer,
    lights_cpu: LightsUniform,
    shadow_layers: Vec<wgpu::TextureView>,
    frame: wgpu::Buffer,
    group0: wgpu::BindGroup,
    /// Group 1 (lights + shadow maps), shared with the direct-light kernel.
    pub group1: wgpu::BindGroup,
    /// Group 1 for the shadow passes: the lights uniform only (the maps are being written).
    shadow_group1: wgpu::BindGroup,
    pub group1_layout: wgpu::BindGroupLayout,
    pub target: RenderTarget,
    bounds: (glam::Vec3, f32),
}

impl MeshRenderer {
    /// Upload `scene` and create a `width`×`height` target with `shadow_size`² shadow maps.
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        width: u32,
        height: u32,
        shadow_size: u32,
    ) -> Result<Self> {
        let dev = &gpu.device;
        let max = gpu.info.max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::knob(format!(
                "image size {width}x{height} is outside 1..={max} (the adapter's limit)"
            )));
        }
        let verts = corner_vertices(scene);
        let corners = (verts.len() / 12) as u32;
        let positions: Vec<f32> = verts
            .chunks_exact(12)
            .flat_map(|v| [v[0], v[1], v[2]])
            .collect();
        let vertices = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mesh vertices"),
            contents: bytemuck::cast_slice(&verts),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let positions = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mesh positions"),
            contents: bytemuck::cast_slice(&positions),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let uvs = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("mesh texture coordinates"),
            contents: bytemuck::cast_slice(&corner_uvs(scene)),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let materials = GpuMaterials::new(gpu, scene, &SceneMaps::new(scene, max));
        let indirect = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("indirect per corner"),
            size: (corners as u64 * 12).max(16),
            usage: wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let lights_cpu = LightsUniform {
            count: 0,
            shadow_bias: 0.0,
            pad: [0; 2],
            lights: [GpuLight::default(); MAX_LIGHTS],
            layer_view_proj: [[0.0; 16]; MAX_SHADOW_LAYERS],
        };
        let lights = dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("lights"),
            contents: bytemuck::bytes_of(&lights_cpu),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        let shadow_tex = dev.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow maps"),
            size: wgpu::Extent3d {
                width: shadow_size,
                height: shadow_size,
                depth_or_array_layers: MAX_SHADOW_LAYERS as u32,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let shadow_array = shadow_tex.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let shadow_layers = (0..MAX_SHADOW_LAYERS as u32)
            .map(|l| {
                shadow_tex.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: l,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        let sampler = dev.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow compare"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let group1_layout = lighting_layout(gpu);
        let group1 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lighting"),
            layout: &group1_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: lights.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&shadow_array),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::Sampler(&sampler),
                },
            ],
        });
        let frame = dev.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame"),
            size: std::mem::size_of::<FrameUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let group0_layout = dev.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("frame"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let group0 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("frame"),
            layout: &group0_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: frame.as_entire_binding(),
            }],
        });
        let lights_only_layout = dev.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lights only"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let shadow_group1 = dev.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lights only"),
            layout: &lights_only_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: lights.as_entire_binding(),
            }],
        });
        let layouts = [
            &group0_layout,
            &group1_layout,
            &lights_only_layout,
            &materials.layout,
        ];
        let (shade, shadow, shadow_masked) = pipelines(gpu, layouts)?;
        let (lo, hi) = scene.bounds();
        Ok(MeshRenderer {
            shade,
            shadow,
            shadow_masked,
            vertices,
            positions,
            uvs,
            materials,
            indirect,
            corners,
            lights,
            lights_cpu,
            shadow_layers,
            frame,
            group0,
            group1,
            shadow_group1,
            group1_layout,
            target: RenderTarget::new(gpu, width, height),
            bounds: ((lo + hi) * 0.5, ((hi - lo) * 0.5).length()),
        })
    }

    /// Number of triangle corners (3 per scene triangle).
    pub fn corners(&self) -> u32 {
        self.corners
    }

    /// Set the frame's punctual lights (at most [`MAX_LIGHTS`], at most [`MAX_SHADOW_LAYERS`]
    /// shadow layers) and compute their shadow projections.
    pub fn set_lights(&mut self, gpu: &Gpu, lights: &[GpuLight]) -> Result<()> {
        if lights.len() > MAX_LIGHTS {
            return Err(Error::knob(format!(
                "{} lights given, at most {MAX_LIGHTS} are supported",
                lights.len()
            )));
        }
        let mut layer = 0u32;
        let mut u = self.lights_cpu;
        u.count = lights.len() as u32;
        for (i, l) in lights.iter().enumerate() {
            let mut l = *l;
            l.params[1] = layer;
            for m in shadow_projections(&l, self.bounds.0, self.bounds.1) {
                if layer as usize >= MAX_SHADOW_LAYERS {
                    return Err(Error::knob(format!("the lights need more than {MAX_SHADOW_LAYERS} shadow layers (a point light takes 6)")));
                }
                u.layer_view_proj[layer as usize] = m.to_cols_array();
                layer += 1;
            }
            u.lights[i] = l;
        }
        // Normal offset of about two shadow-map texels of the scene's extent.
        u.shadow_bias = self.bounds.1 * 2.0 / 1024.0;
        self.lights_cpu = u;
        gpu.queue
            .write_buffer(&self.lights, 0, bytemuck::bytes_of(&u));
        Ok(())
    }

    /// The lights uniform as last set.
    pub fn lights_uniform(&self) -> &LightsUniform {
        &self.lights_cpu
    }

    /// Upload per-corner indirect exitance (3 floats per corner).
    pub fn set_indirect(&self, gpu: &Gpu, per_corner: &[f32]) {
        gpu.queue
            .write_buffer(&self.indirect, 0, bytemuck::cast_slice(per_corner));
    }

    /// Record the shadow passes of the current lights.
    pub fn record_shadows(&self, enc: &mut wgpu::CommandEncoder, timer: &mut PassTimer) {
        let layers: u32 = self.lights_cpu.lights[..self.lights_cpu.count as usize]
            .iter()
            .map(|l| l.layers())
            .sum();
        for layer in 0..layers {
            let ts = timer.render("shadow maps");
            let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &self.shadow_layers[layer as usize],
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: ts,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let m = &self.materials;
            pass.set_index_buffer(m.index.slice(..), wgpu::IndexFormat::Uint32);
            pass.set_pipeline(&self.shadow);
            pass.set_bind_group(1, &self.shadow_group1, &[]);
            pass.set_vertex_buffer(0, self.positions.slice(..));
            pass.draw_indexed(0..m.opaque_corners, 0, layer..layer + 1);
            pass.set_pipeline(&self.shadow_masked);
            pass.set_vertex_buffer(1, self.uvs.slice(..));
            for d in m.draws.iter().filter(|d| d.masked) {
                pass.set_bind_group(2, &m.groups[d.material], &[]);
                pass.draw_indexed(d.first..d.first + d.count, 0, layer..layer + 1);
            }
        }
    }

    /// Record the shading pass for `camera` into the target.
    pub fn record_shade(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        camera: &Camera,
        s: &FrameSettings,
        timer: &mut PassTimer,
    ) {
        let f = FrameUniform {
            view_proj: camera
                .view_projection(self.target.width, self.target.height)
                .to_cols_array(),
            eye: camera.eye.extend(1.0).to_array(),
            exposure: s.exposure,
            emission_scale: s.emission_scale,
            flags: s.flags(),
            pad: 0,
        };
        gpu.queue
            .write_buffer(&self.frame, 0, bytemuck::bytes_of(&f));
        let mut pass = self.target.begin_pass(enc, "shade", s.background, timer);
        pass.set_pipeline(&self.shade);
        pass.set_bind_group(0, &self.group0, &[]);
        pass.set_bind_group(1, &self.group1, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_vertex_buffer(1, self.indirect.slice(..));
        pass.set_vertex_buffer(2, self.uvs.slice(..));
        let m = &self.materials;
        pass.set_index_buffer(m.index.slice(..), wgpu::IndexFormat::Uint32);
        for d in &m.draws {
            pass.set_bind_group(2, &m.groups[d.material], &[]);
            pass.draw_indexed(d.first..d.first + d.count, 0, 0..1);
        }
    }

    /// Resize the render target.
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) {
        self.target = RenderTarget::new(gpu, width, height);
    }
}

/// The bind-group layout of `lighting.wgsl` (group 1).
pub fn lighting_layout(gpu: &Gpu) -> wgpu::BindGroupLayout {
    let all = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
    gpu.device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lighting"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: all,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: all,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: all,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                    count: None,
                },
            ],
        })
}

/// The shading, shadow and masked-shadow pipelines; `layouts`: frame, lighting, lights only,
/// material.
fn pipelines(
    gpu: &Gpu,
    layouts: [&wgpu::BindGroupLayout; 4],
) -> Result<(
    wgpu::RenderPipeline,
    wgpu::RenderPipeline,
    wgpu::RenderPipeline,
)> {
    let [g0, g1, lights_only, material] = layouts;
    let dev = &gpu.device;
    let shade_mod = gpu.shader("mesh_shade.wgsl")?;
    let shadow_mod = gpu.shader("shadow_depth.wgsl")?;
    let masked_mod = gpu.shader("shadow_masked.wgsl")?;
    let shade_layout = dev.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(g0), Some(g1), Some(material)],
        immediate_size: 0,
    });
    let masked_layout = dev.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[None, Some(lights_only), Some(material)],
        immediate_size: 0,
    });
    let shadow_layout = dev.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[None, Some(lights_only)],
        immediate_size: 0,
    });
    let f3 = |loc: u32, offset: u64| wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset,
        shader_location: loc,
    };
    let f2 = |loc: u32| wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x2,
        offset: 0,
        shader_location: loc,
    };
    let mesh_attrs = [f3(0, 0), f3(1, 12), f3(2, 24), f3(3, 36)];
    let indirect_attrs = [f3(4, 0)];
    let uv_attrs = [f2(5)];
    let depth = |bias: wgpu::DepthBiasState| wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias,
    };
    let shade = dev.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("mesh shade"),
        layout: Some(&shade_layout),
        vertex: wgpu::VertexState {
            module: &shade_mod,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[
                Some(wgpu::VertexBufferLayout {
                    array_stride: 48,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &mesh_attrs,
                }),
                Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &indirect_attrs,
                }),
                Some(wgpu::VertexBufferLayout {
                    array_stride: 8,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &uv_attrs,
                }),
            ],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(depth(Default::default())),
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &shade_mod,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(TARGET_FORMAT.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let pos_attrs = [f3(0, 0)];
    let shadow_uv_attrs = [f2(1)];
    let position_buffer = wgpu::VertexBufferLayout {
        array_stride: 12,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &pos_attrs,
    };
    let uv_buffer = wgpu::VertexBufferLayout {
        array_stride: 8,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &shadow_uv_attrs,
    };
    let shadow_pipeline = |label: &str,
                           layout: &wgpu::PipelineLayout,
                           module: &wgpu::ShaderModule,
                           buffers: &[Option<wgpu::VertexBufferLayout>],
                           fragment: bool| {
        dev.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers,
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(depth(wgpu::DepthBiasState {
                constant: 2,
                slope_scale: 2.0,
                clamp: 0.0,
            })),
            multisample: Default::default(),
            fragment: fragment.then(|| wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let shadow = shadow_pipeline(
        "shadow depth",
        &shadow_layout,
        &shadow_mod,
        &[Some(position_buffer.clone())],
        false,
    );
    let shadow_masked = shadow_pipeline(
        "shadow depth, alpha-masked",
        &masked_layout,
        &masked_mod,
        &[Some(position_buffer), Some(uv_buffer)],
        true,
    );
    Ok((shade, shadow, shadow_masked))
}
