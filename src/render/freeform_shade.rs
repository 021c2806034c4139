//! The f32 twin of `shaders/freeform_shade.wgsl`: one pixel's colour from the cast (distance and
//! normal), the shadow pass's answer and the surface's material — the CPU caster's shading
//! (`crate::freeform::shade`: Lambert and a Phong lobe of exponent 32 under the sun, an ambient fraction)
//! then exposure and sRGB, as the kernel computes it.

use crate::render::tonemap::{linear_to_srgb, to_u8};

/// What the shading pass reads besides the pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shading {
    /// Unit direction toward the sun.
    pub sun: [f32; 3],
    pub ambient: f32,
    pub background: [f32; 3],
    pub exposure: f32,
    pub shadows: bool,
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// sRGB8 of one pixel. `hit`: `(t, n)` or `None`; `d` the unit view ray; `material` rgb and
/// specular.
pub fn shade32(
    hit: Option<(f32, [f32; 3])>,
    shadowed: bool,
    d: [f32; 3],
    material: [f32; 4],
    s: &Shading,
) -> [u8; 4] {
    let rgb = match hit {
        None => s.background,
        Some((_, n)) => {
            let l = s.sun;
            let ndl = dot(n, l).max(0.0);
            let vis = if ndl > 0.0 && !(s.shadows && shadowed) {
                1.0
            } else {
                0.0
            };
            let refl: [f32; 3] = std::array::from_fn(|k| 2.0 * dot(n, l) * n[k] - l[k]);
            let spec = material[3] * vis * (-dot(refl, d)).max(0.0).powi(32);
            let a = s.ambient;
            std::array::from_fn(|k| material[k] * (a + (1.0 - a) * ndl * vis) + spec)
        }
    };
    let c = rgb.map(|v| to_u8(linear_to_srgb((v * s.exposure).clamp(0.0, 1.0))));
    [c[0], c[1], c[2], 255]
}
