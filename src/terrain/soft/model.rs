//! The soft-shadow model (docs/algorithms.md §5; the soft-shadow paper §3.1 and §3.4): one ray from P toward the
//! centre of the sun disc; the most occluding point on the track decides how much of the disc
//! is visible, assuming the occluder is a prism across the ray (exact for a straight wall).
//!
//! **Occluder angle.** A terrain sample Q at height h and horizontal distance d from P is seen
//! from P at the elevation angle β = atan(slope) with
//!
//! ```text
//!   flat ground:           slope = (h − z_P) / d
//!   planet of radius R:    φ = d / R,
//!                          slope = ((h − z_P) − (R + h)·2 sin²(φ/2)) / ((R + h)·sin φ)
//! ```
//!
//! (the second is the exact elevation of Q above P's horizontal plane when the map is wrapped on
//! the sphere with d as arc length; it tends to the first as R → ∞, and it is the same geometry
//! as DESIGN's curved ray height: the ray rises faster than the ground). The angle of Q below the
//! sun's centre is θ = e_P − β, exactly (atan, not the small-angle δ/t). Every method finds the
//! largest slope over its samples, `best`, starting from 0 — P's own horizontal plane, so a
//! sun below the local horizon is occluded — and θ* = e_P − atan(best).
//!
//! **Lit fraction.** With d = clamp(θ*/α, −1, 1) and α the sun's angular radius:
//! lit(d) = 1 − (acos d − d·√(1 − d²))/π — the disc's area above a horizontal edge d radii
//! below its centre (lit(1) = 1, lit(0) = ½, lit(−1) = 0).
//!
//! **Curved terrain, per pixel.** On a planet the sun's azimuth and elevation are given at the
//! map's centre; pixel P, at horizontal offset a (metres) from the centre, has its vertical tilted
//! by |a|/R, so its own sun elevation is sin e_P = sin e·cos(|a|/R) + cos e·sin(|a|/R)·(ŝ_h·â)
//! (exact on the sphere). The track direction stays the centre's (the azimuth changes only to
//! second order across a map that is small against R).
//!
//! Precision: f64 throughout; an f32 port must keep `(R + h)` products in the factored form
//! above (no `sqrt(...) − R` cancellation) and can evaluate `atan` once per pixel.

use crate::terrain::sun::Sun;

/// Default angular radius of the Sun, degrees.
pub const SUN_RADIUS_DEG: f64 = 0.2666;

/// lit(d) = 1 − (acos d − d·√(1 − d²))/π for d clamped to [−1, 1].
pub fn lit(d: f64) -> f64 {
    let d = d.clamp(-1.0, 1.0);
    1.0 - (d.acos() - d * (1.0 - d * d).max(0.0).sqrt()) / std::f64::consts::PI
}

/// Slope (tan of the elevation angle) of a terrain point of height `h` at horizontal distance
/// `d` > 0 metres, seen from height `zp`; `radius` = planet radius in metres (∞ = flat).
#[inline]
pub fn slope(h: f64, zp: f64, d: f64, radius: f64) -> f64 {
    if radius.is_infinite() {
        (h - zp) / d
    } else {
        let phi = d / radius;
        let s = (0.5 * phi).sin();
        ((h - zp) - (radius + h) * 2.0 * s * s) / ((radius + h) * phi.sin())
    }
}

/// An upper bound of [`slope`] over heights in [hmin, hmax] and distances in [d_in, d_out]
/// (d_in may be 0: then +∞ when the bound's numerator is positive).
#[inline]
pub fn slope_upper_bound(hmax: f64, hmin: f64, zp: f64, d_in: f64, d_out: f64, radius: f64) -> f64 {
    let (vert, horiz_in, horiz_out) = if radius.is_infinite() {
        (hmax - zp, d_in, d_out)
    } else {
        let phi_in = d_in / radius;
        let s = (0.5 * phi_in).sin();
        (
            (hmax - zp) - (radius + hmax) * 2.0 * s * s,
            (radius + hmin) * phi_in.sin(),
            (radius + hmax) * (d_out / radius).sin(),
        )
    };
    if vert >= 0.0 {
        if horiz_in > 0.0 {
            vert / horiz_in
        } else {
            f64::INFINITY
        }
    } else {
        vert / horiz_out
    }
}

/// True when no sample at distance ≥ `d_in` with a height in [hmin, hmax] can have a slope
/// above `best` (≥ 0): every method stops its track there ("the ray has left the terrain
/// volume").
#[inline]
pub fn beyond_reach(hmax: f64, hmin: f64, zp: f64, d_in: f64, radius: f64, best: f64) -> bool {
    let (vert, horiz_in) = if radius.is_infinite() {
        (hmax - zp, d_in)
    } else {
        let phi_in = d_in / radius;
        let s = (0.5 * phi_in).sin();
        (
            (hmax - zp) - (radius + hmax) * 2.0 * s * s,
            (radius + hmin) * phi_in.sin(),
        )
    };
    vert < 0.0 || (horiz_in > 0.0 && vert / horiz_in <= best)
}

/// The sun as one pixel sees it, and the thresholds every method prunes with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSun {
    /// Height of P (metres).
    pub zp: f64,
    /// The sun's elevation at P (radians).
    pub elevation: f64,
    /// Sun angular radius α (radians).
    pub alpha: f64,
    /// Planet radius (metres; ∞ = flat).
    pub radius: f64,
    /// Slopes at or below this leave the disc fully visible: tan(e_P − α).
    pub slope_lit: f64,
    /// Slopes at or above this hide the disc completely: tan(e_P + α) (∞ past the zenith).
    pub slope_dark: f64,
    /// The starting value of `best`: max(0, slope_lit) (P's horizontal plane, and nothing that
    /// cannot matter).
    pub best_init: f64,
}

/// Pixel-independent soft-shadow knobs in radians and metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftSun {
    /// Sun at the map's centre.
    pub sun: Sun,
    /// α, radians (> 0).
    pub alpha: f64,
    /// Planet radius, metres (∞ = flat).
    pub radius: f64,
}

impl SoftSun {
    /// The sun seen from texel (col, row) of a `width`×`height` map with `cell_size`.
    pub fn at_pixel(
        &self,
        zp: f64,
        col: usize,
        row: usize,
        width: usize,
        height: usize,
        cell_size: [f64; 2],
    ) -> PixelSun {
        let e0 = self.sun.elevation_deg.to_radians();
        let elevation = if self.radius.is_infinite() {
            e0
        } else {
            let ax = (col as f64 + 0.5 - width as f64 / 2.0) * cell_size[0];
            let ay = -(row as f64 + 0.5 - height as f64 / 2.0) * cell_size[1];
            let len = ax.hypot(ay);
            let (sa, ca) = self.sun.azimuth_deg.to_radians().sin_cos();
            let ang = len / self.radius;
            let along = if len > 0.0 {
                (sa * ax + ca * ay) / len
            } else {
                0.0
            };
            (e0.sin() * ang.cos() + e0.cos() * ang.sin() * along)
                .clamp(-1.0, 1.0)
                .asin()
        };
        let half_pi = std::f64::consts::FRAC_PI_2;
        let slope_lit = (elevation - self.alpha).max(-half_pi + 1e-12).tan();
        let slope_dark = if elevation + self.alpha >= half_pi {
            f64::INFINITY
        } else {
            (elevation + self.alpha).tan()
        };
        PixelSun {
            zp,
            elevation,
            alpha: self.alpha,
            radius: self.radius,
            slope_lit,
            slope_dark,
            best_init: slope_lit.max(0.0),
        }
    }
}

impl PixelSun {
    /// Nothing on the track can change the answer: the sun is below the horizon by at least α
    /// (0) or at the zenith (1).
    pub fn settled(&self) -> Option<f32> {
        if self.elevation <= -self.alpha || self.best_init >= self.slope_dark {
            Some(0.0)
        } else if self.elevation >= std::f64::consts::FRAC_PI_2 {
            Some(1.0)
        } else {
            None
        }
    }

    /// The lit fraction for the largest slope found.
    pub fn lit_fraction(&self, best: f64) -> f32 {
        let theta = self.elevation - best.max(0.0).atan();
        lit(theta / self.alpha) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lit_endpoints_and_monotone() {
        assert_eq!(lit(1.0), 1.0);
        assert!((lit(0.0) - 0.5).abs() < 1e-15);
        assert_eq!(lit(-1.0), 0.0);
        assert_eq!(lit(7.0), 1.0);
        assert_eq!(lit(-7.0), 0.0);
        let mut prev = -1.0;
        for i in 0..=2000 {
            let v = lit(-1.0 + i as f64 / 1000.0);
            assert!(v >= prev);
            prev = v;
        }
    }

    #[test]
    fn curved_slope_tends_to_flat() {
        let flat = slope(120.0, 20.0, 1000.0, f64::INFINITY);
        let curved = slope(120.0, 20.0, 1000.0, 1e12);
        assert!((flat - curved).abs() < 1e-9);
        // On the Moon, a point 10 km away at the same height lies below the horizontal.
        assert!(slope(0.0, 0.0, 10_000.0, 1_737_400.0) < 0.0);
    }

    #[test]
    fn bound_covers_samples() {
        for radius in [f64::INFINITY, 6_371_000.0, 1000.0] {
            for (hmax, hmin) in [(50.0, -10.0), (5.0, 1.0), (-20.0, -30.0)] {
                let (d_in, d_out) = (100.0, 400.0);
                let ub = slope_upper_bound(hmax, hmin, 0.0, d_in, d_out, radius);
                for i in 0..=10 {
                    for j in 0..=10 {
                        let h = hmin + (hmax - hmin) * i as f64 / 10.0;
                        let d = d_in + (d_out - d_in) * j as f64 / 10.0;
                        assert!(slope(h, 0.0, d, radius) <= ub + 1e-15, "{radius} {h} {d}");
                    }
                }
            }
        }
    }
}
