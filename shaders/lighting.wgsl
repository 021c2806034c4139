// Punctual lights with shadow maps, shared by the per-patch direct-light kernel and the mesh
// shader (included with `//! include lighting.wgsl`). Bindings live in group 1.
// Rust twins: relume::render::lights::{light_irradiance, point_face, shadow_projections}.

const MAX_LIGHTS: u32 = 8u;
const MAX_SHADOW_LAYERS: u32 = 24u;
const KIND_DIRECTIONAL: u32 = 0u;
const KIND_POINT: u32 = 1u;
const KIND_SPOT: u32 = 2u;

struct GpuLight {
    position: vec4<f32>,
    direction: vec4<f32>,
    radiance: vec4<f32>,   // rgb = colour x intensity, w = range (0 = infinite)
    params: vec4<u32>,     // kind, first layer, bits of cos(inner), bits of cos(outer)
}

struct Lights {
    count: u32,
    shadow_bias: f32,      // world-space normal offset for shadow lookups
    _pad0: u32,
    _pad1: u32,
    lights: array<GpuLight, 8>,
    layer_view_proj: array<mat4x4<f32>, 24>,
}

@group(1) @binding(0) var<uniform> lights: Lights;
@group(1) @binding(1) var shadow_maps: texture_depth_2d_array;
@group(1) @binding(2) var shadow_sampler: sampler_comparison;

fn smoothstep_safe(e0: f32, e1: f32, x: f32) -> f32 {
    if (e1 <= e0) {
        return select(0.0, 1.0, x >= e0);
    }
    let t = clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

struct Incidence {
    irradiance: vec3<f32>,
    to_light: vec3<f32>,
}

// Unshadowed irradiance at p with unit normal n.
fn light_irradiance(light: GpuLight, p: vec3<f32>, n: vec3<f32>) -> Incidence {
    let rad = light.radiance.xyz;
    let dir = light.direction.xyz;
    if (light.params.x == KIND_DIRECTIONAL) {
        let l = -dir;
        return Incidence(rad * max(dot(n, l), 0.0), l);
    }
    let v = light.position.xyz - p;
    let d2 = max(dot(v, v), 1e-12);
    let d = sqrt(d2);
    let l = v / d;
    var h = rad * max(dot(n, l), 0.0) / d2;
    let range = light.radiance.w;
    if (range > 0.0) {
        let q = d / range;
        let w = clamp(1.0 - q * q * q * q, 0.0, 1.0);
        h = h * (w * w);
    }
    if (light.params.x == KIND_SPOT) {
        h = h * smoothstep_safe(bitcast<f32>(light.params.w), bitcast<f32>(light.params.z), dot(-l, dir));
    }
    return Incidence(h, l);
}

fn point_face(v: vec3<f32>) -> u32 {
    let a = abs(v);
    if (a.x >= a.y && a.x >= a.z) {
        return select(1u, 0u, v.x >= 0.0);
    }
    if (a.y >= a.z) {
        return select(3u, 2u, v.y >= 0.0);
    }
    return select(5u, 4u, v.z >= 0.0);
}

// Fraction of the light that reaches p (1 = lit), from the light's shadow map with 2x2 PCF.
fn shadow_visibility(light: GpuLight, p: vec3<f32>, n: vec3<f32>) -> f32 {
    var layer = light.params.y;
    if (light.params.x == KIND_POINT) {
        layer = layer + point_face(p - light.position.xyz);
    }
    let q = p + n * lights.shadow_bias;
    let clip = lights.layer_view_proj[layer] * vec4<f32>(q, 1.0);
    if (clip.w <= 0.0) {
        return 1.0;
    }
    let ndc = clip.xyz / clip.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || ndc.z > 1.0) {
        return 1.0;
    }
    return textureSampleCompareLevel(shadow_maps, shadow_sampler, uv, i32(layer), ndc.z);
}

// Shadowed irradiance from all lights at p with unit normal n.
fn direct_irradiance(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    var h = vec3<f32>(0.0);
    for (var i = 0u; i < min(lights.count, MAX_LIGHTS); i = i + 1u) {
        let light = lights.lights[i];
        let inc = light_irradiance(light, p, n);
        if (any(inc.irradiance > vec3<f32>(0.0))) {
            h = h + inc.irradiance * shadow_visibility(light, p, n);
        }
    }
    return h;
}
