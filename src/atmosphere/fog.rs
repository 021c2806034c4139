//! The constant-density fog of Vyatkin et al. (2018), the model of Hoffman & Preetham (2002):
//!
//! `L = L0·e^(−β_ext·s) + E_sun·(β_sc·Φ(θ)/β_ext)·(1 − e^(−β_ext·s))`
//!
//! per channel, with s the distance to the eye and θ the angle between the view ray (eye →
//! surface) and the sun. The coefficients are the air's at the **eye's altitude**: β_ext =
//! Rayleigh + Mie extinction + ozone, β_sc·Φ = β_R·Φ_R(θ) + β_M·Φ_CS(θ) (so the phase is the
//! scattering-weighted mix, per channel). E_sun is the sun's illuminance **unattenuated** — the
//! paper's choice, which is why it fails for low suns; [`FogParams::new`] can instead attenuate
//! it by the air between the eye and the sun (and zero it below the horizon), a variant the
//! study reports beside the paper's. Single scattering only, no ground, flat density.
//!
//! *Per vertex* (as in the paper): the model is evaluated at the vertices of a triangle and the
//! result interpolated linearly; [`per_vertex`] reproduces that along one edge so the study
//! can measure it against the per-pixel evaluation [`per_pixel`].

use super::{cornette_shanks_phase, rayleigh_phase, reference, Atmosphere};
use glam::DVec3;

/// Coefficients of the constant-density model (1/m, RGB) and the sun it is lit by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FogParams {
    pub extinction: [f64; 3],
    pub rayleigh: [f64; 3],
    pub mie: [f64; 3],
    pub mie_g: f64,
    /// Sun illuminance reaching the fog (RGB).
    pub sun: [f64; 3],
    /// Unit direction toward the sun (+Y up).
    pub sun_dir: DVec3,
}

impl FogParams {
    /// The air at the eye's altitude `eye_altitude` (m). `attenuate_sun` false is the
    /// paper's model (E_sun as at the top of the air); true multiplies it by the transmittance from
    /// the eye to the sun (zero when the planet hides the sun).
    pub fn new(atm: &Atmosphere, eye_altitude: f64, sun_dir: DVec3, attenuate_sun: bool) -> Self {
        let m = atm.medium(eye_altitude);
        let sun_t = if attenuate_sun {
            let eye = super::eye_position(atm, eye_altitude);
            reference::sun_transmittance(atm, eye, sun_dir)
        } else {
            [1.0; 3]
        };
        FogParams {
            extinction: m.extinction,
            rayleigh: m.rayleigh,
            mie: m.mie,
            mie_g: atm.mie_g,
            sun: std::array::from_fn(|c| atm.sun_illuminance[c] * sun_t[c]),
            sun_dir: sun_dir.normalize(),
        }
    }

    /// Radiance at the eye of a surface of radiance `l0` at distance `s` (m), seen along a
    /// ray whose angle with the sun has cosine `cos_theta`.
    pub fn apply(&self, l0: [f64; 3], s: f64, cos_theta: f64) -> [f64; 3] {
        let pr = rayleigh_phase(cos_theta);
        let pm = cornette_shanks_phase(cos_theta, self.mie_g);
        std::array::from_fn(|c| {
            let t = (-self.extinction[c] * s).exp();
            let sc = self.rayleigh[c] * pr + self.mie[c] * pm;
            let inscatter = if self.extinction[c] > 0.0 {
                self.sun[c] * sc / self.extinction[c] * (1.0 - t)
            } else {
                self.sun[c] * sc * s
            };
            l0[c] * t + inscatter
        })
    }

    /// In-scattered radiance and transmittance of the segment from `eye` to `p`.
    pub fn segment(&self, eye: DVec3, p: DVec3) -> ([f64; 3], [f64; 3]) {
        let v = p - eye;
        let s = v.length();
        let mu = if s > 0.0 {
            v.dot(self.sun_dir) / s
        } else {
            1.0
        };
        let inscatter = self.apply([0.0; 3], s, mu);
        let t = std::array::from_fn(|c| (-self.extinction[c] * s).exp());
        (inscatter, t)
    }
}

/// The per-pixel model at the point `a + t·(b − a)` of an edge whose end radiances are `l0a`,
/// `l0b` (linearly interpolated): what a fragment shader computes.
pub fn per_pixel(
    f: &FogParams,
    eye: DVec3,
    (a, b): (DVec3, DVec3),
    (l0a, l0b): ([f64; 3], [f64; 3]),
    t: f64,
) -> [f64; 3] {
    let p = a.lerp(b, t);
    let l0 = std::array::from_fn(|c| l0a[c] + t * (l0b[c] - l0a[c]));
    let v = p - eye;
    let s = v.length();
    f.apply(l0, s, v.dot(f.sun_dir) / s.max(1e-300))
}

/// The per-vertex model at the same point: the model evaluated at `a` and `b`, then
/// interpolated linearly (what a vertex shader plus the rasteriser's interpolation give).
pub fn per_vertex(
    f: &FogParams,
    eye: DVec3,
    (a, b): (DVec3, DVec3),
    (l0a, l0b): ([f64; 3], [f64; 3]),
    t: f64,
) -> [f64; 3] {
    let fa = per_pixel(f, eye, (a, b), (l0a, l0b), 0.0);
    let fb = per_pixel(f, eye, (a, b), (l0a, l0b), 1.0);
    std::array::from_fn(|c| fa[c] + t * (fb[c] - fa[c]))
}

/// The largest relative difference (over RGB and `samples` points of the edge) between the
/// per-vertex and the per-pixel model.
pub fn per_vertex_error(
    f: &FogParams,
    eye: DVec3,
    edge: (DVec3, DVec3),
    l0: ([f64; 3], [f64; 3]),
    samples: usize,
) -> f64 {
    let mut worst = 0.0f64;
    for k in 0..=samples {
        let t = k as f64 / samples as f64;
        let pp = per_pixel(f, eye, edge, l0, t);
        let pv = per_vertex(f, eye, edge, l0, t);
        for c in 0..3 {
            worst = worst.max((pv[c] - pp[c]).abs() / pp[c].abs().max(1e-300));
        }
    }
    worst
}
