//! Twin tests of the raster kernels on the GPU (Mesa lavapipe in CI) against their Rust twins,
//! value by value: `blit.wgsl` and the shadow-depth pass (`shadow_depth.wgsl`). Tolerances are
//! stated next to each assertion with the error measured on lavapipe.

use crate::common;
use crate::twins;

use common::gpu;
use glam::Vec3;
use rand_core::RngCore;
use relume::gpu::compute;
use relume::gpu::mesh_renderer::LightsUniform;
use relume::render::lights::{shadow_depth, shadow_projections, GpuLight};
use relume::scene::LightKind;
use twins::*;

// ---------------------------------------------------------------------------------------------
// 1. blit.wgsl

#[test]
fn blit_matches_its_cpu_twin_for_every_size_and_format() {
    let Some(gpu) = gpu() else { return };
    let (sw, sh) = (37u32, 23u32);
    let mut r = rng(11);
    let source = image::RgbaImage::from_fn(sw, sh, |_, _| {
        let v = r.next_u32().to_le_bytes();
        image::Rgba(v)
    });
    let src_tex = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("blit source"),
        size: wgpu::Extent3d {
            width: sw,
            height: sh,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    gpu.queue.write_texture(
        src_tex.as_image_copy(),
        source.as_raw(),
        wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(4 * sw),
            rows_per_image: Some(sh),
        },
        src_tex.size(),
    );
    let src_view = src_tex.create_view(&Default::default());
    use wgpu::TextureFormat as F;
    // Same size, larger than the source (edge texels repeat), smaller (top-left crop); the
    // formats a window surface offers without sRGB encoding.
    let cases = [
        (F::Rgba8Unorm, sw, sh),
        (F::Rgba8Unorm, 50, 31),
        (F::Bgra8Unorm, sw, sh),
        (F::Bgra8Unorm, 20, 9),
        (F::Rgba16Float, sw, sh),
        (F::Rgba16Float, 41, 30),
    ];
    let mut max_f16_ulps = 0i32;
    for (format, w, h) in cases {
        let blit = relume::gpu::blit::Blit::new(&gpu, format).unwrap();
        let target = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("blit target"),
            size: wgpu::Extent3d {
                width: w,
                height: h,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        blit.draw(&gpu, &src_view, &target.create_view(&Default::default()));
        let want = relume::gpu::blit::blit_reference(&source, w, h);
        let bpp = if format == F::Rgba16Float { 8 } else { 4 };
        let got = read_texture(&gpu, &target, bpp, 0, wgpu::TextureAspect::All);
        for (i, px) in want.pixels().enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            match format {
                F::Rgba8Unorm | F::Bgra8Unorm => {
                    let mut g = [got[4 * i], got[4 * i + 1], got[4 * i + 2], got[4 * i + 3]];
                    if format == F::Bgra8Unorm {
                        g.swap(0, 2);
                    }
                    // 8-bit in, 8-bit out: exact.
                    assert_eq!(g, px.0, "{format:?} {w}x{h} texel ({x}, {y})");
                }
                _ => {
                    for c in 0..4 {
                        let g =
                            half::f16::from_le_bytes([got[8 * i + 2 * c], got[8 * i + 2 * c + 1]]);
                        let want = half::f16::from_f32(px[c] as f32 / 255.0);
                        let ulps = (g.to_bits() as i32 - want.to_bits() as i32).abs();
                        max_f16_ulps = max_f16_ulps.max(ulps);
                        // Unorm → f32 → f16: Vulkan lets the conversion round either way, so
                        // one f16 ulp (measured on lavapipe: 1 ulp; tolerance = measured).
                        assert!(
                            ulps <= 1,
                            "{format:?} {w}x{h} texel ({x}, {y}) ch {c}: gpu {g} cpu {want}"
                        );
                    }
                }
            }
        }
    }
    eprintln!("blit: 8-bit targets exact; Rgba16Float max error {max_f16_ulps} f16 ulp");
}

// ---------------------------------------------------------------------------------------------
// 2. shadow_depth.wgsl

#[test]
fn shadow_depth_pass_matches_the_cpu_rasteriser() {
    let Some(gpu) = gpu() else { return };
    let size = 256u32;
    let tris: Vec<[Vec3; 3]> = vec![
        // A wide slanted triangle, a smaller one nearer the lights overlapping it, a steep one
        // through neither, and a sliver.
        [
            Vec3::new(-0.5, 0.1, -0.5),
            Vec3::new(0.5, 0.3, -0.4),
            Vec3::new(0.0, 0.2, 0.5),
        ],
        [
            Vec3::new(-0.3, 0.6, -0.2),
            Vec3::new(0.3, 0.6, -0.1),
            Vec3::new(0.0, 0.7, 0.3),
        ],
        [
            Vec3::new(0.25, 0.0, 0.25),
            Vec3::new(0.45, 0.5, 0.2),
            Vec3::new(0.3, 0.05, 0.45),
        ],
        [
            Vec3::new(-0.45, 0.4, 0.3),
            Vec3::new(-0.1, 0.45, 0.45),
            Vec3::new(-0.4, 0.42, 0.33),
        ],
    ];
    let (centre, radius) = (Vec3::new(0.0, 0.35, 0.0), 0.9);
    let dir = GpuLight::from_light(
        &light(
            LightKind::Directional,
            Vec3::ZERO,
            Vec3::new(0.3, -1.0, 0.2),
            Vec3::ONE,
            1.0,
        ),
        1.0,
        0,
    );
    let spot = GpuLight::from_light(
        &light(
            LightKind::Spot {
                inner_cone: 0.3,
                outer_cone: 0.7,
            },
            Vec3::new(-0.3, 1.6, 0.2),
            Vec3::new(0.3, -1.3, -0.2),
            Vec3::ONE,
            1.0,
        ),
        1.0,
        0,
    );
    let point = GpuLight::from_light(
        &light(
            LightKind::Point,
            Vec3::new(0.05, 1.4, -0.03),
            Vec3::NEG_Y,
            Vec3::ONE,
            1.0,
        ),
        1.0,
        0,
    );
    // Layers: the directional light's, the spot's, and the point light's −y face (every corner
    // of every triangle is in front of these three, so neither side needs clipping).
    let matrices = [
        shadow_projections(&dir, centre, radius)[0],
        shadow_projections(&spot, centre, radius)[0],
        shadow_projections(&point, centre, radius)[3],
    ];
    let mut u: LightsUniform = bytemuck::Zeroable::zeroed();
    for (i, m) in matrices.iter().enumerate() {
        u.layer_view_proj[i] = m.to_cols_array();
    }
    let lights = compute::uniform(&gpu, "lights", &u);
    let dev = &gpu.device;
    let lights_layout = dev.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
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
    let group = dev.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &lights_layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: lights.as_entire_binding(),
        }],
    });
    let module = gpu.shader("shadow_depth.wgsl").unwrap();
    let layout = dev.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[None, Some(&lights_layout)],
        immediate_size: 0,
    });
    let attrs = [wgpu::VertexAttribute {
        format: wgpu::VertexFormat::Float32x3,
        offset: 0,
        shader_location: 0,
    }];
    // The player's shadow pipeline adds a depth bias (pipeline state, not the kernel); here it
    // is off so that the stored depth is the kernel's z / w itself.
    let pipeline = dev.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("shadow depth test"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attrs,
            })],
        },
        primitive: wgpu::PrimitiveState {
            cull_mode: None,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: wgpu::TextureFormat::Depth32Float,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Less),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: None,
        multiview_mask: None,
        cache: None,
    });
    let positions: Vec<f32> = tris
        .iter()
        .flat_map(|t| t.iter().flat_map(|p| p.to_array()))
        .collect();
    let vertices = {
        use wgpu::util::DeviceExt;
        dev.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("triangles"),
            contents: bytemuck::cast_slice(&positions),
            usage: wgpu::BufferUsages::VERTEX,
        })
    };
    let layers = matrices.len() as u32;
    let depth = dev.create_texture(&wgpu::TextureDescriptor {
        label: Some("shadow layers"),
        size: wgpu::Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: layers,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Depth32Float,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let mut enc = dev.create_command_encoder(&Default::default());
    for layer in 0..layers {
        let view = depth.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer,
            array_layer_count: Some(1),
            ..Default::default()
        });
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("shadow"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(1, &group, &[]);
        pass.set_vertex_buffer(0, vertices.slice(..));
        pass.draw(0..3 * tris.len() as u32, layer..layer + 1);
    }
    gpu.queue.submit([enc.finish()]);
    // Texels whose centre is within half a texel of a projected edge are left out: there the
    // rasteriser's fill rule and its sub-texel vertex snapping decide coverage.
    const EDGE_MARGIN: f32 = 0.5;
    let mut max_err = 0.0f32;
    for (layer, m) in matrices.iter().enumerate() {
        let got: Vec<f32> = bytemuck::cast_slice(&read_texture(
            &gpu,
            &depth,
            4,
            layer as u32,
            wgpu::TextureAspect::DepthOnly,
        ))
        .to_vec();
        let want = shadow_depth(&tris, *m, size);
        let (mut compared, mut covered, mut excluded) = (0, 0, 0);
        let mut layer_err = 0.0f32;
        for (i, (g, w)) in got.iter().zip(&want).enumerate() {
            if w.edge_distance < EDGE_MARGIN {
                excluded += 1;
                continue;
            }
            compared += 1;
            covered += (w.depth < 1.0) as usize;
            let e = (g - w.depth).abs();
            layer_err = layer_err.max(e);
            // Window-space interpolation of z / w in f32 on both sides; the measured maximum
            // on lavapipe is 2.4e-7 (two ulp near 1): 2x margin.
            assert!(
                e <= 4.8e-7,
                "layer {layer} texel ({}, {}): gpu {g} cpu {}",
                i as u32 % size,
                i as u32 / size,
                w.depth
            );
        }
        eprintln!(
            "shadow depth layer {layer}: {compared} texels compared ({covered} covered), {excluded} near edges left out, max |error| {layer_err:.3e}"
        );
        assert!(
            covered > 2000,
            "layer {layer}: only {covered} covered texels"
        );
        assert!(
            excluded < compared / 10,
            "layer {layer}: {excluded} excluded"
        );
        max_err = max_err.max(layer_err);
    }
    eprintln!("shadow depth: max |gpu − cpu| {max_err:.3e}");
}

// ---------------------------------------------------------------------------------------------
