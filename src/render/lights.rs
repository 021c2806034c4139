//! Punctual lights of a frame (KHR_lights_punctual semantics) in the layout the GPU reads, their
//! unshadowed irradiance (the Rust twin of `light_irradiance` in `shaders/lighting.wgsl`), and the
//! shadow-map projections (one layer per directional or spot light, six per point light).

use super::camera::{look_at, orthographic, perspective};
use crate::scene::{Light, LightKind};
use crate::terrain::sun::Sun;
use glam::{Mat4, Vec3};

/// The sun of a mesh scene: a white directional light of 3 W/m² toward `sun` (y up), what
/// the player's `--sun` adds and `relume-bake export DIR gltf --sun` bakes.
pub fn sun_light(sun: &Sun) -> Light {
    Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        position: [0.0; 3],
        direction: (-sun.toward_y_up()).to_array(),
        color: [1.0, 0.97, 0.92],
        intensity: 3.0,
        range: None,
    }
}

/// Most punctual lights per frame.
pub const MAX_LIGHTS: usize = 8;
/// Most shadow-map layers per frame (a point light takes six).
pub const MAX_SHADOW_LAYERS: usize = 24;

pub const KIND_DIRECTIONAL: u32 = 0;
pub const KIND_POINT: u32 = 1;
pub const KIND_SPOT: u32 = 2;

/// One light as the shaders see it (std430/uniform compatible: 16-byte rows).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLight {
    /// World position (w unused).
    pub position: [f32; 4],
    /// Unit direction the light travels (w unused).
    pub direction: [f32; 4],
    /// Colour × intensity (W/m² for directional, W/sr for point and spot); w = range (0 = infinite).
    pub radiance: [f32; 4],
    /// kind, first shadow layer, cos(inner cone) bits, cos(outer cone) bits.
    pub params: [u32; 4],
}

impl GpuLight {
    /// Convert a scene light, with `scale` multiplying its intensity.
    pub fn from_light(l: &Light, scale: f32, first_layer: u32) -> GpuLight {
        let (kind, ci, co) = match l.kind {
            LightKind::Directional => (KIND_DIRECTIONAL, 1.0f32, 1.0f32),
            LightKind::Point => (KIND_POINT, -2.0, -2.0),
            LightKind::Spot {
                inner_cone,
                outer_cone,
            } => (KIND_SPOT, inner_cone.cos(), outer_cone.cos()),
        };
        let d = Vec3::from(l.direction).normalize_or(Vec3::NEG_Y);
        let rad = Vec3::from(l.color) * l.intensity * scale;
        GpuLight {
            position: Vec3::from(l.position).extend(1.0).to_array(),
            direction: d.extend(0.0).to_array(),
            radiance: rad.extend(l.range.unwrap_or(0.0)).to_array(),
            params: [kind, first_layer, ci.to_bits(), co.to_bits()],
        }
    }

    pub fn kind(&self) -> u32 {
        self.params[0]
    }

    /// Shadow-map layers this light uses.
    pub fn layers(&self) -> u32 {
        if self.kind() == KIND_POINT {
            6
        } else {
            1
        }
    }
}

/// Unshadowed irradiance (W/m² per channel) at `p` with unit normal `n`, and the unit vector
/// from `p` toward the light with the distance to it (∞ for directional lights).
/// Twin of `light_irradiance` in `shaders/lighting.wgsl`.
pub fn light_irradiance(light: &GpuLight, p: Vec3, n: Vec3) -> (Vec3, Vec3, f32) {
    let rad = Vec3::new(light.radiance[0], light.radiance[1], light.radiance[2]);
    let dir = Vec3::new(light.direction[0], light.direction[1], light.direction[2]);
    if light.kind() == KIND_DIRECTIONAL {
        let l = -dir;
        return (rad * n.dot(l).max(0.0), l, f32::INFINITY);
    }
    let v = Vec3::new(light.position[0], light.position[1], light.position[2]) - p;
    let d2 = v.length_squared().max(1e-12);
    let d = d2.sqrt();
    let l = v / d;
    let mut h = rad * n.dot(l).max(0.0) / d2;
    let range = light.radiance[3];
    if range > 0.0 {
        // glTF's recommended window: clamp(1 − (d/range)⁴, 0, 1)².
        let w = (1.0 - (d / range).powi(4)).clamp(0.0, 1.0);
        h *= w * w;
    }
    if light.kind() == KIND_SPOT {
        let (ci, co) = (
            f32::from_bits(light.params[2]),
            f32::from_bits(light.params[3]),
        );
        h *= smoothstep(co, ci, (-l).dot(dir));
    }
    (h, l, d)
}

/// GLSL/WGSL `smoothstep` (Hermite between `e0` and `e1`; a step when they are equal).
pub fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    if e1 <= e0 {
        return if x >= e0 { 1.0 } else { 0.0 };
    }
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// View-projection of every shadow layer of `light` for a scene inside the sphere
/// (`centre`, `radius`). Directional: orthographic over the sphere; spot: perspective over the
/// outer cone; point: six 90° faces in the order +x, −x, +y, −y, +z, −z.
pub fn shadow_projections(light: &GpuLight, centre: Vec3, radius: f32) -> Vec<Mat4> {
    let pos = Vec3::new(light.position[0], light.position[1], light.position[2]);
    let dir = Vec3::new(light.direction[0], light.direction[1], light.direction[2]);
    let up_for = |d: Vec3| if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let r = radius.max(1e-6);
    match light.kind() {
        KIND_DIRECTIONAL => {
            let eye = centre - dir * 2.0 * r;
            let view = look_at(eye, centre, up_for(dir));
            vec![orthographic(-r, r, -r, r, 0.0, 4.0 * r) * view]
        }
        KIND_SPOT => {
            let outer = f32::from_bits(light.params[3]).clamp(-1.0, 1.0).acos();
            let far = (pos - centre).length() + r;
            let view = look_at(pos, pos + dir, up_for(dir));
            vec![perspective((2.0 * outer).clamp(0.01, 3.0), 1.0, far * 1e-4, far) * view]
        }
        _ => {
            let far = (pos - centre).length() + r;
            let faces = [
                Vec3::X,
                Vec3::NEG_X,
                Vec3::Y,
                Vec3::NEG_Y,
                Vec3::Z,
                Vec3::NEG_Z,
            ];
            faces
                .iter()
                .map(|&f| {
                    let up = if f.y.abs() > 0.5 {
                        Vec3::Z
                    } else {
                        Vec3::NEG_Y
                    };
                    perspective(std::f32::consts::FRAC_PI_2, 1.0, far * 1e-4, far)
                        * look_at(pos, pos + f, up)
                })
                .collect()
        }
    }
}

/// Which face of a point light's six sees the direction `v` (from the light to the point), in
/// [`shadow_projections`] order. Twin of `point_face` in `shaders/lighting.wgsl`.
pub fn point_face(v: Vec3) -> u32 {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        if v.x >= 0.0 {
            0
        } else {
            1
        }
    } else if a.y >= a.z {
        if v.y >= 0.0 {
            2
        } else {
            3
        }
    } else if v.z >= 0.0 {
        4
    } else {
        5
    }
}

/// One texel of [`shadow_depth`]: the depth the shadow pass stores, and the distance (texels)
/// from the texel's centre to the nearest projected triangle edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthTexel {
    pub depth: f32,
    pub edge_distance: f32,
}

/// Twin of the shadow-map pass (`shaders/shadow_depth.wgsl` with depth test `Less`, cleared to
/// 1): the depth of the nearest of `triangles` (world space, both faces) at each texel centre of
/// a `size`×`size` layer projected by `view_proj`, rows from the top. The depth is clip z / w,
/// interpolated linearly in window space as the rasteriser does. No clipping: every corner must
/// lie in front of the light with depth in [0, 1] (panics otherwise).
pub fn shadow_depth(triangles: &[[Vec3; 3]], view_proj: Mat4, size: u32) -> Vec<DepthTexel> {
    let s = size as f32;
    let window: Vec<[Vec3; 3]> = triangles
        .iter()
        .map(|t| {
            t.map(|p| {
                let c = view_proj * p.extend(1.0);
                assert!(c.w > 0.0, "corner {p} is behind the light");
                let n = c.truncate() / c.w;
                assert!((0.0..=1.0).contains(&n.z), "corner {p} has depth {}", n.z);
                Vec3::new((n.x * 0.5 + 0.5) * s, (0.5 - n.y * 0.5) * s, n.z)
            })
        })
        .collect();
    let segment_distance = |p: glam::Vec2, a: glam::Vec2, b: glam::Vec2| {
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared().max(f32::MIN_POSITIVE)).clamp(0.0, 1.0);
        (p - (a + ab * t)).length()
    };
    let mut out = Vec::with_capacity((size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let mut texel = DepthTexel {
                depth: 1.0,
                edge_distance: f32::INFINITY,
            };
            for [a, b, c] in &window {
                let (a2, b2, c2) = (a.truncate(), b.truncate(), c.truncate());
                for (u, v) in [(a2, b2), (b2, c2), (c2, a2)] {
                    texel.edge_distance = texel.edge_distance.min(segment_distance(p, u, v));
                }
                let area = (b2 - a2).perp_dot(c2 - a2);
                if area == 0.0 {
                    continue;
                }
                let wa = (c2 - b2).perp_dot(p - b2) / area;
                let wb = (a2 - c2).perp_dot(p - c2) / area;
                let wc = 1.0 - wa - wb;
                if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                    let z = wa * a.z + wb * b.z + wc * c.z;
                    texel.depth = texel.depth.min(z);
                }
            }
            out.push(texel);
        }
    }
    out
}
