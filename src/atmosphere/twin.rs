//! The f32 side of Hillaire's model: the parameters `shaders/atmosphere.wgsl` reads (uniform
//! `AtmosphereParams`, kilometres), the medium and phase functions, and the parameterisations
//! and filtering of the look-up tables — the same arithmetic as the WGSL, line for line.
//!
//! Every table is a row-major array of `[f32; 4]` texels. An axis of N texels covers the unit
//! coordinate x ∈ [0, 1] with texel i at x = i / (N − 1) (the end points are texel centres);
//! lookups interpolate linearly at the continuous index x·(N − 1), clamped.
//!
//! Parameterisations (u along rows, v down columns):
//! - transmittance (r, μ) → (x_μ, x_r): with H = √(top² − R²), ρ = √(r² − R²), x_r = ρ/H, and d
//!   the distance to the top along μ, x_μ = (d − d_min)/(d_max − d_min), d_min = top − r,
//!   d_max = ρ + H (Bruneton 2017; only rays that miss the ground).
//! - multiple scattering (r, μ_s) → (μ_s/2 + 1/2, √((r − R)/(top − R))): rows dense near the
//!   ground, where Ψ_ms bends (its lower hemisphere turns from ground to air).
//! - sky view (view zenith θ, azimuth φ from the sun) at the eye: u = √(φ/π); with the
//!   horizon's zenith angle θ_h = π − β, β = acos(ρ/r): v = ½·(1 − √(1 − θ/θ_h)) above the
//!   horizon, v = ½ + ½·√((θ − θ_h)/β) below (Hillaire's non-linear latitude, dense at the
//!   horizon).
//! - aerial perspective (u, v as the sky view, w = √(s / s_max)).

use glam::Vec3;

/// Texels of the transmittance table (x_μ, x_r).
pub const TRANSMITTANCE_SIZE: [usize; 2] = [256, 64];
/// Texels of the multiple-scattering table (μ_s, altitude).
pub const MULTI_SCATTERING_SIZE: [usize; 2] = [32, 32];
/// Texels of the sky-view table (azimuth, zenith).
pub const SKY_VIEW_SIZE: [usize; 2] = [192, 108];
/// Texels of the aerial-perspective volume (azimuth, zenith, distance); two texels each
/// (in-scattering, then transmittance).
pub const AERIAL_SIZE: [usize; 3] = [32, 32, 32];
/// The multiple-scattering table's sphere of directions: azimuths × zenith-cosine bands (64
/// in all, as in the paper; the bands are split at the horizon and crowd toward it, see
/// `lut::band`).
pub const MULTI_AZIMUTHS: usize = 4;
pub const MULTI_BANDS: usize = 16;
/// Quadrature steps: transmittance, multiple scattering (per direction), sky view, aerial.
pub const STEPS: [u32; 4] = [40, 20, 30, 20];

const PI: f32 = std::f32::consts::PI;

/// The parameters shared with WGSL (`AtmosphereParams`): kilometres and 1/km.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AtmosphereGpu {
    /// Rayleigh scattering RGB, w: scale height.
    pub rayleigh: [f32; 4],
    /// Mie scattering RGB, w: scale height.
    pub mie_scattering: [f32; 4],
    /// Mie extinction RGB, w: anisotropy g.
    pub mie_extinction: [f32; 4],
    /// Ozone absorption RGB, w: centre altitude.
    pub ozone: [f32; 4],
    /// Ground albedo RGB, w: ozone half width.
    pub ground_albedo: [f32; 4],
    /// Sun illuminance RGB, w: 0.
    pub sun_illuminance: [f32; 4],
    /// Ground radius, top radius, eye altitude, aerial-perspective range s_max.
    pub radii: [f32; 4],
    /// Unit direction toward the sun (+Y up), w: 0.
    pub sun: [f32; 4],
}

impl AtmosphereGpu {
    /// The f32 parameters of `atm` for an eye at `eye_altitude` metres, the sun toward
    /// `sun` (+Y up) and aerial perspective up to `aerial_range` metres.
    pub fn new(
        atm: &super::Atmosphere,
        eye_altitude: f64,
        sun: glam::DVec3,
        aerial_range: f64,
    ) -> Self {
        let k = |v: [f64; 3], w: f64| [v[0] as f32, v[1] as f32, v[2] as f32, w as f32];
        let km = |v: [f64; 3]| v.map(|x| x * 1000.0);
        let s = sun.normalize();
        AtmosphereGpu {
            rayleigh: k(km(atm.rayleigh_scattering), atm.rayleigh_height / 1000.0),
            mie_scattering: k(km(atm.mie_scattering), atm.mie_height / 1000.0),
            mie_extinction: k(km(atm.mie_extinction), atm.mie_g),
            ozone: k(km(atm.ozone_absorption), atm.ozone_centre / 1000.0),
            ground_albedo: k(atm.ground_albedo, atm.ozone_width / 2000.0),
            sun_illuminance: k(atm.sun_illuminance, 0.0),
            radii: [
                (atm.ground_radius / 1000.0) as f32,
                (atm.top_radius / 1000.0) as f32,
                (eye_altitude / 1000.0) as f32,
                (aerial_range / 1000.0) as f32,
            ],
            sun: [s.x as f32, s.y as f32, s.z as f32, 0.0],
        }
    }

    pub fn ground(&self) -> f32 {
        self.radii[0]
    }
    pub fn top(&self) -> f32 {
        self.radii[1]
    }
    pub fn sun_dir(&self) -> Vec3 {
        Vec3::new(self.sun[0], self.sun[1], self.sun[2])
    }
    pub fn eye(&self) -> Vec3 {
        Vec3::new(0.0, self.radii[0] + self.radii[2], 0.0)
    }
}

pub fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// Scattering (Rayleigh, Mie) and extinction at altitude `h` km.
pub fn medium(p: &AtmosphereGpu, h: f32) -> (Vec3, Vec3, Vec3) {
    let h = h.max(0.0);
    let dr = (-h / p.rayleigh[3]).exp();
    let dm = (-h / p.mie_scattering[3]).exp();
    let d_o = (1.0 - (h - p.ozone[3]).abs() / p.ground_albedo[3]).max(0.0);
    let sr = v3(p.rayleigh) * dr;
    let sm = v3(p.mie_scattering) * dm;
    let ext = sr + v3(p.mie_extinction) * dm + v3(p.ozone) * d_o;
    (sr, sm, ext)
}

pub fn rayleigh_phase(mu: f32) -> f32 {
    3.0 / (16.0 * PI) * (1.0 + mu * mu)
}

pub fn cornette_shanks_phase(mu: f32, g: f32) -> f32 {
    let d = 1.0 + g * g - 2.0 * g * mu;
    3.0 / (8.0 * PI) * (1.0 - g * g) * (1.0 + mu * mu) / ((2.0 + g * g) * d * d.sqrt())
}

/// Nearest non-negative distance from `o` along unit `d` to the sphere of radius `r` about
/// the origin, or −1 when there is none (also from on the sphere heading outward).
pub fn ray_sphere_nearest(o: Vec3, d: Vec3, r: f32) -> f32 {
    let b = o.dot(d);
    let c = o.dot(o) - r * r;
    let disc = b * b - c;
    // On or outside the sphere heading away: no hit. (Without this a ray leaving a point on
    // the ground returned its root t = 0, and the multiple-scattering table's bottom row saw
    // ground in every direction: air light lost, ground light doubled.)
    if disc < 0.0 || (c >= 0.0 && b >= 0.0) {
        return -1.0;
    }
    let q = disc.sqrt();
    let t0 = -b - q;
    let t1 = -b + q;
    if t0 >= 0.0 {
        t0
    } else if t1 >= 0.0 {
        t1
    } else {
        -1.0
    }
}

/// Distance from radius `r` along zenith cosine `mu` to the top of the air.
pub fn distance_to_top(p: &AtmosphereGpu, r: f32, mu: f32) -> f32 {
    let disc = r * r * (mu * mu - 1.0) + p.top() * p.top();
    (-r * mu + disc.max(0.0).sqrt()).max(0.0)
}

/// (x_μ, x_r) of the transmittance table.
pub fn transmittance_uv(p: &AtmosphereGpu, r: f32, mu: f32) -> (f32, f32) {
    let (g, t) = (p.ground(), p.top());
    let h = ((t - g) * (t + g)).sqrt();
    let rho = ((r - g) * (r + g)).max(0.0).sqrt();
    let d = distance_to_top(p, r, mu);
    let d_min = t - r;
    let d_max = rho + h;
    ((d - d_min) / (d_max - d_min).max(1e-6), rho / h)
}

/// (r, μ) of the transmittance table's unit coordinates.
pub fn transmittance_r_mu(p: &AtmosphereGpu, x_mu: f32, x_r: f32) -> (f32, f32) {
    let (g, t) = (p.ground(), p.top());
    let h = ((t - g) * (t + g)).sqrt();
    let rho = h * x_r;
    let r = (rho * rho + g * g).sqrt();
    let d_min = t - r;
    let d_max = rho + h;
    let d = d_min + x_mu * (d_max - d_min);
    let mu = if d == 0.0 {
        1.0
    } else {
        (h * h - rho * rho - d * d) / (2.0 * r * d)
    };
    (r, mu.clamp(-1.0, 1.0))
}

/// Cosine of the horizon's zenith angle seen from radius `r` (0 on the ground, negative above).
pub fn horizon_cosine(p: &AtmosphereGpu, r: f32) -> f32 {
    let q = p.ground() / r.max(p.ground());
    -(1.0 - q * q).max(0.0).sqrt()
}

/// The horizon's zenith angle θ_h seen from radius `r` and β = π − θ_h.
pub fn horizon(p: &AtmosphereGpu, r: f32) -> (f32, f32) {
    let g = p.ground();
    let v_h = ((r - g) * (r + g)).max(0.0).sqrt();
    let beta = (v_h / r).clamp(-1.0, 1.0).acos();
    (PI - beta, beta)
}

/// (u, v) of the sky-view table for view zenith angle `theta` and azimuth `phi` from the sun
/// (both radians), seen from radius `r`.
pub fn sky_view_uv(p: &AtmosphereGpu, r: f32, theta: f32, phi: f32) -> (f32, f32) {
    let (zh, beta) = horizon(p, r);
    let v = if theta < zh {
        let c = (1.0 - theta / zh).max(0.0).sqrt();
        0.5 * (1.0 - c)
    } else {
        let c = ((theta - zh) / beta).max(0.0).sqrt();
        0.5 + 0.5 * c
    };
    ((phi / PI).clamp(0.0, 1.0).sqrt(), v.clamp(0.0, 1.0))
}

/// (θ, φ) of the sky-view table's unit coordinates.
pub fn sky_view_angles(p: &AtmosphereGpu, r: f32, u: f32, v: f32) -> (f32, f32) {
    let (zh, beta) = horizon(p, r);
    let theta = if v < 0.5 {
        let c = 1.0 - 2.0 * v;
        zh * (1.0 - c * c)
    } else {
        let c = 2.0 * v - 1.0;
        zh + beta * c * c
    };
    (theta, PI * u * u)
}

/// View zenith angle and azimuth from the sun of `dir` (+Y up), as the sky view measures them.
pub fn view_angles(dir: Vec3, sun: Vec3) -> (f32, f32) {
    let theta = dir.y.clamp(-1.0, 1.0).acos();
    let lv = (dir.x * dir.x + dir.z * dir.z).sqrt();
    let ls = (sun.x * sun.x + sun.z * sun.z).sqrt();
    let c = if lv > 1e-6 && ls > 1e-6 {
        (dir.x * sun.x + dir.z * sun.z) / (lv * ls)
    } else {
        1.0
    };
    (theta, c.clamp(-1.0, 1.0).acos())
}

/// The direction of view zenith `theta` and azimuth `phi` from a sun in the +X half of the
/// XY plane.
pub fn angles_dir(theta: f32, phi: f32) -> Vec3 {
    let s = theta.sin();
    Vec3::new(s * phi.cos(), theta.cos(), s * phi.sin())
}

/// Linear interpolation in an `nx` × `ny` table at unit coordinates (x, y).
pub fn sample2(tab: &[[f32; 4]], nx: usize, ny: usize, x: f32, y: f32) -> Vec3 {
    let fx = x.clamp(0.0, 1.0) * (nx - 1) as f32;
    let fy = y.clamp(0.0, 1.0) * (ny - 1) as f32;
    let (x0, y0) = (
        (fx.floor() as usize).min(nx - 1),
        (fy.floor() as usize).min(ny - 1),
    );
    let (x1, y1) = ((x0 + 1).min(nx - 1), (y0 + 1).min(ny - 1));
    let (ax, ay) = (fx - x0 as f32, fy - y0 as f32);
    let t = |i: usize, j: usize| v3(tab[j * nx + i]);
    let a = t(x0, y0) + (t(x1, y0) - t(x0, y0)) * ax;
    let b = t(x0, y1) + (t(x1, y1) - t(x0, y1)) * ax;
    a + (b - a) * ay
}

/// Linear interpolation in the aerial-perspective volume at (x, y, z): (in-scattering,
/// transmittance).
pub fn sample_aerial(tab: &[[f32; 4]], x: f32, y: f32, z: f32) -> (Vec3, Vec3) {
    let [nx, ny, nz] = AERIAL_SIZE;
    let f = [
        x.clamp(0.0, 1.0) * (nx - 1) as f32,
        y.clamp(0.0, 1.0) * (ny - 1) as f32,
        z.clamp(0.0, 1.0) * (nz - 1) as f32,
    ];
    let n = [nx, ny, nz];
    let i0: [usize; 3] = std::array::from_fn(|k| (f[k].floor() as usize).min(n[k] - 1));
    let i1: [usize; 3] = std::array::from_fn(|k| (i0[k] + 1).min(n[k] - 1));
    let a: [f32; 3] = std::array::from_fn(|k| f[k] - i0[k] as f32);
    let (mut l, mut t) = (Vec3::ZERO, Vec3::ZERO);
    for corner in 0..8 {
        let pick = |k: usize| (corner >> k) & 1 == 1;
        let idx: [usize; 3] = std::array::from_fn(|k| if pick(k) { i1[k] } else { i0[k] });
        let w: f32 = (0..3)
            .map(|k| if pick(k) { a[k] } else { 1.0 - a[k] })
            .product();
        let texel = 2 * ((idx[2] * ny + idx[1]) * nx + idx[0]);
        l += v3(tab[texel]) * w;
        t += v3(tab[texel + 1]) * w;
    }
    (l, t)
}
