//! The CPU reference of the mesh shader (`shaders/mesh_shade.wgsl`): the same per-corner vertex
//! data, the same Lambertian shading and tone map; visibility of punctual lights by ray casting
//! where the GPU uses shadow maps (so the two agree except near shadow edges).

use super::lights::{light_irradiance, GpuLight};
use super::tonemap::tonemap;
use crate::scene::Scene;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// What to draw and how to display it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameSettings {
    pub exposure: f32,
    /// Multiplies emitted radiance (the emitters' intensity knob).
    pub emission_scale: f32,
    pub direct: bool,
    pub indirect: bool,
    pub shadows: bool,
    pub emission: bool,
    /// Terrain: soft shadows of the sun's disc instead of hard ones.
    pub soft_shadows: bool,
    /// Terrain: hard shadows from the bake's horizon maps when it has them (else the
    /// traversal over the min/max mipmap).
    pub horizon_shadows: bool,
    /// Terrain and freeform scenes with `air`: aerial perspective and sky (by `atmosphere`).
    pub fog: bool,
    /// Terrain and freeform scenes with `air`: which atmosphere model draws them.
    pub atmosphere: crate::atmosphere::Model,
    /// Terrain: thematic textures when the bake has a theme set (else the hypsometric tint).
    pub themes: bool,
    /// Terrain: theme borders move from frame to frame.
    pub theme_animation: bool,
    /// Display colour behind the scene (sRGB, 0..1).
    pub background: [f32; 3],
    /// Mesh scenes: albedo textures (off: each material's mean albedo, the patches' clay view).
    #[serde(default = "yes")]
    pub textures: bool,
}

fn yes() -> bool {
    true
}

impl Default for FrameSettings {
    fn default() -> Self {
        FrameSettings {
            exposure: 1.0,
            emission_scale: 1.0,
            direct: true,
            indirect: true,
            shadows: true,
            emission: true,
            soft_shadows: false,
            horizon_shadows: true,
            fog: true,
            atmosphere: crate::atmosphere::Model::Hillaire,
            themes: true,
            theme_animation: true,
            background: [0.0; 3],
            textures: true,
        }
    }
}

impl FrameSettings {
    /// The `flags` word of the `Frame` uniform.
    pub fn flags(&self) -> u32 {
        self.direct as u32
            | (self.indirect as u32) << 1
            | (self.shadows as u32) << 2
            | (self.emission as u32) << 3
            | (self.textures as u32) << 4
    }
}

/// How far emitters are lifted off their plane, relative to the scene's diagonal, so that an
/// emitter lying in a wall (the Cornell box light in its ceiling) is what the eye sees.
pub const EMITTER_LIFT: f32 = 1e-4;

/// Per-corner vertex data (3 per triangle): position, face normal, albedo (the material's mean
/// over its texture, [`Scene::mean_albedo`]), emission — 12 floats each, the layout of the GPU
/// vertex buffer. Degenerate triangles get the normal +y; emissive
/// triangles are lifted by [`EMITTER_LIFT`] × the scene diagonal along their normal.
pub fn corner_vertices(scene: &Scene) -> Vec<f32> {
    let (lo, hi) = scene.bounds();
    let lift = EMITTER_LIFT * (hi - lo).length();
    let mut out = Vec::with_capacity(scene.triangles.len() * 36);
    let albedos = scene.mean_albedos();
    for t in 0..scene.triangles.len() {
        let [a, b, c] = scene.corners(t);
        let n = (b - a).cross(c - a).normalize_or(Vec3::Y);
        let m = &scene.materials[scene.triangle_material[t] as usize];
        let offset = if m.is_emissive() {
            n * lift
        } else {
            Vec3::ZERO
        };
        for p in [a + offset, b + offset, c + offset] {
            out.extend_from_slice(&p.to_array());
            out.extend_from_slice(&n.to_array());
            out.extend_from_slice(&albedos[scene.triangle_material[t] as usize]);
            out.extend_from_slice(&m.emission);
        }
    }
    out
}

/// Per-corner texture coordinates (2 floats per corner, in the order of [`corner_vertices`]);
/// zeros for a scene without them.
pub fn corner_uvs(scene: &Scene) -> Vec<f32> {
    if scene.uvs.is_empty() {
        return vec![0.0; 6 * scene.triangles.len()];
    }
    scene
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| scene.uvs[v as usize]))
        .flatten()
        .collect()
}

/// Outgoing radiance at a surface point: twin of `shade_point` in mesh_shade.wgsl.
/// `visible(light_index, p, n, to_light, distance)` answers whether the light reaches `p`.
#[allow(clippy::too_many_arguments)]
pub fn shade_point(
    s: &FrameSettings,
    lights: &[GpuLight],
    p: Vec3,
    n: Vec3,
    albedo: Vec3,
    emission: Vec3,
    indirect: Vec3,
    visible: &dyn Fn(usize, Vec3, Vec3, Vec3, f32) -> bool,
) -> Vec3 {
    let mut radiance = Vec3::ZERO;
    if s.direct {
        let mut h = Vec3::ZERO;
        for (i, l) in lights.iter().enumerate() {
            let (irr, to_light, dist) = light_irradiance(l, p, n);
            if irr.max_element() > 0.0 && (!s.shadows || visible(i, p, n, to_light, dist)) {
                h += irr;
            }
        }
        radiance += albedo / std::f32::consts::PI * h;
    }
    if s.indirect {
        radiance += indirect / std::f32::consts::PI;
    }
    if s.emission {
        radiance += emission * s.emission_scale;
    }
    radiance
}

/// Display colour (sRGB 0..1) of a radiance: twin of the end of `fs_main`.
pub fn display(s: &FrameSettings, radiance: Vec3) -> [f32; 3] {
    tonemap(radiance.to_array(), s.exposure)
}
