//! Helpers of the GPU twin tests (`tests/gpu_twins_*.rs`): seeded random inputs, lights, a
//! compute harness that includes `lighting.wgsl`, dispatch and texture readback.
#![allow(dead_code)]

use glam::Vec3;
use rand_core::{RngCore, SeedableRng};
use relume::gpu::mesh_renderer::LightsUniform;
use relume::gpu::{readback, shader_source, Gpu};
use relume::render::lights::{shadow_projections, GpuLight, MAX_LIGHTS, MAX_SHADOW_LAYERS};
use relume::scene::{Light, LightKind};

pub type Rng = rand_pcg::Pcg32;

pub fn rng(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// Uniform in [lo, hi).
pub fn uniform(r: &mut Rng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * ((r.next_u32() >> 8) as f32 / (1u32 << 24) as f32)
}

pub fn unit(r: &mut Rng) -> Vec3 {
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

pub fn light(
    kind: LightKind,
    position: Vec3,
    direction: Vec3,
    color: Vec3,
    intensity: f32,
) -> Light {
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
pub fn lights_uniform(lights: &[GpuLight], centre: Vec3, radius: f32) -> LightsUniform {
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
pub fn lighting_harness(gpu: &Gpu, harness: &str) -> wgpu::ComputePipeline {
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

pub fn dispatch(gpu: &Gpu, p: &wgpu::ComputePipeline, groups: &[&wgpu::BindGroup], count: u32) {
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

/// Copy one layer of a texture with `bpp` bytes per texel back, rows tightly packed.
pub fn read_texture(
    gpu: &Gpu,
    t: &wgpu::Texture,
    bpp: u32,
    layer: u32,
    aspect: wgpu::TextureAspect,
) -> Vec<u8> {
    readback::read_texture_layer(gpu, t, bpp, layer, aspect).unwrap()
}
