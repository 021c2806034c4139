//! Scattered light in the air (aerial perspective and sky): the constant-density fog of Vyatkin
//! et al. (2018) (the model of Hoffman & Preetham 2002), Hillaire 2020's look-up tables
//! (transmittance, multiple scattering, sky view, aerial perspective), and the f64 reference they
//! are measured against (quadrature single scattering plus a Monte Carlo path tracer for every
//! order).
//!
//! Plain data only (layer 3): an [`Atmosphere`] (SI units, metres), positions given as an
//! altitude above the ground sphere, directions in the eye's local frame with **+Y up** (the
//! frame of `terrain::Sun::toward_y_up`). The planet is a sphere of radius
//! [`Atmosphere::ground_radius`] (default 6,371 km, the radius curved terrain uses; Hillaire
//! uses 6,360 km) with the air up to [`Atmosphere::top_radius`] (ground + 100 km).
//!
//! Files: `fog.rs` (constant-density fog, per pixel and per vertex), `frame.rs` (the air's uniform
//! fields of a rendered frame), `reference.rs` (quadrature),
//! `monte_carlo.rs` (path tracer), `twin.rs` (the f32 parameters shared with
//! `shaders/atmosphere.wgsl`, parameterisations, filtering), `lut.rs` (building the tables and
//! the lookups a renderer calls), `study.rs` (error against sun elevation).

pub mod double;
pub mod fog;
pub mod frame;
pub mod lut;
pub mod monte_carlo;
pub mod reference;
pub mod study;
pub mod twin;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which scattered-light model a renderer applies (the player's choice).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// No air: surfaces keep their colour, the sky is black.
    None,
    /// The constant-density fog of Vyatkin et al. (2018) evaluated at vertices and interpolated.
    Fog,
    /// The same model evaluated per pixel.
    FogPerPixel,
    /// Hillaire 2020: look-up tables with multiple scattering; good down to the horizon.
    #[default]
    Hillaire,
}

/// A planet's air: Rayleigh and Mie scattering with exponential profiles, ozone absorption
/// with a tent profile, a Lambertian ground. Coefficients per metre, lengths in metres, RGB.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Atmosphere {
    /// Radius of the ground sphere (m).
    pub ground_radius: f64,
    /// Radius of the top of the air (m).
    pub top_radius: f64,
    /// Rayleigh scattering at the ground (1/m); Rayleigh does not absorb.
    pub rayleigh_scattering: [f64; 3],
    /// Rayleigh scale height (m).
    pub rayleigh_height: f64,
    /// Mie scattering at the ground (1/m).
    pub mie_scattering: [f64; 3],
    /// Mie extinction at the ground (1/m); absorption is extinction − scattering.
    pub mie_extinction: [f64; 3],
    /// Mie scale height (m).
    pub mie_height: f64,
    /// Mie anisotropy g of the Cornette–Shanks phase function.
    pub mie_g: f64,
    /// Ozone absorption at the centre of its layer (1/m).
    pub ozone_absorption: [f64; 3],
    /// Altitude of the centre of the ozone tent (m).
    pub ozone_centre: f64,
    /// Full width of the ozone tent (m): density 1 − |h − centre| / (width / 2), at least 0.
    pub ozone_width: f64,
    /// Lambertian albedo of the ground sphere.
    pub ground_albedo: [f64; 3],
    /// Sun illuminance at the top of the air, normal to the sun (relative units).
    pub sun_illuminance: [f64; 3],
}

impl Default for Atmosphere {
    fn default() -> Self {
        Self::earth()
    }
}

impl Atmosphere {
    /// Earth, as in Hillaire 2020 but on the 6,371 km sphere of curved terrain.
    pub fn earth() -> Atmosphere {
        let ground = 6_371_000.0;
        Atmosphere {
            ground_radius: ground,
            top_radius: ground + 100_000.0,
            rayleigh_scattering: [5.802e-6, 13.558e-6, 33.1e-6],
            rayleigh_height: 8_000.0,
            mie_scattering: [3.996e-6; 3],
            mie_extinction: [4.40e-6; 3],
            mie_height: 1_200.0,
            mie_g: 0.8,
            ozone_absorption: [0.650e-6, 1.881e-6, 0.085e-6],
            ozone_centre: 25_000.0,
            ozone_width: 30_000.0,
            ground_albedo: [0.3; 3],
            sun_illuminance: [1.0; 3],
        }
    }

    /// The same air with every scattering coefficient zero (absorption stays).
    pub fn without_scattering(&self) -> Atmosphere {
        let mut a = *self;
        a.rayleigh_scattering = [0.0; 3];
        for c in 0..3 {
            a.mie_extinction[c] -= a.mie_scattering[c];
        }
        a.mie_scattering = [0.0; 3];
        a
    }

    /// Altitude (m) of a point given relative to the planet's centre.
    pub fn altitude(&self, p: DVec3) -> f64 {
        p.length() - self.ground_radius
    }

    /// The medium at altitude `h` (m).
    pub fn medium(&self, h: f64) -> Medium {
        let (r, m, o) = densities(self, h);
        let mut out = Medium::default();
        for c in 0..3 {
            out.rayleigh[c] = self.rayleigh_scattering[c] * r;
            out.mie[c] = self.mie_scattering[c] * m;
            out.extinction[c] = self.rayleigh_scattering[c] * r
                + self.mie_extinction[c] * m
                + self.ozone_absorption[c] * o;
        }
        out
    }

    /// The largest extinction anywhere in the shell, per channel (a majorant for tracking).
    pub fn max_extinction(&self) -> [f64; 3] {
        let o = if self.ozone_centre - self.ozone_width / 2.0 < self.top_radius {
            1.0
        } else {
            0.0
        };
        std::array::from_fn(|c| {
            self.rayleigh_scattering[c] + self.mie_extinction[c] + self.ozone_absorption[c] * o
        })
    }
}

/// Relative densities (Rayleigh, Mie, ozone) at altitude `h` metres (clamped at the ground).
pub fn densities(atm: &Atmosphere, h: f64) -> (f64, f64, f64) {
    let h = h.max(0.0);
    let r = (-h / atm.rayleigh_height).exp();
    let m = (-h / atm.mie_height).exp();
    let o = (1.0 - (h - atm.ozone_centre).abs() / (0.5 * atm.ozone_width)).max(0.0);
    (r, m, o)
}

/// Scattering and extinction coefficients at a point (1/m, RGB).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Medium {
    pub rayleigh: [f64; 3],
    pub mie: [f64; 3],
    pub extinction: [f64; 3],
}

impl Medium {
    /// Total scattering per channel.
    pub fn scattering(&self) -> [f64; 3] {
        std::array::from_fn(|c| self.rayleigh[c] + self.mie[c])
    }

    /// Scattering times phase (1/m/sr) for scattering angle cosine `mu`.
    pub fn scattering_phase(&self, atm: &Atmosphere, mu: f64) -> [f64; 3] {
        let pr = rayleigh_phase(mu);
        let pm = cornette_shanks_phase(mu, atm.mie_g);
        std::array::from_fn(|c| self.rayleigh[c] * pr + self.mie[c] * pm)
    }
}

/// Rayleigh phase function (1/sr), normalised over the sphere.
pub fn rayleigh_phase(mu: f64) -> f64 {
    3.0 / (16.0 * PI) * (1.0 + mu * mu)
}

/// Henyey–Greenstein phase function (1/sr).
pub fn henyey_greenstein_phase(mu: f64, g: f64) -> f64 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    (1.0 - g * g) / (4.0 * PI * d * d.sqrt())
}

/// Cornette–Shanks phase function (1/sr), the Mie phase of Hillaire 2020.
pub fn cornette_shanks_phase(mu: f64, g: f64) -> f64 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    3.0 / (8.0 * PI) * (1.0 - g * g) * (1.0 + mu * mu) / ((2.0 + g * g) * d * d.sqrt())
}

/// Distances along the ray `o + t·d` (|d| = 1) to a sphere of radius `r` about the origin:
/// `Some((near, far))` when the line meets it (near may be negative: origin inside).
pub fn ray_sphere(o: DVec3, d: DVec3, r: f64) -> Option<(f64, f64)> {
    let b = o.dot(d);
    let c = o.length_squared() - r * r;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let q = disc.sqrt();
    // Stable form: the root of larger magnitude first.
    let t1 = if b > 0.0 { -b - q } else { -b + q };
    let t2 = if t1 != 0.0 { c / t1 } else { 0.0 };
    Some((t1.min(t2), t1.max(t2)))
}

/// Where a ray leaves the air or meets the ground: (distance, hits the ground). `o` inside the
/// shell.
pub fn ray_exit(atm: &Atmosphere, o: DVec3, d: DVec3) -> (f64, bool) {
    if let Some((near, _)) = ray_sphere(o, d, atm.ground_radius) {
        // 1 mm: a point on the ground leaving it does not meet it again.
        if near > 1e-3 {
            return (near, true);
        }
    }
    let far = ray_sphere(o, d, atm.top_radius).map_or(0.0, |(_, f)| f.max(0.0));
    (far, false)
}

/// Does the ray from `p` toward `d` meet the ground sphere (the sun is behind the planet)?
pub fn blocked_by_ground(atm: &Atmosphere, p: DVec3, d: DVec3) -> bool {
    matches!(ray_sphere(p, d, atm.ground_radius), Some((near, _)) if near > 0.0)
}

/// The unit direction at elevation `elevation_deg` above the horizon and azimuth
/// `azimuth_deg` (from +X toward +Z) in the +Y-up frame.
pub fn direction(elevation_deg: f64, azimuth_deg: f64) -> DVec3 {
    let (se, ce) = elevation_deg.to_radians().sin_cos();
    let (sa, ca) = azimuth_deg.to_radians().sin_cos();
    DVec3::new(ce * ca, se, ce * sa)
}

/// The eye at altitude `h` above the ground, on the +Y axis through the planet's centre.
pub fn eye_position(atm: &Atmosphere, h: f64) -> DVec3 {
    DVec3::new(0.0, atm.ground_radius + h, 0.0)
}
