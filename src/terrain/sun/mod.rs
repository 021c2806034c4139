//! The sun and its track through a height map (docs/algorithms.md §4, §9).
//!
//! Convention: azimuth in degrees clockwise from north (+y, toward row 0), elevation in degrees
//! above the horizon; the unit vector toward the sun is (sin az · cos el, cos az · cos el, sin el)
//! in height-map (x east, y north, z up) space. In texel space (x = column, y = row, rows go
//! south) the track of a pixel P at texel position p is the half-line p + u·t, t ≥ 0, with
//! u = normalise(sin az / cell_x, −cos az / cell_y). The sun ray above the track rises
//! `rise_per_t` metres per unit of t (tan el × world metres per unit of t).

pub mod solar;
pub mod spec;

use crate::error::{Error, Result};

/// Components of `u` smaller than this (in absolute value) are snapped to exactly 0 and the
/// other component to ±1: the track is then axis-aligned. Over a 2^24-texel map the snapped
/// track deviates from the true one by less than 2e-5 texels.
pub const AXIS_SNAP: f64 = 1e-12;

/// The sun as a direction: azimuth and elevation in degrees. The one sun model of relume: the
/// terrain kernels use its f64 direction, the GPU its f32 view [`Sun::toward_y_up`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Sun {
    /// Degrees clockwise from north (any finite value; wrapped).
    pub azimuth_deg: f64,
    /// Degrees above the horizon, in [−90, 90].
    pub elevation_deg: f64,
}

impl Sun {
    /// A sun direction; refuses non-finite angles and elevations outside [−90, 90].
    pub fn new(azimuth_deg: f64, elevation_deg: f64) -> Result<Sun> {
        if !azimuth_deg.is_finite() {
            return Err(Error::knob(format!(
                "sun azimuth must be a finite number of degrees, got {azimuth_deg}"
            )));
        }
        if !(elevation_deg.is_finite() && (-90.0..=90.0).contains(&elevation_deg)) {
            return Err(Error::knob(format!(
                "sun elevation must be in [-90, 90] degrees, got {elevation_deg}"
            )));
        }
        Ok(Sun {
            azimuth_deg,
            elevation_deg,
        })
    }

    /// Unit vector toward the sun in (x east, y north, z up).
    pub fn direction(&self) -> [f64; 3] {
        let (sa, ca) = self.azimuth_deg.to_radians().sin_cos();
        let (se, ce) = self.elevation_deg.to_radians().sin_cos();
        [sa * ce, ca * ce, se]
    }

    /// The same direction in f64: toward the sun in a y-up world whose north is −z (x east, z
    /// south; the terrain frame's world).
    pub fn toward_y_up_f64(&self) -> glam::DVec3 {
        let [x, y, z] = self.direction();
        glam::DVec3::new(x, z, -y)
    }

    /// f32 view for a y-up scene whose north is −z (the player's mesh scenes):
    /// (sin az · cos el, sin el, −cos az · cos el), evaluated in f32.
    pub fn toward_y_up(&self) -> glam::Vec3 {
        let (az, el) = (
            (self.azimuth_deg as f32).to_radians(),
            (self.elevation_deg as f32).to_radians(),
        );
        glam::Vec3::new(az.sin() * el.cos(), el.sin(), -az.cos() * el.cos())
    }

    /// s · up = sin(elevation).
    pub fn up_component(&self) -> f64 {
        self.elevation_deg.to_radians().sin()
    }
}

/// What the sun's position means for a whole map before any traversal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrackKind {
    /// A proper track: 0 < elevation < 90°.
    Ray,
    /// Elevation ≥ 90°: no horizontal track, nothing can shadow (hard shadows: lit).
    Zenith,
    /// Elevation ≤ 0°: the sun is at or below the horizon (hard shadows: shadowed).
    BelowHorizon,
}

/// The per-sun constants every per-pixel kernel uses (the GPU receives the same fields as
/// uniforms, rounded to f32).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Track {
    pub kind: TrackKind,
    /// Unit direction of travel in texel space (x = column, y = row, south).
    pub ux: f64,
    pub uy: f64,
    /// Sign of `ux` / `uy` as a texel step: −1, 0 (axis-aligned) or +1.
    pub step_x: i64,
    pub step_y: i64,
    /// 1/ux and 1/uy (0 for a zero component; never used then).
    pub inv_ux: f64,
    pub inv_uy: f64,
    /// World horizontal metres per unit of t.
    pub metres_per_t: f64,
    /// tan(elevation) (0 for `Zenith`/`BelowHorizon`).
    pub tan_elevation: f64,
    /// Metres the sun ray rises per unit of t: tan(el) × metres_per_t.
    pub rise_per_t: f64,
    /// Elevation in radians.
    pub elevation: f64,
}

impl Track {
    /// The track of `sun` over a map with the given cell size (metres per texel, x and y).
    pub fn new(sun: &Sun, cell_size: [f64; 2]) -> Track {
        let elevation = sun.elevation_deg.to_radians();
        let (sa, ca) = sun.azimuth_deg.to_radians().sin_cos();
        let vx = sa / cell_size[0];
        let vy = -ca / cell_size[1];
        let n = vx.hypot(vy);
        let (mut ux, mut uy) = (vx / n, vy / n);
        if ux.abs() < AXIS_SNAP {
            ux = 0.0;
            uy = uy.signum();
        } else if uy.abs() < AXIS_SNAP {
            uy = 0.0;
            ux = ux.signum();
        }
        let metres_per_t = (ux * cell_size[0]).hypot(uy * cell_size[1]);
        let kind = if sun.elevation_deg <= 0.0 {
            TrackKind::BelowHorizon
        } else if sun.elevation_deg >= 90.0 {
            TrackKind::Zenith
        } else {
            TrackKind::Ray
        };
        let tan_elevation = if kind == TrackKind::Ray {
            elevation.tan()
        } else {
            0.0
        };
        let step = |u: f64| {
            if u > 0.0 {
                1
            } else if u < 0.0 {
                -1
            } else {
                0
            }
        };
        let inv = |u: f64| if u == 0.0 { 0.0 } else { 1.0 / u };
        Track {
            kind,
            ux,
            uy,
            step_x: step(ux),
            step_y: step(uy),
            inv_ux: inv(ux),
            inv_uy: inv(uy),
            metres_per_t,
            tan_elevation,
            rise_per_t: tan_elevation * metres_per_t,
            elevation,
        }
    }

    /// The t at which the track from texel centre coordinate `p` (x or y) crosses the grid
    /// line `boundary` of the same axis: (boundary − p) · inv_u. Every traversal computes event
    /// times with this one expression, so that texel, block and map-border events agree bit for
    /// bit. For an axis with step 0 the caller must not ask (the event never happens).
    #[inline]
    pub fn crossing(p: f64, boundary: i64, inv_u: f64) -> f64 {
        (boundary as f64 - p) * inv_u
    }

    /// Time at which the track leaves column `c` (or row; pass the axis' values):
    /// +∞ when the axis does not move.
    #[inline]
    pub fn exit_time(p: f64, c: i64, step: i64, inv_u: f64) -> f64 {
        if step > 0 {
            Self::crossing(p, c + 1, inv_u)
        } else if step < 0 {
            Self::crossing(p, c, inv_u)
        } else {
            f64::INFINITY
        }
    }

    /// Time at which the track enters column `c` (−∞ when the axis does not move; negative for
    /// the start column).
    #[inline]
    pub fn entry_time(p: f64, c: i64, step: i64, inv_u: f64) -> f64 {
        if step > 0 {
            Self::crossing(p, c, inv_u)
        } else if step < 0 {
            Self::crossing(p, c + 1, inv_u)
        } else {
            f64::NEG_INFINITY
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_follows_the_convention() {
        let east = Sun::new(90.0, 0.0).unwrap().direction();
        assert!((east[0] - 1.0).abs() < 1e-12 && east[1].abs() < 1e-12);
        let north_high = Sun::new(0.0, 30.0).unwrap().direction();
        assert!((north_high[1] - 30f64.to_radians().cos()).abs() < 1e-12);
        assert!((north_high[2] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn track_points_toward_row_zero_for_a_northern_sun() {
        let t = Track::new(&Sun::new(0.0, 10.0).unwrap(), [30.0, 30.0]);
        assert_eq!((t.ux, t.uy, t.step_x, t.step_y), (0.0, -1.0, 0, -1));
        assert_eq!(t.metres_per_t, 30.0);
        let t = Track::new(&Sun::new(90.0, 10.0).unwrap(), [30.0, 10.0]);
        assert_eq!((t.ux, t.uy, t.step_x, t.step_y), (1.0, 0.0, 1, 0));
        // Anisotropic cells bend the texel-space direction of a diagonal sun.
        let t = Track::new(&Sun::new(45.0, 10.0).unwrap(), [1.0, 2.0]);
        assert!(t.ux > 0.0 && t.uy < 0.0 && t.ux > -t.uy);
    }

    #[test]
    fn bad_angles_are_refused() {
        assert!(Sun::new(f64::NAN, 10.0).is_err());
        assert!(Sun::new(0.0, 91.0).is_err());
        assert!(Sun::new(0.0, -90.0).is_ok());
    }
}
