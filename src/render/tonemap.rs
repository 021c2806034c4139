//! Display transform: exposure, Reinhard-style tone curve on luminance-preserving RGB, sRGB
//! encoding. The WGSL twin is `tonemap` in `shaders/common.wgsl`; tests compare them.

/// Linear → sRGB transfer (IEC 61966-2-1). Twin of `linear_to_srgb` in common.wgsl.
pub use crate::scene::texture::linear_to_srgb;

/// Map linear radiance to display sRGB in [0, 1]: `x·exposure / (1 + x·exposure)` per channel
/// (Reinhard), then sRGB. Twin of `tonemap` in common.wgsl.
pub fn tonemap(rgb: [f32; 3], exposure: f32) -> [f32; 3] {
    rgb.map(|c| {
        let x = (c * exposure).max(0.0);
        linear_to_srgb(x / (1.0 + x)).clamp(0.0, 1.0)
    })
}

/// Encode linear [0, 1] as 8-bit sRGB (the one sRGB encoder: [`linear_to_srgb`], then [`to_u8`]).
pub fn linear_to_srgb8(v: f32) -> u8 {
    to_u8(linear_to_srgb(v.clamp(0.0, 1.0)))
}

/// Quantise a display value to 8 bits (round to nearest), as a `Rgba8Unorm` target does.
pub fn to_u8(c: f32) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}
