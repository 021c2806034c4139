//! The f32 twin of `shaders/freeform_shade.wgsl`: one pixel's colour from the cast (distance and
//! normal), the shadow pass's answer and the surface's material — the CPU caster's shading
//! (`crate::freeform::shade`: Lambert and a Phong lobe of exponent 32 under the sun, an ambient
//! fraction), then the air when the scene has one (aerial perspective on surfaces, the sky where
//! rays miss), then exposure and sRGB, as the kernel computes it.

use crate::atmosphere::frame::AirFrame;
use crate::atmosphere::lut::{self, Luts};
use crate::atmosphere::Atmosphere;
use crate::render::tonemap::{linear_to_srgb, to_u8};
use crate::scene::freeform::SceneAir;
use glam::{DVec3, Vec3};

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

/// The air over a freeform frame: the model's uniform fields (`atmosphere::frame`, model 0 =
/// none), the scene's kilometres per unit, and Hillaire's tables when the model is his.
#[derive(Clone, Copy, Debug)]
pub struct FreeformAir<'a> {
    pub frame: AirFrame,
    pub km_per_unit: f32,
    pub luts: Option<&'a Luts>,
}

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Linear radiance `rgb` of a surface at distance `t` (scene units) along the unit ray `d` —
/// or, with `t` None, of the background where the ray missed — as seen through the air, the
/// sun toward unit `sun`: twin of `through_air` in `shaders/freeform_shade.wgsl`. Surfaces:
/// `rgb·T + L_in·π` over t·km_per_unit; misses: the sky (the constant-density fog's s → ∞
/// limit, or Hillaire's sky view). The fog of Vyatkin et al. (2018), a per-vertex model, is
/// evaluated per pixel (no vertices).
pub fn through_air(
    rgb: [f32; 3],
    d: [f32; 3],
    t: Option<f32>,
    sun: [f32; 3],
    air: &FreeformAir,
) -> [f32; 3] {
    let f = &air.frame;
    let dir = Vec3::from(d);
    let scale = f.fog_sun[3];
    let out = match (f.model, air.luts) {
        (1 | 2, _) => {
            let (s_km, l0) = match t {
                Some(t) => (t * air.km_per_unit, Vec3::from(rgb)),
                None => (1e9, Vec3::ZERO),
            };
            let inscatter = lut::fog(
                Vec3::ZERO,
                s_km,
                dir.dot(Vec3::from(sun)),
                v3(f.fog_ext),
                v3(f.fog_rayleigh),
                v3(f.fog_mie),
                f.fog_ext[3],
                v3(f.fog_sun),
            ) * scale;
            l0 * (-v3(f.fog_ext) * s_km).exp() + inscatter
        }
        (3, Some(luts)) => match t {
            Some(t) => {
                let (l, tr) = luts.aerial_perspective(dir, t * air.km_per_unit);
                Vec3::from(rgb) * tr + l * scale
            }
            None => luts.sky_radiance(dir) * scale,
        },
        _ => Vec3::from(rgb),
    };
    out.to_array()
}

/// Where a scene placed by `a` puts an eye at height `eye_y` (scene units) in the air: its
/// altitude (m, rounded to 1 m so that sideways moves rebuild no table, kept inside the air:
/// 1 m to 1 km below its top), the sun `sun` as f64, and the aerial volume's range (m: the
/// view's `far` distance, 10 to 400 km).
pub fn air_placement(
    a: &SceneAir,
    eye_y: f64,
    far: f64,
    sun: [f32; 3],
    atm: &Atmosphere,
) -> (f64, DVec3, f64) {
    let top = atm.top_radius - atm.ground_radius - 1000.0;
    let eye_altitude = a.altitude(eye_y).round().clamp(1.0, top);
    let range = (far * a.metres_per_unit).clamp(10_000.0, 400_000.0);
    let sun = DVec3::new(sun[0] as f64, sun[1] as f64, sun[2] as f64);
    (eye_altitude, sun, range)
}

/// sRGB8 of one pixel. `hit`: `(t, n)` or `None`; `d` the unit view ray; `material` rgb and
/// specular; `air` the scene's air (None: no air, the sun white).
pub fn shade32(
    hit: Option<(f32, [f32; 3])>,
    shadowed: bool,
    d: [f32; 3],
    material: [f32; 4],
    s: &Shading,
    air: Option<&FreeformAir>,
) -> [u8; 4] {
    let sun_c = air.map_or([1.0; 3], |a| {
        [
            a.frame.sun_light[0],
            a.frame.sun_light[1],
            a.frame.sun_light[2],
        ]
    });
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
            std::array::from_fn(|k| {
                material[k] * (a + (1.0 - a) * ndl * vis * sun_c[k]) + spec * sun_c[k]
            })
        }
    };
    let rgb = match air {
        Some(a) => through_air(rgb, d, hit.map(|h| h.0), s.sun, a),
        None => rgb,
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
