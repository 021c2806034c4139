// Terrain frame: the height field as a grid mesh (x east = column · cell_x, y up = height,
// z south = row · cell_y), shaded per pixel at the pixel's texel: albedo (thematic textures or
// the hypsometric tint) × (sun × Lambert × shadow brightness + sky), relief shadows by the
// accelerated traversal or the horizon maps (hard) or branch-and-bound (soft), scattered light
// by the chosen atmosphere model, tone map; and the sky by the same model (`fs_sky`).
// Rust twins: relume::render::terrain_shading, relume::theme::compose, relume::atmosphere.
//! include terrain_shadow.wgsl
//! include theme.wgsl
//! include atmosphere_lookup.wgsl

struct TerrainFrame {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    eye: vec4<f32>,            // world position (y up)
    sun: vec4<f32>,            // toward the sun in map space (x east, y north, z up); w = k_shadow
    cell: vec4<f32>,           // cell_x, cell_y, vertical exaggeration, grid step (texels)
    sun_light: vec4<f32>,      // sun irradiance reaching the terrain (RGB), w: sky (ambient) term
    fog_ext: vec4<f32>,        // constant-density fog: extinction per km (RGB), w: Mie g
    fog_rayleigh: vec4<f32>,   // Rayleigh scattering per km (RGB), w: unused
    fog_mie: vec4<f32>,        // Mie scattering per km (RGB), w: unused
    fog_sun: vec4<f32>,        // sun illuminance lighting the air (RGB), w: radiance scale (π)
    exposure: f32,
    flags: u32,                // bit 0 shadows, bit 1 air, bit 2 soft shadows, bit 3 horizon maps, bit 4 themes
    min_height: f32,
    max_height_tint: f32,
    model: u32,                // 1 fog per vertex, 2 per pixel, 3 Hillaire (with bit 1 set)
    pad0: u32,
    pad1: u32,
    pad2: u32,
}
@group(0) @binding(0) var<uniform> frame: TerrainFrame;

// Pipeline constants (gpu::terrain_pipelines makes one pipeline per combination): code a frame
// does not use is compiled out, as a software rasteriser runs both sides of a branch.
override THEMES: bool = true;
override HILLAIRE: bool = true;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) texel: vec2<f32>,
    @location(1) world: vec3<f32>,
    // Per-vertex constant-density fog: in-scattered radiance (rgb) and transmittance (rgb).
    @location(2) fog_in: vec3<f32>,
    @location(3) fog_t: vec3<f32>,
}

// Map space (x east, y north, z up) → world (x east, y up, z south).
fn sun_world() -> vec3<f32> {
    return vec3<f32>(frame.sun.x, frame.sun.z, -frame.sun.y);
}

// The constant-density fog (Vyatkin et al. 2018) over the segment eye → world: (in-scattered,
// transmittance) in the terrain's radiance units (× frame.fog_sun.w).
fn seed_fog(world: vec3<f32>) -> array<vec3<f32>, 2> {
    let to_p = world - frame.eye.xyz;
    let s_km = length(to_p) * 1e-3;
    let mu = dot(to_p / max(length(to_p), 1e-6), sun_world());
    let inscatter = fog(vec3<f32>(0.0), s_km, mu, frame.fog_ext.xyz, frame.fog_rayleigh.xyz,
        frame.fog_mie.xyz, frame.fog_ext.w, frame.fog_sun.xyz) * frame.fog_sun.w;
    return array<vec3<f32>, 2>(inscatter, exp(-frame.fog_ext.xyz * s_km));
}

@vertex
fn vs_main(@location(0) texel: vec2<f32>) -> VOut {
    // texel = texel-space position of a texel centre of the decimated grid.
    let col = min(u32(texel.x), terrain.width - 1u);
    let row = min(u32(texel.y), terrain.height - 1u);
    let h = heights[row * terrain.width + col];
    let world = vec3<f32>(texel.x * frame.cell.x, h * frame.cell.z, texel.y * frame.cell.y);
    var o: VOut;
    o.clip = frame.view_proj * vec4<f32>(world, 1.0);
    o.texel = texel;
    o.world = world;
    o.fog_in = vec3<f32>(0.0);
    o.fog_t = vec3<f32>(1.0);
    if ((frame.flags & 2u) != 0u && frame.model == 1u) {
        let f = seed_fog(world);
        o.fog_in = f[0];
        o.fog_t = f[1];
    }
    return o;
}

// Lambert term at texel (col, row) from central differences (one-sided at the border) in
// metres: relume::terrain::relief::lambert.
fn lambert_at(col: i32, row: i32) -> f32 {
    let w = i32(terrain.width);
    let h = i32(terrain.height);
    let c0 = max(col - 1, 0);
    let c1 = min(col + 1, w - 1);
    let r0 = max(row - 1, 0);
    let r1 = min(row + 1, h - 1);
    var dzdx = 0.0;
    if (c1 > c0) {
        dzdx = (height_at(c1, row) - height_at(c0, row)) / (f32(c1 - c0) * frame.cell.x);
    }
    var dzdy = 0.0;
    if (r1 > r0) {
        dzdy = (height_at(col, r0) - height_at(col, r1)) / (f32(r1 - r0) * frame.cell.y);
    }
    let n = vec3<f32>(-dzdx, -dzdy, 1.0);
    let l = dot(n, frame.sun.xyz) / length(n);
    return max(l, 0.0);
}

// Hypsometric tint (linear RGB) of a height, t = position between the map's min and max.
// Rust twin: relume::render::terrain_shading::tint.
fn tint(t_in: f32) -> vec3<f32> {
    let t = clamp(t_in, 0.0, 1.0);
    let low = vec3<f32>(0.10, 0.25, 0.08);
    let mid = vec3<f32>(0.35, 0.30, 0.18);
    let high = vec3<f32>(0.80, 0.80, 0.80);
    if (t < 0.5) {
        return mix(low, mid, t * 2.0);
    }
    return mix(mid, high, t * 2.0 - 1.0);
}

// Radiance of a texel (before the air): albedo × (sun × Lambert × (1 − (1 − k)·shadow) + sky).
// Rust twin: relume::render::terrain_shading::texel_radiance.
fn texel_radiance(albedo: vec3<f32>, lambert: f32, shadow: f32, k: f32) -> vec3<f32> {
    let relief = lambert * (1.0 - (1.0 - k) * shadow);
    return albedo * (frame.sun_light.xyz * relief + frame.sun_light.w);
}

@fragment
fn fs_main(v: VOut) -> @location(0) vec4<f32> {
    // Theme lookup position (index texels) and the pixel's footprint, taken here in uniform
    // control flow: the index map spans the height map.
    let tp = v.texel * (theme.index_size / vec2<f32>(f32(terrain.width), f32(terrain.height)));
    let footprint = max(length(dpdx(tp)), length(dpdy(tp)));
    let col = clamp(i32(floor(v.texel.x)), 0, i32(terrain.width) - 1);
    let row = clamp(i32(floor(v.texel.y)), 0, i32(terrain.height) - 1);
    var shadow = 0.0;
    if ((frame.flags & 1u) != 0u) {
        if ((frame.flags & 4u) != 0u) {
            shadow = 1.0 - lit_branch_and_bound(col, row);
        } else if ((frame.flags & 8u) != 0u) {
            shadow = select(0.0, 1.0, shadowed_horizon(col, row));
        } else if (shadowed_accelerated(col, row)) {
            shadow = 1.0;
        }
    }
    var albedo: vec3<f32>;
    if (THEMES && (frame.flags & 16u) != 0u) {
        albedo = theme_albedo(tp, footprint);
    } else {
        let h = height_at(col, row);
        albedo = tint((h - frame.min_height) / max(frame.max_height_tint - frame.min_height, 1e-6));
    }
    var rgb = texel_radiance(albedo, lambert_at(col, row), shadow, frame.sun.w);
    if ((frame.flags & 2u) != 0u) {
        // Scattered light (docs/atmosphere.md): L = L0·T + in-scattered.
        if (frame.model == 1u) {
            rgb = rgb * v.fog_t + v.fog_in;
        } else if (frame.model == 2u) {
            let f = seed_fog(v.world);
            rgb = rgb * f[1] + f[0];
        } else if (HILLAIRE && frame.model == 3u) {
            let to_p = v.world - frame.eye.xyz;
            let s = length(to_p);
            let m = aerial_perspective(to_p / max(s, 1e-6), s * 1e-3);
            rgb = rgb * m.transmittance + m.inscatter * frame.fog_sun.w;
        }
    }
    return vec4<f32>(tonemap(rgb, frame.exposure), 1.0);
}

// The sky: a full-screen triangle at the far plane (drawn after the terrain, depth test
// less-equal, so only where no terrain is), coloured by the atmosphere model.
struct SkyOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) ndc: vec2<f32>,
}

@vertex
fn vs_sky(@builtin(vertex_index) i: u32) -> SkyOut {
    let xy = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u)) * 2.0 - vec2<f32>(1.0);
    var o: SkyOut;
    o.clip = vec4<f32>(xy, 1.0, 1.0);
    o.ndc = xy;
    return o;
}

@fragment
fn fs_sky(v: SkyOut) -> @location(0) vec4<f32> {
    let far = frame.inv_view_proj * vec4<f32>(v.ndc, 1.0, 1.0);
    let near = frame.inv_view_proj * vec4<f32>(v.ndc, 0.0, 1.0);
    let dir = normalize(far.xyz / far.w - near.xyz / near.w);
    var rgb = vec3<f32>(0.0);
    if (frame.model == 3u) {
        rgb = sky_radiance(dir) * frame.fog_sun.w;
    } else {
        // The constant-density fog's limit s → ∞: E_sun·(β_sc·Φ)/β_ext.
        let mu = dot(dir, sun_world());
        rgb = fog(vec3<f32>(0.0), 1e9, mu, frame.fog_ext.xyz, frame.fog_rayleigh.xyz,
            frame.fog_mie.xyz, frame.fog_ext.w, frame.fog_sun.xyz) * frame.fog_sun.w;
    }
    return vec4<f32>(tonemap(rgb, frame.exposure), 1.0);
}
