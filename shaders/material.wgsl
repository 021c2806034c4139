// A mesh material's maps (group 2, one bind group per material), shared by the shading pass and
// the alpha-tested shadow pass (included with `//! include material.wgsl`).
// Rust twins: relume::render::material_maps::SceneMaps::{albedo_at, opaque_at}; the bind group is
// built by relume::gpu::mesh_materials.

struct Material {
    albedo_u: vec4<f32>,   // image u = dot(albedo_u.xyz, vec3(uv, 1))
    albedo_v: vec4<f32>,
    mask_u: vec4<f32>,
    mask_v: vec4<f32>,
    factor: vec4<f32>,     // rgb: albedo factor; a: alpha cutoff
    flags: vec4<u32>,      // x: bit 0 albedo texture, bit 1 alpha mask
}

@group(2) @binding(0) var<uniform> material: Material;
@group(2) @binding(1) var albedo_map: texture_2d<f32>;
@group(2) @binding(2) var albedo_sampler: sampler;
@group(2) @binding(3) var mask_map: texture_2d<f32>;
@group(2) @binding(4) var mask_sampler: sampler;

fn albedo_coords(uv: vec2<f32>) -> vec2<f32> {
    let h = vec3<f32>(uv, 1.0);
    return vec2<f32>(dot(material.albedo_u.xyz, h), dot(material.albedo_v.xyz, h));
}

fn mask_coords(uv: vec2<f32>) -> vec2<f32> {
    let h = vec3<f32>(uv, 1.0);
    return vec2<f32>(dot(material.mask_u.xyz, h), dot(material.mask_v.xyz, h));
}

// True where the alpha mask cuts the surface away. The lookup runs in uniform control flow
// (implicit derivatives), the test after it.
fn masked_out(uv: vec2<f32>) -> bool {
    let alpha = textureSample(mask_map, mask_sampler, mask_coords(uv)).r;
    return (material.flags.x & 2u) != 0u && alpha < material.factor.a;
}
