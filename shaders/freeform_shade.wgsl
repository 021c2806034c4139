// Shading of a freeform frame (after `freeform.wgsl` cast it): Lambert and Phong under the sun,
// an ambient fraction, sun shadows from the shadow pass, the background where the ray missed,
// exposure, sRGB; thematic textures over every surface when the scene has them (theme.wgsl,
// group 2); the air when the scene has one (aerial perspective and sky by the frame's model,
// Hillaire's tables in group 3). Rust twins: relume::render::freeform_shade::{shade32,
// themed_albedo, through_air}.
//! include theme.wgsl
//! include atmosphere_lookup.wgsl

struct ShadeFrame {
    forward: vec4<f32>,    // xyz, tan_x
    right: vec4<f32>,      // xyz, tan_y
    up: vec4<f32>,         // xyz, exposure
    sun: vec4<f32>,        // unit direction toward the sun, ambient
    background: vec4<f32>, // linear rgb, unused
    size: vec4<u32>,       // width, height, shadows, theme projection (0 none, 1 planar, 2 spherical)
    eye: vec4<f32>,        // xyz eye (world), w: the angle one pixel spans
    projection: vec4<f32>, // planar: min x, min z, max x, max z; spherical: centre xyz
    air: vec4<u32>,        // model (0 none, 1/2 fog per pixel, 3 Hillaire), unused x3
    air_scale: vec4<f32>,  // km per scene unit, unused x3
    sun_light: vec4<f32>,  // the sun's colour on surfaces (rgb), unused
    fog_ext: vec4<f32>,    // constant-density fog: extinction per km (rgb), w: Mie g
    fog_rayleigh: vec4<f32>,
    fog_mie: vec4<f32>,
    fog_sun: vec4<f32>,    // sun illuminance lighting the air (rgb), w: radiance scale (pi)
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

// The theme albedo where the unit ray d meets a surface at distance t: twin of
// relume::render::freeform_shade::themed_albedo.
fn freeform_theme_albedo(d: vec3<f32>, t: f32) -> vec3<f32> {
    let p = shade_frame.eye.xyz + d * t;
    let iw = theme.index_size.x;
    let ih = theme.index_size.y;
    let c = shade_frame.projection;
    var u: f32;
    var v: f32;
    var texel: f32;
    if (shade_frame.size.w == 1u) {
        let sx = c.z - c.x;
        let sz = c.w - c.y;
        u = (p.x - c.x) / sx;
        v = (p.z - c.y) / sz;
        texel = sx / iw;
    } else {
        let q = p - c.xyz;
        let r = max(sqrt(dot(q, q)), 1e-20);
        u = (atan2(q.z, q.x) + PI) / (2.0 * PI);
        v = acos(clamp(q.y / r, -1.0, 1.0)) / PI;
        texel = 2.0 * PI * r / iw;
    }
    let footprint = t * shade_frame.eye.w / max(texel, 1e-20);
    return theme_albedo(vec2<f32>(u * iw, v * ih), footprint);
}

// Radiance rgb of a surface at distance t (scene units) along unit d, or of the background
// where the ray missed (hit false), seen through the air: twin of
// relume::render::freeform_shade::through_air.
fn through_air(rgb: vec3<f32>, d: vec3<f32>, t: f32, hit: bool) -> vec3<f32> {
    let model = shade_frame.air.x;
    let scale = shade_frame.fog_sun.w;
    if (model == 1u || model == 2u) {
        var s_km = 1e9;
        var l0 = vec3<f32>(0.0);
        if (hit) {
            s_km = t * shade_frame.air_scale.x;
            l0 = rgb;
        }
        let inscatter = fog(vec3<f32>(0.0), s_km, dot(d, shade_frame.sun.xyz), shade_frame.fog_ext.xyz,
            shade_frame.fog_rayleigh.xyz, shade_frame.fog_mie.xyz, shade_frame.fog_ext.w,
            shade_frame.fog_sun.xyz) * scale;
        return l0 * exp(-shade_frame.fog_ext.xyz * s_km) + inscatter;
    }
    if (model == 3u) {
        if (hit) {
            let m = aerial_perspective(d, t * shade_frame.air_scale.x);
            return rgb * m.transmittance + m.inscatter * scale;
        }
        return sky_radiance(d) * scale;
    }
    return rgb;
}

@compute @workgroup_size(8, 8)
fn shade(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = shade_frame.size.x;
    let h = shade_frame.size.y;
    if (id.x >= w || id.y >= h) { return; }
    let i = id.y * w + id.x;
    let hit = hit_normals[i];
    var rgb = shade_frame.background.xyz;
    let x = (( f32(id.x) + 0.5) / f32(w) * 2.0 - 1.0) * shade_frame.forward.w;
    let y = (1.0 - (f32(id.y) + 0.5) / f32(h) * 2.0) * shade_frame.right.w;
    let d = normalize(shade_frame.forward.xyz + x * shade_frame.right.xyz + y * shade_frame.up.xyz);
    if (hit.x >= 0.0) {
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
        var albedo = m.xyz;
        if (shade_frame.size.w != 0u) {
            albedo = freeform_theme_albedo(d, hit.x);
        }
        let sun_c = shade_frame.sun_light.xyz;
        rgb = albedo * (a + (1.0 - a) * ndl * vis * sun_c) + spec * sun_c;
    }
    rgb = through_air(rgb, d, hit.x, hit.x >= 0.0);
    let e = rgb * shade_frame.up.w;
    let c = vec3<f32>(linear_to_srgb(clamp(e.x, 0.0, 1.0)), linear_to_srgb(clamp(e.y, 0.0, 1.0)), linear_to_srgb(clamp(e.z, 0.0, 1.0)));
    textureStore(shaded, vec2<i32>(id.xy), vec4<f32>(c, 1.0));
}
