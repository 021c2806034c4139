//! Punctual lights declared outside the scene file — in a pipeline's `Scene(lights: [...])` or
//! with `relume-player --light` — in world units (after the input's `scale`) and
//! KHR_lights_punctual semantics. [`LightSpec::to_light`] checks every value and gives the same
//! [`Light`] a glTF file would.
//!
//! ```ron
//! lights: [
//!     Point(position: (0.28, 0.4, 0.2), intensity: 0.05, color: (1.0, 0.8, 0.6)),
//!     Spot(position: (0.278, 0.273, -0.5), direction: (0, 0, 1), angle: 10, intensity: 0.5),
//!     Directional(direction: (0, -1, 1)),
//! ]
//! ```

use super::{Light, LightKind};
use serde::{Deserialize, Serialize};

/// A light as a pipeline or command line states it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum LightSpec {
    /// Light from `position` in all directions; `intensity` in candela (default 1).
    Point {
        position: [f32; 3],
        #[serde(default = "one")]
        intensity: f32,
        #[serde(default = "white")]
        color: [f32; 3],
    },
    /// A point light restricted to a cone of half-angle `angle` degrees around `direction` (the
    /// inner, full-strength cone is 80 % of it); `intensity` in candela (default 1).
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        angle: f32,
        #[serde(default = "one")]
        intensity: f32,
        #[serde(default = "white")]
        color: [f32; 3],
    },
    /// Light travelling along `direction` from infinitely far; `intensity` in lux (default 3, the
    /// player's sun).
    Directional {
        direction: [f32; 3],
        #[serde(default = "three")]
        intensity: f32,
        #[serde(default = "white")]
        color: [f32; 3],
    },
}

fn one() -> f32 {
    1.0
}
fn three() -> f32 {
    3.0
}
fn white() -> [f32; 3] {
    [1.0; 3]
}

impl LightSpec {
    /// The light, named `name`; the error says which value is out of range.
    pub fn to_light(&self, name: &str) -> Result<Light, String> {
        let (kind, position, direction, intensity, color) = match *self {
            LightSpec::Point {
                position,
                intensity,
                color,
            } => (
                LightKind::Point,
                position,
                [0.0, -1.0, 0.0],
                intensity,
                color,
            ),
            LightSpec::Spot {
                position,
                direction,
                angle,
                intensity,
                color,
            } => {
                if !(angle > 0.0 && angle <= 90.0) {
                    return Err(format!(
                        "the spot's cone half-angle must be in (0, 90] degrees, got {angle}"
                    ));
                }
                let outer = angle.to_radians();
                let kind = LightKind::Spot {
                    inner_cone: 0.8 * outer,
                    outer_cone: outer,
                };
                (kind, position, direction, intensity, color)
            }
            LightSpec::Directional {
                direction,
                intensity,
                color,
            } => (
                LightKind::Directional,
                [0.0; 3],
                direction,
                intensity,
                color,
            ),
        };
        if position.iter().any(|v| !v.is_finite()) {
            return Err(format!("position {position:?} is not finite"));
        }
        let d = glam::Vec3::from(direction);
        let len = d.length();
        if !(len.is_finite() && len > 1e-12) {
            return Err(format!("direction {direction:?} has no length"));
        }
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(format!(
                "intensity must be a finite number ≥ 0, got {intensity}"
            ));
        }
        if color.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(format!(
                "colour components must be finite and ≥ 0, got {color:?}"
            ));
        }
        Ok(Light {
            name: name.into(),
            kind,
            position,
            direction: (d / len).to_array(),
            color,
            intensity,
            range: None,
        })
    }
}
