//! The kernels that lacked a twin test, each on the GPU (Mesa lavapipe in CI) against its Rust
//! twin value by value: the blit, the shadow-depth pass, `lighting.wgsl`'s functions (through a
//! compute harness that includes it), the direct-light kernel with punctual lights and shadow
//! maps, and the memory layout of every struct Rust and WGSL share (naga's layouter, no GPU).
//!
//! Tolerances are stated next to each assertion with the error measured on lavapipe.

mod common;

use common::gpu;
use glam::{DVec3, Mat4, Vec3, Vec4};
use rand_core::{RngCore, SeedableRng};
use relume::gpu::mesh_renderer::{LightsUniform, MeshRenderer};
use relume::gpu::radiosity_runtime::{RadiosityRuntime, TransportSource};
use relume::gpu::{compute, readback, shader_source, Gpu};
use relume::render::lights::{
    light_irradiance, point_face, shadow_depth, shadow_projections, GpuLight, KIND_DIRECTIONAL,
    KIND_POINT, KIND_SPOT, MAX_LIGHTS, MAX_SHADOW_LAYERS,
};
use relume::render::mesh_reference::FrameSettings;
use relume::scene::{Light, LightKind};

type Rng = rand_pcg::Pcg32;

fn rng(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// Uniform in [lo, hi).
fn uniform(r: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * ((r.next_u32() >> 8) as f32 / (1u32 << 24) as f32)
}

fn unit(r: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(
            uniform(r, -1.0, 1.0),
            uniform(r, -1.0, 1.0),
            uniform(r, -1.0, 1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn light(kind: LightKind, position: Vec3, direction: Vec3, color: Vec3, intensity: f32) -> Light {
    Light {
        name: "test".into(),
        kind,
        position: position.to_array(),
        direction: direction.normalize().to_array(),
        color: color.to_array(),
        intensity,
        range: None,
    }
}

/// A lights uniform holding `lights` with their shadow layers (as `MeshRenderer::set_lights`
/// lays them out) for a scene inside the sphere (`centre`, `radius`).
fn lights_uniform(lights: &[GpuLight], centre: Vec3, radius: f32) -> LightsUniform {
    let mut u = LightsUniform {
        count: lights.len() as u32,
        shadow_bias: 0.0,
        pad: [0; 2],
        lights: [GpuLight::default(); MAX_LIGHTS],
        layer_view_proj: [[0.0; 16]; MAX_SHADOW_LAYERS],
    };
    let mut layer = 0;
    for (i, l) in lights.iter().enumerate() {
        let mut l = *l;
        l.params[1] = layer as u32;
        for m in shadow_projections(&l, centre, radius) {
            u.layer_view_proj[layer] = m.to_cols_array();
            layer += 1;
        }
        u.lights[i] = l;
    }
    u
}

/// A compute module: `common.wgsl` + `lighting.wgsl` (composed as the runtime does) + `harness`.
fn lighting_harness(gpu: &Gpu, harness: &str) -> wgpu::ComputePipeline {
    let src = format!(
        "{}\n// ---- gpu_twins harness\n{harness}",
        shader_source("lighting.wgsl").unwrap()
    );
    let module = naga::front::wgsl::parse_str(&src)
        .unwrap_or_else(|e| panic!("harness: {}", e.emit_to_string(&src)));
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .unwrap_or_else(|e| panic!("harness: {e:?}"));
    let module = gpu
        .device
        .create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("lighting harness"),
            source: wgpu::ShaderSource::Wgsl(src.into()),
        });
    gpu.device
        .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("lighting harness"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        })
}

fn dispatch(gpu: &Gpu, p: &wgpu::ComputePipeline, groups: &[&wgpu::BindGroup], count: u32) {
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(p);
        for (i, g) in groups.iter().enumerate() {
            pass.set_bind_group(i as u32, *g, &[]);
        }
        pass.dispatch_workgroups(count.div_ceil(64), 1, 1);
    }
    gpu.queue.submit([enc.finish()]);
    gpu.wait();
}

// ---------------------------------------------------------------------------------------------
// 1. blit.wgsl

/// Copy one layer of a texture with `bpp` bytes per texel back, rows tightly packed.
fn read_texture(
    gpu: &Gpu,
    t: &wgpu::Texture,
    bpp: u32,
    layer: u32,
    aspect: wgpu::TextureAspect,
) -> Vec<u8> {
    readback::read_texture_layer(gpu, t, bpp, layer, aspect).unwrap()
}

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
// 3. lighting.wgsl: light_irradiance, point_face, the shadow layers' projections

fn random_light(r: &mut Rng) -> GpuLight {
    let kind = match r.next_u32() % 3 {
        0 => LightKind::Directional,
        1 => LightKind::Point,
        _ => {
            let inner = uniform(r, 0.0, 1.0);
            // A quarter of the spots have equal cones (a hard step).
            let outer = if r.next_u32() % 4 == 0 {
                inner
            } else {
                inner + uniform(r, 0.02, 0.5)
            };
            LightKind::Spot {
                inner_cone: inner,
                outer_cone: outer,
            }
        }
    };
    let mut l = light(
        kind,
        Vec3::new(
            uniform(r, -2.0, 2.0),
            uniform(r, -2.0, 2.0),
            uniform(r, -2.0, 2.0),
        ),
        unit(r),
        Vec3::new(
            uniform(r, 0.0, 3.0),
            uniform(r, 0.0, 3.0),
            uniform(r, 0.0, 3.0),
        ),
        uniform(r, 0.1, 4.0),
    );
    if r.next_u32() % 2 == 0 {
        l.range = Some(uniform(r, 0.5, 5.0));
    }
    GpuLight::from_light(&l, 1.0, 0)
}

#[test]
fn light_irradiance_matches_its_rust_twin() {
    let Some(gpu) = gpu() else { return };
    let mut r = rng(3);
    let lights: Vec<GpuLight> = (0..64).map(|_| random_light(&mut r)).collect();
    let cases = 8192usize;
    let mut input: Vec<[f32; 4]> = Vec::with_capacity(2 * cases);
    for i in 0..cases {
        let li = i % lights.len();
        let l = &lights[li];
        let (pos, dir) = (
            Vec3::from_slice(&l.position[..3]),
            Vec3::from_slice(&l.direction[..3]),
        );
        let p = if l.kind() == KIND_SPOT && i % 4 != 3 {
            // Most spot cases inside or just outside the outer cone, through the smoothstep.
            let outer = f32::from_bits(l.params[3]).acos();
            let a = uniform(&mut r, 0.0, 1.2 * outer);
            let perp = dir.cross(unit(&mut r)).normalize();
            pos + (dir * a.cos() + perp * a.sin()) * uniform(&mut r, 0.05, 4.0)
        } else {
            Vec3::new(
                uniform(&mut r, -2.5, 2.5),
                uniform(&mut r, -2.5, 2.5),
                uniform(&mut r, -2.5, 2.5),
            )
        };
        // Half the normals face the light (so that most values are not zero).
        let mut n = unit(&mut r);
        let to_light = if l.kind() == KIND_DIRECTIONAL {
            -dir
        } else {
            pos - p
        };
        if i % 2 == 0 && n.dot(to_light) < 0.0 {
            n = -n;
        }
        input.push(p.extend(li as f32).to_array());
        input.push(n.extend(0.0).to_array());
    }
    let p = lighting_harness(
        &gpu,
        r#"
@group(0) @binding(0) var<storage, read> test_lights: array<GpuLight>;
@group(0) @binding(1) var<storage, read> test_in: array<vec4<f32>>;        // p (w = light), n
@group(0) @binding(2) var<storage, read_write> test_out: array<vec4<f32>>; // irradiance, to_light
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&test_in) / 2u) {
        return;
    }
    let p = test_in[2u * i];
    let inc = light_irradiance(test_lights[u32(p.w)], p.xyz, test_in[2u * i + 1u].xyz);
    test_out[2u * i] = vec4<f32>(inc.irradiance, 0.0);
    test_out[2u * i + 1u] = vec4<f32>(inc.to_light, 0.0);
}
"#,
    );
    let lb = compute::storage(&gpu, "lights", &lights);
    let ib = compute::storage(&gpu, "in", &input);
    let ob = compute::output(&gpu, "out", input.len() as u64 * 16);
    let g = compute::bind(
        &gpu,
        &p,
        &[
            lb.as_entire_binding(),
            ib.as_entire_binding(),
            ob.as_entire_binding(),
        ],
    );
    dispatch(&gpu, &p, &[&g], cases as u32);
    let got = readback::read_f32(&gpu, &ob).unwrap();
    let (mut max_h, mut max_l, mut nonzero) = (0.0f32, 0.0f32, [0usize; 3]);
    let mut worst = String::new();
    let mut results = Vec::with_capacity(cases);
    for i in 0..cases {
        let l = &lights[i % lights.len()];
        let (p, n) = (
            Vec3::from_slice(&input[2 * i][..3]),
            Vec3::from_slice(&input[2 * i + 1][..3]),
        );
        let (h, to_light, d) = light_irradiance(l, p, n);
        let gh = Vec3::from_slice(&got[8 * i..8 * i + 3]);
        let gl = Vec3::from_slice(&got[8 * i + 4..8 * i + 7]);
        // Error relative to the light's unwindowed, unattenuated irradiance scale at p (the
        // range window and the spot's smoothstep cancel digits near their edges).
        let rad = Vec3::from_slice(&l.radiance[..3]).max_element();
        let scale = if l.kind() == KIND_DIRECTIONAL {
            rad
        } else {
            rad / (d * d).max(1e-12)
        }
        .max(f32::MIN_POSITIVE);
        let eh = (gh - h).abs().max_element() / scale;
        let el = (gl - to_light).abs().max_element();
        if eh > max_h {
            max_h = eh;
            worst = format!("case {i} kind {} gpu {gh} cpu {h}", l.kind());
        }
        max_l = max_l.max(el);
        if h.max_element() > 0.0 {
            nonzero[l.kind() as usize] += 1;
        }
        results.push((i, eh, el, gh, h));
    }
    eprintln!(
        "light_irradiance: max relative error {max_h:.3e} ({worst}), to_light max |error| {max_l:.3e}; lit cases per kind {nonzero:?}"
    );
    // Measured on lavapipe: irradiance 1.4e-7 relative, tolerance 5e-7 (3.5x); to_light is
    // bit-identical there (0), tolerance two ulp of a unit vector (2.4e-7) for GPUs whose
    // sqrt and division are not correctly rounded.
    const TOL_H: f32 = 5e-7;
    const TOL_L: f32 = 2.4e-7;
    for (i, eh, el, gh, h) in results {
        assert!(
            eh <= TOL_H,
            "case {i}: irradiance gpu {gh} cpu {h} (relative {eh:.3e})"
        );
        assert!(el <= TOL_L, "case {i}: to_light error {el:.3e}");
    }
    for (k, &c) in nonzero.iter().enumerate() {
        assert!(c > 500, "kind {k}: only {c} lit cases");
    }
}

#[test]
fn point_face_matches_its_rust_twin_including_ties() {
    let Some(gpu) = gpu() else { return };
    let mut dirs: Vec<Vec3> = Vec::new();
    // Every axis-aligned, edge and corner direction (ties of two and three axes), zero and
    // negative zeros, scaled ties.
    for x in [-1.0f32, 0.0, 1.0] {
        for y in [-1.0f32, 0.0, 1.0] {
            for z in [-1.0f32, 0.0, 1.0] {
                dirs.push(Vec3::new(x, y, z));
                dirs.push(Vec3::new(x, y, z) * 3.5);
            }
        }
    }
    dirs.extend([
        Vec3::new(-0.0, -0.0, -0.0),
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::new(-0.0, 1.0, 1.0),
        Vec3::new(2.0, -2.0, 1.0),
        Vec3::new(-3.0, 3.0, 3.0),
        Vec3::new(1e-3, -1e-3, 0.0),
        Vec3::new(0.5, 0.25, -0.5),
        Vec3::new(-0.25, -0.5, 0.5),
    ]);
    let mut r = rng(5);
    for _ in 0..2000 {
        dirs.push(unit(&mut r) * uniform(&mut r, 0.01, 10.0));
        // Ties between two random axes with random signs.
        let a = uniform(&mut r, 0.1, 2.0);
        let b = uniform(&mut r, 0.0, a);
        let s = |r: &mut Rng| if r.next_u32() % 2 == 0 { 1.0 } else { -1.0 };
        let v = [a * s(&mut r), a * s(&mut r), b * s(&mut r)];
        let k = (r.next_u32() % 3) as usize;
        dirs.push(Vec3::new(v[k], v[(k + 1) % 3], v[(k + 2) % 3]));
    }
    let p = lighting_harness(
        &gpu,
        r#"
@group(0) @binding(0) var<storage, read> test_dirs: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> test_faces: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < arrayLength(&test_dirs)) {
        test_faces[id.x] = point_face(test_dirs[id.x].xyz);
    }
}
"#,
    );
    let input: Vec<[f32; 4]> = dirs.iter().map(|d| d.extend(0.0).to_array()).collect();
    let ib = compute::storage(&gpu, "dirs", &input);
    let ob = compute::output(&gpu, "faces", dirs.len() as u64 * 4);
    let g = compute::bind(&gpu, &p, &[ib.as_entire_binding(), ob.as_entire_binding()]);
    dispatch(&gpu, &p, &[&g], dirs.len() as u32);
    let got: Vec<u32> = bytemuck::cast_slice(&readback::read_buffer(&gpu, &ob).unwrap()).to_vec();
    let mut per_face = [0usize; 6];
    for (i, d) in dirs.iter().enumerate() {
        let want = point_face(*d);
        assert_eq!(got[i], want, "direction {d:?}");
        per_face[want as usize] += 1;
    }
    // Independent of both: a face's axis is (one of) the largest components, with its sign.
    for d in &dirs {
        let f = point_face(*d) as usize;
        let (axis, negative) = (f / 2, f % 2 == 1);
        let a = d.abs();
        assert!(a[axis] >= a.max_element(), "{d:?} → face {f}");
        assert_eq!(d[axis] < 0.0, negative, "{d:?} → face {f}");
    }
    eprintln!(
        "point_face: {} directions agree; per face {per_face:?}",
        dirs.len()
    );
    assert!(per_face.iter().all(|&c| c > 100), "{per_face:?}");
}

#[test]
fn shadow_layer_projections_match_their_rust_twin() {
    let Some(gpu) = gpu() else { return };
    let (centre, radius) = (Vec3::new(0.2, 0.5, -0.1), 1.7);
    let lights = [
        GpuLight::from_light(
            &light(
                LightKind::Directional,
                Vec3::ZERO,
                Vec3::new(0.4, -1.0, 0.3),
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
        GpuLight::from_light(
            &light(
                LightKind::Spot {
                    inner_cone: 0.2,
                    outer_cone: 0.6,
                },
                Vec3::new(-1.0, 2.5, 0.5),
                Vec3::new(0.5, -1.0, -0.2),
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
        GpuLight::from_light(
            &light(
                LightKind::Point,
                Vec3::new(0.3, 0.6, 0.1),
                Vec3::Y,
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
        // A directional light straight down (the other `up` vector).
        GpuLight::from_light(
            &light(
                LightKind::Directional,
                Vec3::ZERO,
                Vec3::NEG_Y,
                Vec3::ONE,
                1.0,
            ),
            1.0,
            0,
        ),
    ];
    let u = lights_uniform(&lights, centre, radius);
    let mut r = rng(9);
    let cases = 4096usize;
    let points: Vec<[f32; 4]> = (0..cases)
        .map(|i| {
            let p = centre + unit(&mut r) * radius * uniform(&mut r, 0.0, 1.0).cbrt();
            p.extend((i % lights.len()) as f32).to_array()
        })
        .collect();
    // The layer choice and projection of `shadow_visibility`, without the normal offset and
    // the texture lookup.
    let p = lighting_harness(
        &gpu,
        r#"
@group(0) @binding(0) var<storage, read> test_points: array<vec4<f32>>;   // p, w = light
@group(0) @binding(1) var<storage, read_write> test_clip: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> test_layer: array<u32>;
@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= arrayLength(&test_points)) {
        return;
    }
    let p = test_points[i];
    let light = lights.lights[u32(p.w)];
    var layer = light.params.y;
    if (light.params.x == KIND_POINT) {
        layer = layer + point_face(p.xyz - light.position.xyz);
    }
    test_layer[i] = layer;
    test_clip[i] = lights.layer_view_proj[layer] * vec4<f32>(p.xyz, 1.0);
}
"#,
    );
    let ub = compute::uniform(&gpu, "lights", &u);
    let pb = compute::storage(&gpu, "points", &points);
    let cb = compute::output(&gpu, "clip", cases as u64 * 16);
    let lb = compute::output(&gpu, "layer", cases as u64 * 4);
    let g0 = compute::bind(
        &gpu,
        &p,
        &[
            pb.as_entire_binding(),
            cb.as_entire_binding(),
            lb.as_entire_binding(),
        ],
    );
    let g1 = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &p.get_bind_group_layout(1),
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: ub.as_entire_binding(),
        }],
    });
    dispatch(&gpu, &p, &[&g0, &g1], cases as u32);
    let clip = readback::read_f32(&gpu, &cb).unwrap();
    let layers: Vec<u32> =
        bytemuck::cast_slice(&readback::read_buffer(&gpu, &lb).unwrap()).to_vec();
    let projections: Vec<Vec<Mat4>> = lights
        .iter()
        .map(|l| shadow_projections(l, centre, radius))
        .collect();
    let mut max_err = 0.0f32;
    let mut inside_cone = 0;
    for i in 0..cases {
        let li = i % lights.len();
        let l = &u.lights[li];
        let pos = Vec3::from_slice(&points[i][..3]);
        let face = if l.kind() == KIND_POINT {
            point_face(pos - Vec3::from_slice(&l.position[..3]))
        } else {
            0
        };
        assert_eq!(layers[i], l.params[1] + face, "point {i}: layer");
        let want = projections[li][face as usize] * pos.extend(1.0);
        let got = Vec4::from_slice(&clip[4 * i..4 * i + 4]);
        let e = (got - want).abs().max_element() / want.abs().max_element().max(1.0);
        max_err = max_err.max(e);
        // Measured on lavapipe: 2.3e-7 relative (a chain of four multiply-adds): 2x.
        assert!(
            e <= 4.8e-7,
            "point {i}: gpu {got} cpu {want} (relative {e:.3e})"
        );
        // Independent property of the twin: the chosen layer sees the point (inside the
        // layer's frustum) — for directional and point lights every point of the sphere, for
        // the spot every point inside its outer cone.
        let ndc = want.truncate() / want.w;
        let cone = (pos - Vec3::from_slice(&l.position[..3]))
            .normalize()
            .dot(Vec3::from_slice(&l.direction[..3]));
        let must_see = l.kind() != KIND_SPOT || cone > f32::from_bits(l.params[3]);
        inside_cone += (l.kind() == KIND_SPOT && must_see) as usize;
        if must_see {
            let eps = 1e-4;
            assert!(
                want.w > 0.0
                    && ndc.x.abs() <= 1.0 + eps
                    && ndc.y.abs() <= 1.0 + eps
                    && (-eps..=1.0 + eps).contains(&ndc.z),
                "light {li} face {face}: point {pos} projects to {ndc} (w {})",
                want.w
            );
        }
    }
    eprintln!("shadow projections: max relative clip error {max_err:.3e}; {inside_cone} points inside the spot's cone");
    assert!(inside_cone > 50);
}

// ---------------------------------------------------------------------------------------------
// 4. direct_light.wgsl with punctual lights and shadow maps

/// The square occluder of the direct-light scene: centre, half size (horizontal, facing up).
const OCCLUDER: (Vec3, f32) = (Vec3::new(0.3, 0.6, 0.2), 0.4);

/// Does the occluder cut the segment from `p` to `end`? (Exact, independent of any BVH.)
fn occluded(p: Vec3, end: Vec3) -> bool {
    let (c, h) = OCCLUDER;
    let dy = end.y - p.y;
    if dy.abs() < 1e-12 {
        return false;
    }
    let t = (c.y - p.y) / dy;
    if !(1e-4..1.0).contains(&t) {
        return false;
    }
    let q = p + (end - p) * t;
    (q.x - c.x).abs() <= h && (q.z - c.z).abs() <= h
}

fn light_end(l: &GpuLight, p: Vec3) -> Vec3 {
    if l.kind() == KIND_DIRECTIONAL {
        p - Vec3::from_slice(&l.direction[..3]) * 100.0
    } else {
        Vec3::from_slice(&l.position[..3])
    }
}

#[test]
fn direct_light_kernel_with_punctual_lights_and_shadow_maps_matches_its_twin() {
    use relume::radiosity::fixtures::SceneBuilder;
    use relume::radiosity::voxelize::{voxelize, Resolution, VoxelizeParams};
    use relume::render::direct::patch_exitance;
    let Some(gpu) = gpu() else { return };
    // A floor and a floating square above it.
    let mut b = SceneBuilder::new();
    let m = b.material("grey", [0.8, 0.6, 0.4], [0.0; 3]);
    b.rectangle("floor", DVec3::ZERO, DVec3::Z * 1.5, DVec3::X * 1.5, m);
    let (c, h) = OCCLUDER;
    b.rectangle(
        "occluder",
        c.as_dvec3(),
        DVec3::Z * h as f64,
        DVec3::X * h as f64,
        m,
    );
    let scene = b.build();
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(300),
            samples_per_patch: 16,
        },
    )
    .unwrap();
    let n = set.patches.len();
    let mut renderer = MeshRenderer::new(&gpu, &scene, 8, 8, 1024).unwrap();
    let zeros = relume::radiosity::TransportMatrix::zeros(1, n);
    let rt = RadiosityRuntime::new(&gpu, &set, TransportSource::Dense(&zeros), &renderer).unwrap();
    let mut point = light(
        LightKind::Point,
        Vec3::new(0.0, 1.4, 0.0),
        Vec3::NEG_Y,
        Vec3::new(1.0, 0.8, 0.6),
        2.0,
    );
    point.range = Some(4.0);
    let spot = light(
        LightKind::Spot {
            inner_cone: 0.35,
            outer_cone: 0.6,
        },
        Vec3::new(-0.8, 1.5, 0.4),
        Vec3::new(1.1, -0.9, -0.2),
        Vec3::new(0.7, 0.9, 1.0),
        3.0,
    );
    let sun = light(
        LightKind::Directional,
        Vec3::ZERO,
        Vec3::new(0.35, -1.0, -0.25),
        Vec3::new(1.0, 0.95, 0.9),
        1.5,
    );
    let s = FrameSettings::default();
    let mut timer = relume::gpu::timing::PassTimer::new(&gpu, 48);
    // Sample points whose shadow is the same within DELTA in the surface plane all around
    // (about 10 shadow-map texels for every light here): far from shadow edges, where the
    // shadow map's PCF, its normal offset and its depth bias change nothing.
    const DELTA: f32 = 0.04;
    let clear = |l: &GpuLight, p: Vec3| {
        let o = occluded(p, light_end(l, p));
        (0..8).all(|k| {
            let a = k as f32 * std::f32::consts::FRAC_PI_4;
            let q = p + Vec3::new(a.cos(), 0.0, a.sin()) * DELTA;
            occluded(q, light_end(l, q)) == o
        })
    };
    let mut overall = 0.0f32;
    for (name, scene_lights) in [
        ("point", vec![point.clone()]),
        ("spot", vec![spot.clone()]),
        ("directional", vec![sun.clone()]),
        ("all three", vec![point, spot, sun]),
    ] {
        let gl: Vec<GpuLight> = scene_lights
            .iter()
            .map(|l| GpuLight::from_light(l, 1.0, 0))
            .collect();
        renderer.set_lights(&gpu, &gl).unwrap();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        renderer.record_shadows(&mut enc, &mut timer);
        rt.record(
            &gpu,
            &mut enc,
            &renderer,
            &s,
            set.samples_per_patch,
            &mut timer,
        );
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        let got = readback::read_f32(&gpu, &rt.exitance).unwrap();
        let u = renderer.lights_uniform();
        let lights = &u.lights[..u.count as usize];
        let exact = |l: usize, p: Vec3, _n: Vec3, _to: Vec3, _d: f32| {
            !occluded(p, light_end(&lights[l], p))
        };
        let want = patch_exitance(&set, lights, &s, &exact);
        let unshadowed = patch_exitance(&set, lights, &s, &|_, _, _, _, _| true);
        let spp = set.samples_per_patch as usize;
        let (mut compared, mut shadowed, mut lit) = (0, 0, 0);
        let mut max_err = 0.0f32;
        for i in 0..n {
            let samples = &set.samples[i * spp..(i + 1) * spp];
            if !samples
                .iter()
                .all(|sp| lights.iter().all(|l| clear(l, Vec3::from(sp.position))))
            {
                continue;
            }
            compared += 1;
            let un = Vec3::from(unshadowed[i]);
            let (w, g) = (
                Vec3::from(want[i]),
                Vec3::from_slice(&got[4 * i..4 * i + 3]),
            );
            if un.max_element() > 0.0 {
                if w.max_element() < 0.5 * un.max_element() {
                    shadowed += 1;
                } else {
                    lit += 1;
                }
            }
            // Relative to the patch's unshadowed exitance (0 where no light reaches it).
            // Measured on lavapipe: 1.6e-7 (the point light; spot and sun bit-identical),
            // tolerance 5e-7 (3.2x).
            let e = (g - w).abs().max_element() / un.max_element().max(1e-20);
            max_err = max_err.max(e);
            assert!(
                e <= 5e-7,
                "{name}: patch {i} at {:?}: gpu {g} cpu {w} (unshadowed {un})",
                set.patches[i].centroid
            );
        }
        eprintln!(
            "direct light, {name}: {compared}/{n} patches away from shadow edges compared \
             ({shadowed} mostly shadowed, {lit} mostly lit), max relative error {max_err:.3e}"
        );
        assert!(
            compared * 2 > n,
            "{name}: only {compared} of {n} patches compared"
        );
        assert!(
            shadowed >= 3 && lit >= 3,
            "{name}: {shadowed} shadowed, {lit} lit"
        );
        overall = overall.max(max_err);
    }
    eprintln!("direct light: max relative error {overall:.3e}");
}

// ---------------------------------------------------------------------------------------------
// 5. Struct layouts shared by Rust and WGSL, against naga's layouter

/// A Rust type written into a WGSL struct: members (WGSL name, Rust byte offset, byte size).
struct Shared {
    shader: &'static str,
    wgsl: &'static str,
    rust: &'static str,
    size: usize,
    members: Vec<(&'static str, usize, usize)>,
}

/// (offset, size) of a Rust field.
macro_rules! field {
    ($t:ty, $f:ident) => {{
        let z: $t = bytemuck::Zeroable::zeroed();
        (std::mem::offset_of!($t, $f), std::mem::size_of_val(&z.$f))
    }};
}

/// (offset, size) of element `k` of a Rust padding array of u32.
macro_rules! pad {
    ($t:ty, $f:ident, $k:expr) => {{
        let z: $t = bytemuck::Zeroable::zeroed();
        assert_eq!(std::mem::size_of_val(&z.$f[0]), 4);
        assert!($k < z.$f.len());
        (std::mem::offset_of!($t, $f) + 4 * $k, 4)
    }};
}

macro_rules! shared {
    ($shader:literal, $wgsl:literal, $t:ty { $($m:literal : $v:expr),* $(,)? }) => {
        Shared {
            shader: $shader,
            wgsl: $wgsl,
            rust: stringify!($t),
            size: std::mem::size_of::<$t>(),
            members: vec![$({ let (o, s) = $v; ($m, o, s) }),*],
        }
    };
}

/// A uniform the driver writes as a plain `[u32; N]` (floats as their bits), member by member.
fn words(shader: &'static str, wgsl: &'static str, names: &[&'static str]) -> Shared {
    Shared {
        shader,
        wgsl,
        rust: "[u32; N]",
        size: 4 * names.len(),
        members: names
            .iter()
            .enumerate()
            .map(|(i, n)| (*n, 4 * i, 4))
            .collect(),
    }
}

fn shared_structs() -> Vec<Shared> {
    use relume::gpu::compressed_gather::Params as GatherParams;
    use relume::gpu::mesh_renderer::FrameUniform;
    use relume::gpu::terrain_renderer::{TerrainFrame, TerrainParams};
    vec![
        shared!("lighting.wgsl", "GpuLight", GpuLight {
            "position": field!(GpuLight, position),
            "direction": field!(GpuLight, direction),
            "radiance": field!(GpuLight, radiance),
            "params": field!(GpuLight, params),
        }),
        shared!("lighting.wgsl", "Lights", LightsUniform {
            "count": field!(LightsUniform, count),
            "shadow_bias": field!(LightsUniform, shadow_bias),
            "_pad0": pad!(LightsUniform, pad, 0),
            "_pad1": pad!(LightsUniform, pad, 1),
            "lights": field!(LightsUniform, lights),
            "layer_view_proj": field!(LightsUniform, layer_view_proj),
        }),
        shared!("mesh_shade.wgsl", "Frame", FrameUniform {
            "view_proj": field!(FrameUniform, view_proj),
            "eye": field!(FrameUniform, eye),
            "exposure": field!(FrameUniform, exposure),
            "emission_scale": field!(FrameUniform, emission_scale),
            "flags": field!(FrameUniform, flags),
            "_pad": field!(FrameUniform, pad),
        }),
        shared!("gather_compressed.wgsl", "GatherParams", GatherParams {
            "n": field!(GatherParams, n),
            "padded": field!(GatherParams, padded),
            "channels": field!(GatherParams, channels),
            "encoding": field!(GatherParams, encoding),
            "hardware": field!(GatherParams, hardware),
            "layer_words": field!(GatherParams, layer_words),
            "log_range": field!(GatherParams, log_range),
            "_pad": field!(GatherParams, pad),
            "scale": field!(GatherParams, scale),
            "lut": field!(GatherParams, lut),
        }),
        shared!("terrain_render.wgsl", "TerrainFrame", TerrainFrame {
            "view_proj": field!(TerrainFrame, view_proj),
            "eye": field!(TerrainFrame, eye),
            "sun": field!(TerrainFrame, sun),
            "cell": field!(TerrainFrame, cell),
            "fog": field!(TerrainFrame, fog),
            "exposure": field!(TerrainFrame, exposure),
            "flags": field!(TerrainFrame, flags),
            "min_height": field!(TerrainFrame, min_height),
            "max_height_tint": field!(TerrainFrame, max_height_tint),
        }),
        shared!("terrain_shadow.wgsl", "TerrainParams", TerrainParams {
            "width": field!(TerrainParams, width),
            "height": field!(TerrainParams, height),
            "levels": field!(TerrainParams, levels),
            "kind": field!(TerrainParams, kind),
            "step_x": field!(TerrainParams, step_x),
            "step_y": field!(TerrainParams, step_y),
            "_pad0": pad!(TerrainParams, pad0, 0),
            "_pad1": pad!(TerrainParams, pad0, 1),
            "ux": field!(TerrainParams, ux),
            "uy": field!(TerrainParams, uy),
            "inv_ux": field!(TerrainParams, inv_ux),
            "inv_uy": field!(TerrainParams, inv_uy),
            "rise_per_t": field!(TerrainParams, rise_per_t),
            "max_height": field!(TerrainParams, max_height),
            "min_height": field!(TerrainParams, min_height),
            "metres_per_t": field!(TerrainParams, metres_per_t),
            "alpha": field!(TerrainParams, alpha),
            "planet_radius": field!(TerrainParams, planet_radius),
            "sin_elevation0": field!(TerrainParams, sin_elevation0),
            "cos_elevation0": field!(TerrainParams, cos_elevation0),
            "sin_azimuth": field!(TerrainParams, sin_azimuth),
            "cos_azimuth": field!(TerrainParams, cos_azimuth),
            "cell_x": field!(TerrainParams, cell_x),
            "cell_y": field!(TerrainParams, cell_y),
            "tan_alpha": field!(TerrainParams, tan_alpha),
            "_pad2": pad!(TerrainParams, pad1, 0),
            "_pad3": pad!(TerrainParams, pad1, 1),
            "_pad4": pad!(TerrainParams, pad1, 2),
        }),
        // Written as words by RadiosityRuntime, the dense gather, the corner transfer, the
        // terrain mask pass and the tone-map test.
        words(
            "direct_light.wgsl",
            "DirectParams",
            &["patches", "samples_per_patch", "emission_scale", "flags"],
        ),
        words(
            "gather_dense.wgsl",
            "GatherParams",
            &["n", "channel", "_pad0", "_pad1"],
        ),
        words(
            "corner_interpolate.wgsl",
            "TransferParams",
            &["corners", "_pad0", "_pad1", "_pad2"],
        ),
        words(
            "terrain_mask.wgsl",
            "MaskParams",
            &["method", "_pad0", "_pad1", "_pad2"],
        ),
        words("tonemap_test.wgsl", "Params", &["count", "exposure"]),
    ]
}

#[test]
fn shared_structs_have_the_layout_naga_computes() {
    let table = shared_structs();
    let mut checked = 0;
    for (shader, _) in relume::gpu::SHADERS {
        let src = shader_source(shader).unwrap();
        let module = naga::front::wgsl::parse_str(&src)
            .unwrap_or_else(|e| panic!("{shader}: {}", e.emit_to_string(&src)));
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        // Every struct a uniform or storage binding holds (itself or as array elements) must
        // be in the table, except those only the GPU writes and reads.
        let mut bound = Vec::new();
        for (_, var) in module.global_variables.iter() {
            if !matches!(
                var.space,
                naga::AddressSpace::Uniform | naga::AddressSpace::Storage { .. }
            ) {
                continue;
            }
            let mut ty = var.ty;
            if let naga::TypeInner::Array { base, .. } = module.types[ty].inner {
                ty = base;
            }
            if let naga::TypeInner::Struct { .. } = module.types[ty].inner {
                bound.push(module.types[ty].name.clone().unwrap());
            }
        }
        for name in &bound {
            assert!(
                table.iter().any(|s| s.wgsl == name
                    && (s.shader == *shader
                        || shader_source(shader)
                            .unwrap()
                            .contains(&format!("// ---- {}", s.shader)))),
                "{shader}: struct {name} is bound but has no Rust counterpart in the layout table"
            );
        }
        for s in table.iter().filter(|s| s.shader == *shader) {
            let (handle, ty) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(s.wgsl))
                .unwrap_or_else(|| panic!("{shader} has no struct {}", s.wgsl));
            let naga::TypeInner::Struct { members, .. } = &ty.inner else {
                panic!("{shader}: {} is not a struct", s.wgsl)
            };
            assert_eq!(
                layouter[handle].size as usize, s.size,
                "{shader}: size of {} (WGSL) vs {} (Rust)",
                s.wgsl, s.rust
            );
            let wgsl: Vec<(&str, usize, usize)> = members
                .iter()
                .map(|m| {
                    (
                        m.name.as_deref().unwrap(),
                        m.offset as usize,
                        layouter[m.ty].size as usize,
                    )
                })
                .collect();
            assert_eq!(
                wgsl, s.members,
                "{shader}: members (name, offset, size) of {} (WGSL, left) vs {} (Rust, right)",
                s.wgsl, s.rust
            );
            checked += 1;
        }
    }
    assert_eq!(checked, table.len(), "a table entry names a missing shader");
    eprintln!("{checked} shared structs match naga's layout");
}
