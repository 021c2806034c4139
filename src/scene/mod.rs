//! The plain scene description every loader produces (pbrt-v4 style: parsing first, building
//! later): world-space triangles with a material and a source object each, diffuse materials with
//! emission, and punctual lights. Nothing here knows about patches, BVHs or GPUs.
//!
//! Conventions (README "Conventions"): right-handed, y up; units are whatever the file uses,
//! multiplied by the pipeline's `scale` knob (the bundled Cornell box is in millimetres);
//! front faces wind counter-clockwise; emission is radiance L (W·m⁻²·sr⁻¹, OBJ `Ke`).

pub mod builder;
pub mod freeform;
pub mod generate;
mod gltf_loader;
pub mod light_spec;
pub mod mtl;
mod obj_loader;
pub mod obj_writer;
pub mod punctual;
pub mod shape_texture;
pub mod texture;

use crate::error::{Error, Result};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::Path;
use texture::{AlphaMask, Texture, TextureRef};

/// A diffuse material: albedo (reflectance, linear RGB in [0, 1]), optionally textured and
/// alpha-masked, and emitted radiance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Material {
    pub name: String,
    /// Diffuse reflectance ρ per channel, linear RGB, each in [0, 1]; with a texture, the factor
    /// the texture's linear colour is multiplied by (OBJ `Kd`, glTF `baseColorFactor`).
    pub albedo: [f32; 3],
    /// Emitted radiance L per channel (W·m⁻²·sr⁻¹). The exitance of a Lambertian emitter is π·L.
    pub emission: [f32; 3],
    /// The albedo texture (OBJ `map_Kd`, glTF `baseColorTexture`).
    pub albedo_texture: Option<TextureRef>,
    /// Where the surface is cut away (None: opaque everywhere).
    pub alpha: Option<AlphaMask>,
}

impl Material {
    /// The material used when a file names none (or its MTL is missing): 50 % grey, no emission.
    pub fn default_grey() -> Self {
        Material {
            name: "default".into(),
            albedo: [0.5; 3],
            emission: [0.0; 3],
            albedo_texture: None,
            alpha: None,
        }
    }

    /// A plain material: one albedo, one emitted radiance, no texture, opaque.
    pub fn plain(name: impl Into<String>, albedo: [f32; 3], emission: [f32; 3]) -> Self {
        Material {
            name: name.into(),
            albedo,
            emission,
            albedo_texture: None,
            alpha: None,
        }
    }

    /// True when a texture modulates the albedo or the alpha.
    pub fn is_textured(&self) -> bool {
        self.albedo_texture.is_some() || self.alpha.as_ref().is_some_and(|a| a.texture.is_some())
    }

    /// True when the material emits light in any channel.
    pub fn is_emissive(&self) -> bool {
        self.emission.iter().any(|&e| e > 0.0)
    }
}

/// The kind of a punctual light (KHR_lights_punctual semantics).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum LightKind {
    /// Light along `direction` from infinitely far away; intensity in lux (lm/m²).
    Directional,
    /// Light from `position` in all directions; intensity in candela (lm/sr).
    Point,
    /// A point light restricted to a cone around `direction` (angles in radians).
    Spot { inner_cone: f32, outer_cone: f32 },
}

/// A punctual light in world space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    pub name: String,
    pub kind: LightKind,
    pub position: [f32; 3],
    /// Unit direction the light travels (for directional and spot lights).
    pub direction: [f32; 3],
    /// Linear RGB colour.
    pub color: [f32; 3],
    /// Candela for point and spot lights, lux for directional lights.
    pub intensity: f32,
    /// Range beyond which a point or spot light has no effect (None = infinite).
    pub range: Option<f32>,
}

/// A triangle mesh scene in world space.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Scene {
    /// World-space vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Vertex indices of each triangle, counter-clockwise front faces.
    pub triangles: Vec<[u32; 3]>,
    /// Material index of each triangle (into `materials`).
    pub triangle_material: Vec<u32>,
    /// Source object index of each triangle (into `objects`).
    pub triangle_object: Vec<u32>,
    /// Names of the source objects (OBJ `o`/`g`, glTF mesh or node names).
    pub objects: Vec<String>,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// Texture coordinates per vertex (glTF frame: origin top-left, v down); empty when no
    /// triangle has any. Vertices of untextured objects hold (0, 0).
    pub uvs: Vec<[f32; 2]>,
    /// The images materials refer to.
    pub textures: Vec<Texture>,
    /// Cameras the source file names (glTF camera nodes), in node order. Not part of
    /// `scene.bin` (a bake stores them in `views.json` when there are any).
    #[serde(skip)]
    pub viewpoints: Vec<Viewpoint>,
}

/// A perspective camera of the source file, in world space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Viewpoint {
    /// The node's (or camera's) name.
    pub name: String,
    pub eye: [f32; 3],
    /// A point one unit along the view direction.
    pub target: [f32; 3],
    pub up: [f32; 3],
    /// Vertical field of view, degrees.
    pub fov_y_deg: f32,
}

/// What a loader noticed but did not treat as an error.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct LoadWarnings {
    pub messages: Vec<String>,
}

impl LoadWarnings {
    pub fn push(&mut self, m: impl Into<String>) {
        self.messages.push(m.into());
    }
}

/// Load options shared by every scene format.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneOptions {
    /// Multiply every position by this factor (e.g. 0.001 for millimetres to metres).
    pub scale: f32,
}

impl Default for SceneOptions {
    fn default() -> Self {
        SceneOptions { scale: 1.0 }
    }
}

/// Load an OBJ (+MTL), glTF or GLB scene, chosen by extension.
///
/// Errors name `path`. Non-finite positions are errors; degenerate (zero-area) triangles are
/// kept in the scene — later stages skip and count them — and reported among the warnings.
pub fn load_scene(path: &Path, opts: SceneOptions) -> Result<(Scene, LoadWarnings)> {
    if !(opts.scale.is_finite() && opts.scale > 0.0) {
        return Err(Error::knob(format!(
            "scene scale must be a positive finite number, got {}",
            opts.scale
        )));
    }
    if path.is_dir() {
        return Err(Error::input(
            path,
            "is a directory, expected a scene file (.obj, .gltf or .glb)",
        ));
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let mut warnings = LoadWarnings::default();
    let mut scene = match ext.as_deref() {
        Some("obj") => obj_loader::load(path, &mut warnings)?,
        Some("gltf") | Some("glb") => gltf_loader::load(path, &mut warnings)?,
        _ => {
            return Err(Error::unsupported(
                path,
                "unknown scene format (expected .obj, .gltf or .glb)",
            ))
        }
    };
    if opts.scale != 1.0 {
        for p in &mut scene.positions {
            for c in p.iter_mut() {
                *c *= opts.scale;
            }
        }
        for l in &mut scene.lights {
            for c in l.position.iter_mut() {
                *c *= opts.scale;
            }
            l.range = l.range.map(|r| r * opts.scale);
        }
        for v in &mut scene.viewpoints {
            let forward = [0, 1, 2].map(|k| v.target[k] - v.eye[k]);
            v.eye = v.eye.map(|c| c * opts.scale);
            v.target = [0, 1, 2].map(|k| v.eye[k] + forward[k]);
        }
    }
    scene.validate(path)?;
    let degenerate = scene.degenerate_triangles().count();
    if degenerate == scene.triangles.len() {
        return Err(Error::input(
            path,
            format!("all {degenerate} triangle(s) are degenerate (zero area): nothing to light"),
        ));
    }
    if degenerate > 0 {
        warnings.push(format!(
            "{degenerate} degenerate (zero-area) triangle(s) will be ignored by the bake"
        ));
    }
    Ok((scene, warnings))
}

impl Scene {
    /// Check the invariants every later stage relies on; errors name `path`.
    pub fn validate(&self, path: &Path) -> Result<()> {
        if self.triangles.is_empty() {
            return Err(Error::input(path, "the scene has no triangles"));
        }
        if let Some((i, p)) = self
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            return Err(Error::input(
                path,
                format!("vertex {} has a non-finite coordinate {:?}", i + 1, p),
            ));
        }
        let n = self.positions.len() as u32;
        if let Some((t, tri)) = self
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&v| v >= n))
        {
            return Err(Error::input(
                path,
                format!("triangle {t} refers to vertex {tri:?}, but there are only {n} vertices"),
            ));
        }
        let nm = self.materials.len() as u32;
        if self.triangle_material.len() != self.triangles.len()
            || self.triangle_object.len() != self.triangles.len()
            || self.triangle_material.iter().any(|&m| m >= nm)
            || self
                .triangle_object
                .iter()
                .any(|&o| o as usize >= self.objects.len())
        {
            return Err(Error::Internal(format!(
                "{}: loader produced inconsistent material/object indices",
                path.display()
            )));
        }
        if !self.uvs.is_empty() && self.uvs.len() != self.positions.len() {
            return Err(Error::Internal(format!(
                "{}: loader produced {} texture coordinates for {} vertices",
                path.display(),
                self.uvs.len(),
                self.positions.len()
            )));
        }
        if let Some(i) = self
            .uvs
            .iter()
            .position(|t| t.iter().any(|c| !c.is_finite()))
        {
            return Err(Error::input(
                path,
                format!(
                    "vertex {} has a non-finite texture coordinate {:?}",
                    i + 1,
                    self.uvs[i]
                ),
            ));
        }
        for m in &self.materials {
            self.validate_textures(path, m)?;
            if m.albedo
                .iter()
                .chain(&m.emission)
                .any(|c| !c.is_finite() || *c < 0.0)
            {
                return Err(Error::input(
                    path,
                    format!("material `{}` has a negative or non-finite colour", m.name),
                ));
            }
            if m.albedo.iter().any(|&c| c > 1.0) {
                return Err(Error::input(
                    path,
                    format!(
                        "material `{}` has albedo {:?} above 1: a diffuse surface cannot reflect more light than it receives",
                        m.name, m.albedo
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Texture references of `m` point at textures that exist, with finite transforms, and its
    /// alpha factor and cutoff are finite numbers.
    fn validate_textures(&self, path: &Path, m: &Material) -> Result<()> {
        let refs = m.albedo_texture.iter().chain(
            m.alpha
                .iter()
                .flat_map(|a| a.texture.as_ref().map(|t| &t.0)),
        );
        for r in refs {
            if r.texture as usize >= self.textures.len() {
                return Err(Error::Internal(format!(
                    "{}: material `{}` names texture {} of {}",
                    path.display(),
                    m.name,
                    r.texture,
                    self.textures.len()
                )));
            }
            if r.transform.iter().flatten().any(|c| !c.is_finite()) {
                return Err(Error::input(
                    path,
                    format!(
                        "material `{}` has a non-finite texture transform {:?}",
                        m.name, r.transform
                    ),
                ));
            }
        }
        if let Some(a) = &m.alpha {
            if !(a.factor.is_finite() && a.cutoff.is_finite()) {
                return Err(Error::input(
                    path,
                    format!(
                        "material `{}` has a non-finite alpha ({} cut at {})",
                        m.name, a.factor, a.cutoff
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The mean albedo of material `m` over its texture (factor × the texture's mean linear
    /// colour), its albedo when untextured: one colour per material, for reports and
    /// per-material decisions.
    pub fn mean_albedo(&self, m: &Material) -> [f32; 3] {
        match &m.albedo_texture {
            None => m.albedo,
            Some(t) => {
                let mean = t.of(&self.textures).mean_linear_rgb();
                [0, 1, 2].map(|c| m.albedo[c] * mean[c])
            }
        }
    }

    /// [`Scene::mean_albedo`] of every material, in order.
    pub fn mean_albedos(&self) -> Vec<[f32; 3]> {
        self.materials.iter().map(|m| self.mean_albedo(m)).collect()
    }

    /// The three corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|v| Vec3::from(self.positions[v as usize]))
    }

    /// Area of triangle `t`.
    pub fn triangle_area(&self, t: usize) -> f32 {
        let [a, b, c] = self.corners(t);
        0.5 * (b - a).cross(c - a).length()
    }

    /// Indices of triangles whose area is zero (or not a normal number) relative to their size.
    pub fn degenerate_triangles(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.triangles.len()).filter(move |&t| self.is_degenerate(t))
    }

    /// True when triangle `t` has zero area (or not a normal number) relative to its size.
    pub fn is_degenerate(&self, t: usize) -> bool {
        let [a, b, c] = self.corners(t);
        let cross = (b - a).cross(c - a).length();
        let scale = (b - a).length_squared().max((c - a).length_squared());
        cross.partial_cmp(&(scale * 1e-12)) != Some(std::cmp::Ordering::Greater)
            || !cross.is_normal()
    }

    /// Indices of the triangles that are not degenerate: what the bake voxelizes and traces.
    pub fn live_triangles(&self) -> Vec<u32> {
        (0..self.triangles.len() as u32)
            .filter(|&t| !self.is_degenerate(t as usize))
            .collect()
    }

    /// Axis-aligned bounds (min, max) of all vertices referenced by triangles.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for tri in &self.triangles {
            for &v in tri {
                let p = Vec3::from(self.positions[v as usize]);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        (lo, hi)
    }

    /// Total surface area of all triangles.
    pub fn total_area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| self.triangle_area(t) as f64)
            .sum()
    }

    /// True when every material is grey (R = G = B albedo): one colour channel suffices for the
    /// transport matrix.
    pub fn is_grey(&self) -> bool {
        self.materials.iter().all(|m| {
            m.albedo[0] == m.albedo[1]
                && m.albedo[1] == m.albedo[2]
                && m.albedo_texture
                    .as_ref()
                    .is_none_or(|t| t.of(&self.textures).is_grey())
        })
    }

    /// Index of a material with this name, adding it when absent.
    pub(crate) fn material_index(&mut self, m: Material) -> u32 {
        if let Some(i) = self.materials.iter().position(|x| *x == m) {
            return i as u32;
        }
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }
}
