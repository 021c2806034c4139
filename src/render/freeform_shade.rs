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

/// Thematic textures on a freeform frame: the set's lookup, how it is laid on the scene
/// (`SceneThemes::projection` packed: kind 1 planar / 2 spherical), the eye and the angle one
/// pixel spans (2·tan_x / width).
pub struct ThemeView<'a> {
    pub look: crate::theme::compose::Lookup<'a>,
    pub kind: u32,
    pub projection: [f32; 4],
    pub eye: [f32; 3],
    pub pixel_angle: f32,
}

/// The theme albedo where the unit ray `d` from the eye meets a surface at distance `t`: twin
/// of `freeform_theme_albedo` in `shaders/freeform_shade.wgsl`.
pub fn themed_albedo(tv: &ThemeView, d: [f32; 3], t: f32) -> [f32; 3] {
    let p: [f32; 3] = std::array::from_fn(|k| tv.eye[k] + d[k] * t);
    let base = &tv.look.set.index.levels[0];
    let (iw, ih) = (base.width as f32, base.height as f32);
    let c = tv.projection;
    let (u, v, texel) = if tv.kind == 1 {
        let (sx, sz) = (c[2] - c[0], c[3] - c[1]);
        ((p[0] - c[0]) / sx, (p[2] - c[1]) / sz, sx / iw)
    } else {
        let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        let r = dot(q, q).sqrt().max(1e-20);
        let u = (q[2].atan2(q[0]) + std::f32::consts::PI) / std::f32::consts::TAU;
        let v = (q[1] / r).clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        (u, v, std::f32::consts::TAU * r / iw)
    };
    let footprint = t * tv.pixel_angle / texel.max(1e-20);
    tv.look.albedo([u * iw, v * ih], footprint)
}
