// Terrain frame: the height field as a grid mesh (x east = column · cell_x, y up = height,
// z south = row · cell_y), shaded per pixel at the pixel's texel: hypsometric tint × (Lambert ×
// shadow brightness + sky), relief shadows by the accelerated traversal or the horizon maps (hard), aerial
// perspective, tone map; soft shadows (the sun disc's lit fraction by branch-and-bound) on
// request. Rust twin: relume::render::terrain_shading.
//! include terrain_shadow.wgsl
//! include theme.wgsl

struct TerrainFrame {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,            // world position (y up)
    sun: vec4<f32>,            // toward the sun in map space (x east, y north, z up); w = k_shadow
    cell: vec4<f32>,           // cell_x, cell_y, vertical exaggeration, grid step (texels)
    fog: vec4<f32>,            // extinction per metre, scattering albedo, anisotropy g, sun strength
    exposure: f32,
    flags: u32,                // bit 0 shadows, bit 1 fog, bit 2 soft shadows, bit 3 horizon maps, bit 4 themes
    min_height: f32,
    max_height_tint: f32,
}
@group(0) @binding(0) var<uniform> frame: TerrainFrame;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) texel: vec2<f32>,
    @location(1) world: vec3<f32>,
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

// Radiance of a texel (before fog): albedo × (sun × Lambert × (1 − (1 − k)·shadow) + sky).
// Rust twin: relume::render::terrain_shading::texel_radiance.
fn texel_radiance(albedo: vec3<f32>, lambert: f32, shadow: f32, k: f32) -> vec3<f32> {
    let relief = lambert * (1.0 - (1.0 - k) * shadow);
    return albedo * (frame.fog.w * relief + 0.15);
}

// Henyey-Greenstein phase function.
fn phase(cos_theta: f32, g: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * PI * pow(max(d, 1e-6), 1.5));
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
    if ((frame.flags & 16u) != 0u) {
        albedo = theme_albedo(tp, footprint);
    } else {
        let h = height_at(col, row);
        albedo = tint((h - frame.min_height) / max(frame.max_height_tint - frame.min_height, 1e-6));
    }
    var rgb = texel_radiance(albedo, lambert_at(col, row), shadow, frame.sun.w);
    if ((frame.flags & 2u) != 0u) {
        // Aerial perspective (docs/algorithms.md §6): L = L0·e^(−β s) + E_sun·(β_sc/β_ext)·Φ(θ)·(1 − e^(−β s)).
        let to_eye = frame.eye.xyz - v.world;
        let s = length(to_eye);
        let view = -to_eye / max(s, 1e-6);
        // Map space (x east, y north, z up) → world (x east, y up, z south).
        let sun_world = vec3<f32>(frame.sun.x, frame.sun.z, -frame.sun.y);
        let transmittance = exp(-frame.fog.x * s);
        let inscatter = frame.fog.w * frame.fog.y * phase(dot(view, sun_world), frame.fog.z) * 4.0 * PI
            * vec3<f32>(0.55, 0.65, 0.85);
        rgb = rgb * transmittance + inscatter * (1.0 - transmittance);
    }
    return vec4<f32>(tonemap(rgb, frame.exposure), 1.0);
}
