//! The plain description of a freeform (function-based) scene, as read from
//! `scenes/freeform/*.ron`: surfaces made of a base quadric plus perturbation functions,
//! combined by union, intersection and difference; a camera and a sun. Nothing here evaluates
//! a field: `freeform::Field::compile` turns this into the arrays the ray casters use.
//!
//! The field of a surface is `F(x) + Σ gᵢ·Rᵢ(x)`, with `F` the base quadric and
//! `Rᵢ(x) = max(Qᵢ(x), 0)³`, where `Qᵢ = −(the perturbation shape's quadric)`: a perturbation acts
//! inside its shape, grows as the cube of the depth into it, and is C² where it starts. Solid is
//! where the field is negative, so a **negative weight adds material (raises the surface)** and
//! a positive weight removes it (lowers, dents). Union is `min`, intersection `max`, difference
//! `max(a, −b)`.
//!
//! Every quadric is written in its own frame and placed by a transform `M = T·R·S`
//! (translate, rotate X then Y then Z in degrees, scale); the world quadric is `Cᵀ Q C` with
//! `C = M⁻¹`.

use crate::error::ron_located::{located, RonFormat};
use crate::error::{Error, IoContext, Result};
use ron::extensions::Extensions;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub use super::shape_texture::{Carrier, HeightGrid, TexturedSurface};

/// The most perturbations one surface may carry (the GPU kernel's loop bound is the same).
pub const MAX_PERTURBATIONS: usize = 4096;

/// A freeform scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Freeform")]
pub struct FreeformScene {
    /// The solid: one surface or a CSG tree of them.
    pub shape: Shape,
    #[serde(default)]
    pub camera: Option<FreeformCamera>,
    #[serde(default)]
    pub sun: Option<SunAngles>,
    /// Linear RGB of pixels whose ray hits nothing.
    #[serde(default = "default_background")]
    pub background: [f64; 3],
    /// Ambient fraction of the sun's light on shadowed or back-facing points, in [0, 1].
    #[serde(default = "default_ambient")]
    pub ambient: f64,
    /// Thematic textures over every surface (replacing the surfaces' colours): a theme set
    /// (docs/themes.md) and how its index map is laid on the scene.
    #[serde(default)]
    pub themes: Option<SceneThemes>,
    /// The air over the scene (aerial perspective and sky, docs/atmosphere.md): how large the
    /// scene is in the world. Without it, nothing is drawn through the air.
    #[serde(default)]
    pub air: Option<SceneAir>,
}

/// How a freeform scene sits in the planet's air: the scene's +y is up, its unit is
/// `metres_per_unit` metres and the plane y = `sea_level` is altitude 0 (the surfaces are the
/// scene's own; the air's ground sphere only shapes the sky and the tables).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneAir {
    pub metres_per_unit: f64,
    #[serde(default)]
    pub sea_level: f64,
}

impl SceneAir {
    /// Check the numbers.
    pub fn check(&self) -> std::result::Result<(), String> {
        if !(self.metres_per_unit.is_finite() && self.metres_per_unit > 0.0) {
            return Err(format!(
                "air: metres_per_unit must be a positive number, got {}",
                self.metres_per_unit
            ));
        }
        if !self.sea_level.is_finite() {
            return Err(format!(
                "air: sea_level must be finite, got {}",
                self.sea_level
            ));
        }
        Ok(())
    }

    /// Altitude (m) of a scene point's y.
    pub fn altitude(&self, y: f64) -> f64 {
        (y - self.sea_level) * self.metres_per_unit
    }
}

/// A theme set laid over a freeform scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneThemes {
    /// The theme set, relative to the scene file (its map must not need a height map: an
    /// `Image` or `Polygons` map, or `Rules` naming one).
    pub file: String,
    pub projection: ThemeProjection,
}

/// How a point of a surface finds its place on the index map.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ThemeProjection {
    /// Straight down (−y) onto the rectangle `min`..`max` of the xz plane: u along x, v along z.
    Planar { min: [f64; 2], max: [f64; 2] },
    /// Longitude and latitude around `centre` (y up), as a sphere carrier's shape texture maps
    /// them (equirectangular): u = (atan2(z, x) + π)/2π, v = θ/π with θ from +y.
    Spherical { centre: [f64; 3] },
}

impl ThemeProjection {
    /// Check the numbers.
    pub fn check(&self) -> std::result::Result<(), String> {
        match *self {
            ThemeProjection::Planar { min, max } => {
                let finite = min.iter().chain(&max).all(|v| v.is_finite());
                if finite && min[0] < max[0] && min[1] < max[1] {
                    Ok(())
                } else {
                    Err(format!(
                        "themes: a planar projection needs finite min < max, got {min:?}..{max:?}"
                    ))
                }
            }
            ThemeProjection::Spherical { centre } => {
                if centre.iter().all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err(format!(
                        "themes: the sphere's centre must be finite, got {centre:?}"
                    ))
                }
            }
        }
    }

    /// The f32 view the shaders use: (kind 1 planar / 2 spherical, four numbers).
    pub fn packed(&self) -> (u32, [f32; 4]) {
        match *self {
            ThemeProjection::Planar { min, max } => (
                1,
                [min[0] as f32, min[1] as f32, max[0] as f32, max[1] as f32],
            ),
            ThemeProjection::Spherical { centre } => (
                2,
                [centre[0] as f32, centre[1] as f32, centre[2] as f32, 0.0],
            ),
        }
    }
}

fn default_background() -> [f64; 3] {
    [0.55, 0.65, 0.8]
}
fn default_ambient() -> f64 {
    0.15
}

/// A pinhole camera: eye, target, vertical field of view in degrees. `near`/`far` bound the
/// depth searched (defaults: 1e-3 and 1e3 times the eye–target distance).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FreeformCamera {
    pub eye: [f64; 3],
    pub target: [f64; 3],
    #[serde(default = "default_fov")]
    pub fov: f64,
    #[serde(default)]
    pub near: Option<f64>,
    #[serde(default)]
    pub far: Option<f64>,
}

fn default_fov() -> f64 {
    45.0
}

/// Sun azimuth (degrees clockwise from north, −z in this y-up space) and elevation.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SunAngles {
    pub azimuth: f64,
    pub elevation: f64,
}

/// A node of the CSG tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    Surface(Box<Surface>),
    /// A shape texture: a height grid displacing a carrier surface along its normal.
    Textured(Box<TexturedSurface>),
    /// Points inside any child (`min` of the fields).
    Union(Vec<Shape>),
    /// Points inside every child (`max`).
    Intersection(Vec<Shape>),
    /// Points inside the first and outside the second (`max(a, −b)`).
    Difference(Box<Shape>, Box<Shape>),
}

/// A base quadric, its placement, its perturbations and its colour.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Surface {
    pub base: Quadric,
    #[serde(default)]
    pub transform: Transform,
    #[serde(default)]
    pub perturbations: Vec<Perturbation>,
    /// Diffuse albedo, linear RGB in [0, 1].
    #[serde(default = "default_color")]
    pub color: [f64; 3],
    /// Phong specular weight in [0, 1] (exponent 32).
    #[serde(default = "default_specular")]
    pub specular: f64,
}

pub(super) fn default_color() -> [f64; 3] {
    [0.7, 0.7, 0.7]
}
pub(super) fn default_specular() -> f64 {
    0.15
}

/// `gᵢ · max(−shape(x), 0)³`: acts inside `shape`; negative `weight` raises the surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Perturbation {
    pub shape: Quadric,
    #[serde(default)]
    pub transform: Transform,
    pub weight: f64,
}

/// A quadric in its own frame; negative inside. Axes of revolution are +y.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Quadric {
    /// `n·x − offset` (n normalised): solid below the plane.
    Plane { normal: [f64; 3], offset: f64 },
    /// `|x|²/r² − 1`.
    Sphere { radius: f64 },
    /// `x²/a² + y²/b² + z²/c² − 1`.
    Ellipsoid { radii: [f64; 3] },
    /// `(x² + z²)/r² − 1`, infinite along y.
    Cylinder { radius: f64 },
    /// `(x² + z²) − tan²(half_angle)·y²`: the double cone, apex at the origin.
    Cone { half_angle: f64 },
    /// `(x² + z²)/r² − y/h`: opens toward +y, radius r at height h.
    Paraboloid { radius: f64, height: f64 },
    /// One sheet: `(x² + z²)/r² − y²/h² − 1`; two sheets: `−(x² + z²)/r² + y²/h² − 1`
    /// (solid inside the two bowls).
    Hyperboloid {
        radius: f64,
        height: f64,
        #[serde(default = "one")]
        sheets: u8,
    },
    /// `[x 1]ᵀ Q [x 1]` for a symmetric 4×4 `Q` (rows).
    General { matrix: [[f64; 4]; 4] },
}

fn one() -> u8 {
    1
}

/// Object → world placement: `T · Rz · Ry · Rx · S`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transform {
    #[serde(default)]
    pub translate: [f64; 3],
    /// Degrees about x, then y, then z.
    #[serde(default)]
    pub rotate: [f64; 3],
    #[serde(default = "unit_scale")]
    pub scale: [f64; 3],
}

fn unit_scale() -> [f64; 3] {
    [1.0; 3]
}

impl Default for Transform {
    fn default() -> Self {
        Transform {
            translate: [0.0; 3],
            rotate: [0.0; 3],
            scale: [1.0; 3],
        }
    }
}

const FREEFORM_FORMAT: RonFormat = RonFormat {
    reference: "docs/freeform.md",
    planned: &[],
    variant_word: "shape",
    variant_enum: "Shape",
};

impl FreeformScene {
    /// Read and check a scene file.
    pub fn load(path: &Path) -> Result<FreeformScene> {
        let text = std::fs::read_to_string(path).at(path, "cannot read freeform scene")?;
        FreeformScene::parse(path, &text)
    }

    /// Parse and check scene text; `path` only names the file in messages.
    pub fn parse(path: &Path, text: &str) -> Result<FreeformScene> {
        let options = ron::Options::default().with_default_extension(
            Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES,
        );
        let scene: FreeformScene = options
            .from_str(text)
            .map_err(|e| located(path, text, e, &FREEFORM_FORMAT))?;
        scene.check().map_err(|m| Error::input(path, m))?;
        Ok(scene)
    }

    /// The number of surfaces (leaves) and of perturbations over all of them.
    pub fn counts(&self) -> (usize, usize) {
        let mut leaves = Vec::new();
        self.shape.surfaces(&mut leaves);
        (
            leaves.len(),
            leaves.iter().map(|s| s.perturbations.len()).sum(),
        )
    }

    fn check(&self) -> std::result::Result<(), String> {
        if let Some(t) = &self.themes {
            t.projection.check()?;
        }
        if let Some(a) = &self.air {
            a.check()?;
        }
        let mut leaves = Vec::new();
        self.shape.surfaces(&mut leaves);
        self.shape.check_arity()?;
        for (i, s) in leaves.iter().enumerate() {
            let at = format!("surface {} (in file order)", i + 1);
            s.base.check().map_err(|m| format!("{at}: base: {m}"))?;
            s.transform
                .check()
                .map_err(|m| format!("{at}: transform: {m}"))?;
            if s.perturbations.len() > MAX_PERTURBATIONS {
                return Err(format!(
                    "{at}: {} perturbations, more than the supported {MAX_PERTURBATIONS}",
                    s.perturbations.len()
                ));
            }
            for (j, p) in s.perturbations.iter().enumerate() {
                let at = format!("{at}, perturbation {}", j + 1);
                p.shape.check().map_err(|m| format!("{at}: shape: {m}"))?;
                p.transform
                    .check()
                    .map_err(|m| format!("{at}: transform: {m}"))?;
                if !p.weight.is_finite() {
                    return Err(format!("{at}: weight must be finite, got {}", p.weight));
                }
            }
            if !s.color.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(format!("{at}: color must be in [0, 1], got {:?}", s.color));
            }
            if !(0.0..=1.0).contains(&s.specular) {
                return Err(format!(
                    "{at}: specular must be in [0, 1], got {}",
                    s.specular
                ));
            }
        }
        let mut textured = Vec::new();
        self.shape.textured(&mut textured);
        for (i, t) in textured.iter().enumerate() {
            t.check()
                .map_err(|m| format!("shape texture {} (in file order): {m}", i + 1))?;
        }
        if let Some(c) = &self.camera {
            finite3(&c.eye).map_err(|m| format!("camera eye: {m}"))?;
            finite3(&c.target).map_err(|m| format!("camera target: {m}"))?;
            if c.eye == c.target {
                return Err("camera eye and target are the same point".into());
            }
            if !(c.fov > 0.0 && c.fov < 180.0) {
                return Err(format!(
                    "camera fov must be in (0, 180) degrees, got {}",
                    c.fov
                ));
            }
            let near = c.near.unwrap_or(1.0);
            let far = c.far.unwrap_or(f64::MAX);
            if !(near > 0.0 && near.is_finite() && far > near) {
                return Err(format!(
                    "camera near/far must satisfy 0 < near < far, got {:?}/{:?}",
                    c.near, c.far
                ));
            }
        }
        if let Some(s) = &self.sun {
            if !s.azimuth.is_finite() || !(-90.0..=90.0).contains(&s.elevation) {
                return Err(format!(
                    "sun needs a finite azimuth and an elevation in [-90, 90], got {}/{}",
                    s.azimuth, s.elevation
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.ambient) {
            return Err(format!("ambient must be in [0, 1], got {}", self.ambient));
        }
        Ok(())
    }
}

impl Shape {
    /// The surfaces in file order (depth first, left to right).
    pub fn surfaces<'a>(&'a self, out: &mut Vec<&'a Surface>) {
        match self {
            Shape::Surface(s) => out.push(s),
            Shape::Textured(_) => {}
            Shape::Union(c) | Shape::Intersection(c) => c.iter().for_each(|c| c.surfaces(out)),
            Shape::Difference(a, b) => {
                a.surfaces(out);
                b.surfaces(out);
            }
        }
    }

    /// The shape textures of the tree, in file order.
    pub fn textured<'a>(&'a self, out: &mut Vec<&'a TexturedSurface>) {
        match self {
            Shape::Textured(t) => out.push(t),
            Shape::Surface(_) => {}
            Shape::Union(c) | Shape::Intersection(c) => c.iter().for_each(|c| c.textured(out)),
            Shape::Difference(a, b) => {
                a.textured(out);
                b.textured(out);
            }
        }
    }

    /// The shape textures of the tree, mutable (the loader resolves their files).
    pub fn textured_mut(&mut self) -> Vec<&mut TexturedSurface> {
        match self {
            Shape::Textured(t) => vec![t],
            Shape::Surface(_) => Vec::new(),
            Shape::Union(c) | Shape::Intersection(c) => {
                c.iter_mut().flat_map(Shape::textured_mut).collect()
            }
            Shape::Difference(a, b) => {
                let mut v = a.textured_mut();
                v.extend(b.textured_mut());
                v
            }
        }
    }

    fn check_arity(&self) -> std::result::Result<(), String> {
        match self {
            Shape::Surface(_) | Shape::Textured(_) => Ok(()),
            Shape::Union(c) | Shape::Intersection(c) => {
                if c.is_empty() {
                    return Err("a Union or Intersection needs at least one child".into());
                }
                c.iter().try_for_each(Shape::check_arity)
            }
            Shape::Difference(a, b) => {
                a.check_arity()?;
                b.check_arity()
            }
        }
    }
}

pub(super) fn finite3(v: &[f64; 3]) -> std::result::Result<(), String> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(format!("must be finite, got {v:?}"))
    }
}

pub(super) fn positive(name: &str, v: f64) -> std::result::Result<(), String> {
    if v > 0.0 && v.is_finite() {
        Ok(())
    } else {
        Err(format!("{name} must be a positive finite number, got {v}"))
    }
}

impl Quadric {
    fn check(&self) -> std::result::Result<(), String> {
        match self {
            Quadric::Plane { normal, offset } => {
                finite3(normal)?;
                if normal.iter().map(|x| x * x).sum::<f64>() < 1e-24 {
                    return Err("plane normal must not be zero".into());
                }
                if !offset.is_finite() {
                    return Err(format!("plane offset must be finite, got {offset}"));
                }
                Ok(())
            }
            Quadric::Sphere { radius } | Quadric::Cylinder { radius } => {
                positive("radius", *radius)
            }
            Quadric::Ellipsoid { radii } => radii.iter().try_for_each(|r| positive("radii", *r)),
            Quadric::Cone { half_angle } => {
                if *half_angle > 0.0 && *half_angle < 90.0 {
                    Ok(())
                } else {
                    Err(format!(
                        "cone half_angle must be in (0, 90) degrees, got {half_angle}"
                    ))
                }
            }
            Quadric::Paraboloid { radius, height } => {
                positive("radius", *radius)?;
                positive("height", *height)
            }
            Quadric::Hyperboloid {
                radius,
                height,
                sheets,
            } => {
                positive("radius", *radius)?;
                positive("height", *height)?;
                if *sheets == 1 || *sheets == 2 {
                    Ok(())
                } else {
                    Err(format!("hyperboloid sheets must be 1 or 2, got {sheets}"))
                }
            }
            Quadric::General { matrix } => {
                for (i, row) in matrix.iter().enumerate() {
                    for (j, v) in row.iter().enumerate() {
                        if !v.is_finite() {
                            return Err(format!("matrix[{i}][{j}] must be finite, got {v}"));
                        }
                        let w = matrix[j][i];
                        if (v - w).abs() > 1e-12 * v.abs().max(w.abs()).max(1.0) {
                            return Err(format!(
                                "matrix must be symmetric: [{i}][{j}] = {v} but [{j}][{i}] = {w}"
                            ));
                        }
                    }
                }
                Ok(())
            }
        }
    }
}

impl Transform {
    fn check(&self) -> std::result::Result<(), String> {
        finite3(&self.translate)?;
        finite3(&self.rotate)?;
        for s in self.scale {
            if !(s.is_finite() && s.abs() > 1e-12) {
                return Err(format!(
                    "scale must be finite and non-zero, got {:?}",
                    self.scale
                ));
            }
        }
        Ok(())
    }
}
