// Shading of a freeform frame (after `freeform.wgsl` cast it): Lambert and Phong under the sun,
// an ambient fraction, sun shadows from the shadow pass, the background where the ray missed,
// exposure, sRGB. Rust twin: relume::render::freeform_shade::shade32.

struct ShadeFrame {
    forward: vec4<f32>,    // xyz, tan_x
    right: vec4<f32>,      // xyz, tan_y
    up: vec4<f32>,         // xyz, exposure
    sun: vec4<f32>,        // unit direction toward the sun, ambient
    background: vec4<f32>, // linear rgb, unused
    size: vec4<u32>,       // width, height, shadows, unused
}

@group(0) @binding(0) var<uniform> shade_frame: ShadeFrame;
// The caster's surfaces as vec4s: five per surface, the material (rgb, specular) the fifth.
@group(0) @binding(1) var<storage, read> surfaces: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> hit_normals: array<vec4<f32>>;
// Per pixel (status, shadowed, leaf, 0) from the shadow pass.
@group(0) @binding(3) var<storage, read> shadow_state: array<vec4<f32>>;
@group(0) @binding(4) var shaded: texture_storage_2d<rgba8unorm, write>;

fn pow32(x: f32) -> f32 {
    let x2 = x * x;
    let x4 = x2 * x2;
    let x8 = x4 * x4;
    let x16 = x8 * x8;
    return x16 * x16;
}

@compute @workgroup_size(8, 8)
fn shade(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = shade_frame.size.x;
    let h = shade_frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    let i = id.y * w + id.x;
    let hit = hit_normals[i];
    var rgb = shade_frame.background.xyz;
    if (hit.x >= 0.0) {
        let x = (( f32(id.x) + 0.5) / f32(w) * 2.0 - 1.0) * shade_frame.forward.w;
        let y = (1.0 - (f32(id.y) + 0.5) / f32(h) * 2.0) * shade_frame.right.w;
        let d = normalize(shade_frame.forward.xyz + x * shade_frame.right.xyz + y * shade_frame.up.xyz);
        let n = hit.yzw;
        let l = shade_frame.sun.xyz;
        let s = shadow_state[i];
        let m = surfaces[5u * u32(s.z) + 4u];
        let ndl = max(dot(n, l), 0.0);
        var vis = 0.0;
        if (ndl > 0.0 && !(shade_frame.size.z == 1u && s.y > 0.5)) { vis = 1.0; }
        let refl = 2.0 * dot(n, l) * n - l;
        let spec = m.w * vis * pow32(max(-dot(refl, d), 0.0));
        let a = shade_frame.sun.w;
        rgb = m.xyz * (a + (1.0 - a) * ndl * vis) + vec3<f32>(spec);
    }
    let e = rgb * shade_frame.up.w;
    let c = vec3<f32>(linear_to_srgb(clamp(e.x, 0.0, 1.0)), linear_to_srgb(clamp(e.y, 0.0, 1.0)), linear_to_srgb(clamp(e.z, 0.0, 1.0)));
    textureStore(shaded, vec2<i32>(id.xy), vec4<f32>(c, 1.0));
}
