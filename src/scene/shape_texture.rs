//! Shape textures in a freeform scene (`Shape::Textured`): a height grid over a carrier surface
//! (plane or sphere), plain data as read from the RON file. `freeform::texture` evaluates and
//! bounds them; `load::freeform_scene` replaces file grids by their samples.

use super::freeform::{default_color, default_specular, finite3, positive};
use serde::{Deserialize, Serialize};

/// A shape texture (the "shape textures" of Vyatkin et al. 2018): the carrier surface displaced
/// along its unit normal by `height_scale ×` the bilinear interpolation of a height grid,
/// optionally morphed toward a second grid. Solid is below the displaced surface. Only the
/// deviation from the carrier is stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TexturedSurface {
    pub carrier: Carrier,
    pub heights: HeightGrid,
    /// A second grid of the same size: the surface at morph parameter s ∈ [0, 1] uses
    /// `(1 − s)·heights + s·morph_to`.
    #[serde(default)]
    pub morph_to: Option<HeightGrid>,
    /// World units per grid unit.
    #[serde(default = "unit")]
    pub height_scale: f64,
    /// Level of detail: the grid box-filtered 2^lod × 2^lod before use (0: full detail).
    #[serde(default)]
    pub lod: u32,
    #[serde(default = "default_color")]
    pub color: [f64; 3],
    #[serde(default = "default_specular")]
    pub specular: f64,
}

fn unit() -> f64 {
    1.0
}

/// The surface a shape texture displaces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Carrier {
    /// A rectangle: grid sample (i, j) of a W×H grid sits at
    /// `origin + u_axis·size[0]·i/(W−1) + v_axis·size[1]·j/(H−1)`; the normal is
    /// `u_axis × v_axis` (the axes must be orthogonal); outside the rectangle the edge heights
    /// continue.
    Plane {
        origin: [f64; 3],
        u_axis: [f64; 3],
        v_axis: [f64; 3],
        size: [f64; 2],
    },
    /// A sphere, the grid an equirectangular map: column i at longitude
    /// −180° + (i + ½)·360°/W (atan2(z, x)), row j at latitude 90° − (j + ½)·180°/H.
    Sphere { centre: [f64; 3], radius: f64 },
    /// A cylinder about the vertical axis through `base` (the quadric x² + z² = r² there): the
    /// grid wraps around it, column i at angle −180° + (i + ½)·360°/W (atan2(z, x)), row j at
    /// height `base.y + length·j/(H−1)`; beyond the ends the end rows' heights continue. Other
    /// orientations: rotate the scene's camera and sun instead (the carrier stays upright).
    Cylinder {
        base: [f64; 3],
        radius: f64,
        length: f64,
    },
}

/// Heights of a shape texture: inline, or a height map file (any format `relume-bake` reads for
/// terrain), relative to the scene file, box-filtered by `downsample`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum HeightGrid {
    Grid {
        width: usize,
        height: usize,
        values: Vec<f32>,
    },
    File {
        path: String,
        #[serde(default)]
        downsample: u32,
    },
}

impl HeightGrid {
    fn check(&self) -> std::result::Result<(), String> {
        match self {
            HeightGrid::Grid {
                width,
                height,
                values,
            } => {
                if *width < 2 || *height < 2 {
                    return Err(format!(
                        "a height grid needs at least 2x2 samples, got {width}x{height}"
                    ));
                }
                if values.len() != width * height {
                    return Err(format!(
                        "a {width}x{height} height grid needs {} values, got {}",
                        width * height,
                        values.len()
                    ));
                }
                if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                    return Err(format!("height value {} is not finite", i + 1));
                }
                Ok(())
            }
            HeightGrid::File { path, downsample } => {
                if path.is_empty() {
                    return Err("a height grid file needs a path".into());
                }
                if *downsample > 64 {
                    return Err(format!("downsample must be at most 64, got {downsample}"));
                }
                Ok(())
            }
        }
    }

    /// (width, height) of an inline grid.
    pub fn size(&self) -> Option<(usize, usize)> {
        match self {
            HeightGrid::Grid { width, height, .. } => Some((*width, *height)),
            HeightGrid::File { .. } => None,
        }
    }
}

impl TexturedSurface {
    /// Check the values (the loader checks again once file grids are read).
    pub fn check(&self) -> std::result::Result<(), String> {
        match &self.carrier {
            Carrier::Plane {
                origin,
                u_axis,
                v_axis,
                size,
            } => {
                finite3(origin).map_err(|m| format!("carrier origin {m}"))?;
                let len = |v: &[f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let (lu, lv) = (len(u_axis), len(v_axis));
                if !(lu > 0.0 && lu.is_finite() && lv > 0.0 && lv.is_finite()) {
                    return Err("carrier u_axis and v_axis must be finite and non-zero".into());
                }
                let cos = (u_axis[0] * v_axis[0] + u_axis[1] * v_axis[1] + u_axis[2] * v_axis[2])
                    / (lu * lv);
                if cos.abs() > 1e-9 {
                    return Err(format!(
                        "carrier u_axis and v_axis must be orthogonal (cosine {cos:.3e})"
                    ));
                }
                positive("carrier size[0]", size[0])?;
                positive("carrier size[1]", size[1])?;
            }
            Carrier::Sphere { centre, radius } => {
                finite3(centre).map_err(|m| format!("carrier centre {m}"))?;
                positive("carrier radius", *radius)?;
            }
            Carrier::Cylinder {
                base,
                radius,
                length,
            } => {
                finite3(base).map_err(|m| format!("carrier base {m}"))?;
                positive("carrier radius", *radius)?;
                positive("carrier length", *length)?;
            }
        }
        self.heights.check().map_err(|m| format!("heights: {m}"))?;
        if let Some(m) = &self.morph_to {
            m.check().map_err(|m| format!("morph_to: {m}"))?;
            if let (Some(a), Some(b)) = (self.heights.size(), m.size()) {
                if a != b {
                    return Err(format!(
                        "morph_to is {}x{}, heights {}x{}: a morph needs grids of one size",
                        b.0, b.1, a.0, a.1
                    ));
                }
            }
        }
        if !(self.height_scale.is_finite() && self.height_scale != 0.0) {
            return Err(format!(
                "height_scale must be finite and non-zero, got {}",
                self.height_scale
            ));
        }
        if self.lod > 12 {
            return Err(format!("lod must be at most 12, got {}", self.lod));
        }
        if !self.color.iter().all(|c| (0.0..=1.0).contains(c)) {
            return Err(format!("color must be in [0, 1], got {:?}", self.color));
        }
        if !(0.0..=1.0).contains(&self.specular) {
            return Err(format!("specular must be in [0, 1], got {}", self.specular));
        }
        Ok(())
    }
}
