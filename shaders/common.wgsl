// Shared WGSL types and helpers, prepended to every kernel in shaders/ (see src/gpu/mod.rs).

const PI: f32 = 3.14159265358979;

// Linear → sRGB transfer (IEC 61966-2-1), per channel. Rust twin: relume::render::tonemap::linear_to_srgb.
fn linear_to_srgb(c: f32) -> f32 {
    if (c <= 0.0031308) {
        return 12.92 * max(c, 0.0);
    }
    return 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

// Exposure, Reinhard per channel, sRGB. Rust twin: relume::render::tonemap::tonemap.
fn tonemap(rgb: vec3<f32>, exposure: f32) -> vec3<f32> {
    let x = max(rgb * exposure, vec3<f32>(0.0));
    let t = x / (vec3<f32>(1.0) + x);
    return clamp(vec3<f32>(linear_to_srgb(t.x), linear_to_srgb(t.y), linear_to_srgb(t.z)), vec3<f32>(0.0), vec3<f32>(1.0));
}
