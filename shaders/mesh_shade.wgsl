// Final shading of the full mesh: direct light from punctual lights (shadow maps, per pixel),
// indirect light transferred from the patches (per corner, interpolated), emission, tone map.
// Rust twin: relume::render::mesh_reference (CPU ray caster with BVH visibility).
//! include lighting.wgsl
//! include material.wgsl

struct Frame {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    exposure: f32,
    emission_scale: f32,
    flags: u32,        // bit 0 direct, bit 1 indirect, bit 2 shadows, bit 3 emission, bit 4 textures
    _pad: u32,
}
@group(0) @binding(0) var<uniform> frame: Frame;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    @location(3) emission: vec3<f32>,
    @location(4) indirect: vec3<f32>,
    @location(5) uv: vec2<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) albedo: vec3<f32>,
    @location(3) emission: vec3<f32>,
    @location(4) indirect: vec3<f32>,
    @location(5) uv: vec2<f32>,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var o: VertexOut;
    o.clip = frame.view_proj * vec4<f32>(v.position, 1.0);
    o.world = v.position;
    o.normal = v.normal;
    o.albedo = v.albedo;
    o.emission = v.emission;
    o.indirect = v.indirect;
    o.uv = v.uv;
    return o;
}

// Outgoing radiance of a Lambertian point: the twin of relume::render::mesh_reference::shade.
fn shade_point(p: vec3<f32>, n_in: vec3<f32>, albedo: vec3<f32>, emission: vec3<f32>, indirect: vec3<f32>) -> vec3<f32> {
    var n = normalize(n_in);
    var radiance = vec3<f32>(0.0);
    if ((frame.flags & 1u) != 0u) {
        var h = vec3<f32>(0.0);
        for (var i = 0u; i < min(lights.count, MAX_LIGHTS); i = i + 1u) {
            let light = lights.lights[i];
            let inc = light_irradiance(light, p, n);
            var vis = 1.0;
            if ((frame.flags & 4u) != 0u && any(inc.irradiance > vec3<f32>(0.0))) {
                vis = shadow_visibility(light, p, n);
            }
            h = h + inc.irradiance * vis;
        }
        radiance = radiance + albedo / PI * h;
    }
    if ((frame.flags & 2u) != 0u) {
        radiance = radiance + indirect / PI;
    }
    if ((frame.flags & 8u) != 0u) {
        radiance = radiance + emission * frame.emission_scale;
    }
    return radiance;
}

@fragment
fn fs_main(v: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Both lookups before any branch: their mip level comes from the uv derivatives.
    let texel = textureSample(albedo_map, albedo_sampler, albedo_coords(v.uv)).rgb;
    if (masked_out(v.uv)) {
        discard;
    }
    var albedo = v.albedo;
    var indirect = v.indirect;
    if ((frame.flags & 16u) != 0u && (material.flags.x & 1u) != 0u) {
        albedo = material.factor.rgb * texel;
        // The patches reflect the material's mean albedo (the vertex albedo); the texel's
        // departure from it modulates the indirect light too.
        indirect = indirect * albedo / max(v.albedo, vec3<f32>(1e-6));
    }
    // Two-sided: light the side facing the viewer (open scenes show back faces).
    var n = normalize(v.normal);
    if (!front) {
        n = -n;
    }
    let radiance = shade_point(v.world, n, albedo, v.emission, indirect);
    return vec4<f32>(tonemap(radiance, frame.exposure), 1.0);
}
