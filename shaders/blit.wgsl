// Copies the player's RGBA8 target onto the window's surface (any format) texel for texel.
// Rust twin: relume::gpu::blit::blit_reference (tests/gpu_twins_raster.rs compares them texel by texel).

@group(0) @binding(0) var source: texture_2d<f32>;

struct VOut { @builtin(position) clip: vec4<f32> }

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> VOut {
    // One triangle that covers the viewport.
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return VOut(vec4<f32>(uv * 2.0 - 1.0, 0.0, 1.0));
}

@fragment
fn fs_main(v: VOut) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(source));
    let p = clamp(vec2<i32>(v.clip.xy), vec2<i32>(0), size - vec2<i32>(1));
    return textureLoad(source, p, 0);
}
