//! Hillaire 2020's tables, built and read in f32 — the CPU twins of the kernels and lookups of
//! `shaders/atmosphere.wgsl` (same parameterisations, same quadrature, see `twin.rs`).
//!
//! - **Transmittance** T(r, μ) to the top of the air: 40 midpoint steps.
//! - **Multiple scattering** Ψ_ms(r, μ_s) for unit illuminance: from 64 directions the
//!   second-order light L₂ (isotropic phase, ground albedo lit by the sun) and the transfer
//!   f_ms = ⟨∫T·σ_s⟩; Ψ_ms = L₂ / (1 − f_ms), the infinite series of isotropic orders (paper
//!   §5.5). The paper's 8 × 8 directions uniform on the sphere miss the radiance that peaks at
//!   the horizon (grazing paths through the low Mie layer): L₂ came out 22 % low in red at 1.5 km
//!   against a 32,768-direction quadrature. Here 4 azimuths × 16 zenith bands, split at the
//!   horizon and crowded toward it, with steps crowded toward the point ([`band`]): within 2 %
//!   of that quadrature from 0.1 to 20 km, at the same cost (`tests/library/atmosphere_orders.rs`).
//! - **Sky view** L(θ, φ) at the eye: 30 steps (quadratic spacing) to the ground or the top;
//!   single scattering (phase, T from the table, planet shadow) plus σ_s·Ψ_ms.
//! - **Aerial perspective** (φ, θ, s): the same integrand over 20 uniform steps from the eye to
//!   s = s_max·w² (clamped where the ray meets the ground), in-scattering and transmittance.
//!
//! Each step integrates a constant source S over its length analytically:
//! `L += T·(S − S·e^(−σ_t·Δt))/σ_t`, `T ·= e^(−σ_t·Δt)` (paper §5.6.3).

use super::twin::{self, *};
use glam::Vec3;
use rayon::prelude::*;

/// All four tables, built for one eye altitude and sun (`AtmosphereGpu::radii`, `sun`).
#[derive(Clone, Debug, PartialEq)]
pub struct Luts {
    pub params: AtmosphereGpu,
    pub transmittance: Vec<[f32; 4]>,
    pub multi_scattering: Vec<[f32; 4]>,
    pub sky_view: Vec<[f32; 4]>,
    /// Two texels per cell: in-scattering, then transmittance.
    pub aerial: Vec<[f32; 4]>,
}

fn quad(v: Vec3, w: f32) -> [f32; 4] {
    [v.x, v.y, v.z, w]
}

fn unit(i: usize, n: usize) -> f32 {
    i as f32 / (n - 1) as f32
}

/// Transmittance texel (i, j).
pub fn transmittance_texel(p: &AtmosphereGpu, i: usize, j: usize) -> [f32; 4] {
    let [w, h] = TRANSMITTANCE_SIZE;
    let (r, mu) = transmittance_r_mu(p, unit(i, w), unit(j, h));
    let d = distance_to_top(p, r, mu);
    let dir = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), mu, 0.0);
    let o = Vec3::new(0.0, r, 0.0);
    let n = STEPS[0];
    let dt = d / n as f32;
    let mut tau = Vec3::ZERO;
    for k in 0..n {
        let x = o + dir * ((k as f32 + 0.5) * dt);
        let (_, _, ext) = medium(p, x.length() - p.ground());
        tau += ext * dt;
    }
    quad((-tau).exp(), 1.0)
}

/// Transmittance from radius `r` along zenith cosine `mu` to the top (table lookup).
pub fn transmittance(p: &AtmosphereGpu, tab: &[[f32; 4]], r: f32, mu: f32) -> Vec3 {
    let (x, y) = transmittance_uv(p, r, mu);
    let [w, h] = TRANSMITTANCE_SIZE;
    sample2(tab, w, h, x, y)
}

/// Ψ_ms at radius `r` for sun zenith cosine `mu_s` (table lookup).
pub fn multi_scattering(p: &AtmosphereGpu, tab: &[[f32; 4]], r: f32, mu_s: f32) -> Vec3 {
    let [w, h] = MULTI_SCATTERING_SIZE;
    let y = ((r - p.ground()) / (p.top() - p.ground())).max(0.0).sqrt();
    sample2(tab, w, h, 0.5 * mu_s + 0.5, y)
}

/// Sun visibility and transmittance at `x` (km, planet centre at the origin).
fn sun_light(p: &AtmosphereGpu, trans: &[[f32; 4]], x: Vec3, sun: Vec3) -> (f32, Vec3, f32) {
    let r = x.length();
    let mu_s = x.dot(sun) / r;
    // The planet hides the sun below the local horizon: the same test as a ray–sphere hit
    // toward the sun, but well conditioned near the ground (and defined under it, where an
    // aerial cell's march may pass).
    let shadow = if mu_s < horizon_cosine(p, r) {
        0.0
    } else {
        1.0
    };
    (shadow, transmittance(p, trans, r, mu_s), mu_s)
}

/// The multiple-scattering raymarch of one direction: (L₂ integrand sum, f_ms sum).
fn multi_direction(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    o: Vec3,
    dir: Vec3,
    sun: Vec3,
    n: u32,
    quadratic: bool,
) -> (Vec3, Vec3) {
    let t_ground = ray_sphere_nearest(o, dir, p.ground());
    let t_top = ray_sphere_nearest(o, dir, p.top());
    let t_max = if t_ground >= 0.0 {
        t_ground
    } else {
        t_top.max(0.0)
    };
    let iso = 1.0 / (4.0 * std::f32::consts::PI);
    let (mut l, mut f, mut thr) = (Vec3::ZERO, Vec3::ZERO, Vec3::ONE);
    for k in 0..n {
        let (t0, t1) = step_span(k, n, t_max, quadratic);
        let dt = t1 - t0;
        let x = o + dir * (0.5 * (t0 + t1));
        let (sr, sm, ext) = medium(p, x.length() - p.ground());
        let (shadow, ts, _) = sun_light(p, trans, x, sun);
        let scat = sr + sm;
        let step_t = (-ext * dt).exp();
        let s = ts * scat * (shadow * iso);
        let inv = Vec3::ONE / ext.max(Vec3::splat(1e-12));
        l += thr * (s - s * step_t) * inv;
        f += thr * (scat - scat * step_t) * inv;
        thr *= step_t;
    }
    if t_ground >= 0.0 {
        let x = o + dir * t_ground;
        let up = x / x.length();
        let (_, ts, _) = sun_light(p, trans, x, sun);
        let cos = up.dot(sun).clamp(0.0, 1.0);
        l += thr * ts * v3(p.ground_albedo) * (cos / std::f32::consts::PI);
    }
    (l, f)
}

/// Step `k` of `n` over `[0, t_max]`: uniform, or quadratic (crowded toward 0).
fn step_span(k: u32, n: u32, t_max: f32, quadratic: bool) -> (f32, f32) {
    let (a, b) = (k as f32 / n as f32, (k + 1) as f32 / n as f32);
    if quadratic {
        (a * a * t_max, b * b * t_max)
    } else {
        (a * t_max, b * t_max)
    }
}

/// The sampling of the multiple-scattering table: azimuths × zenith-cosine bands, raymarch
/// steps per direction, and where they crowd. [`MultiQuality::TWIN`] is what the WGSL kernel
/// uses; [`MultiQuality::PAPER`] is Hillaire's; others are CPU-only, for measuring the table's
/// own error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MultiQuality {
    pub azimuths: usize,
    pub bands: usize,
    pub steps: u32,
    /// Hillaire's infinite isotropic series L₂/(1 − f_ms); false keeps order two (L₂) alone.
    pub all_orders: bool,
    /// Bands split at the horizon and crowded toward it, steps crowded toward the point
    /// ([`band`]); false: the paper's uniform bands and steps.
    pub horizon: bool,
}

impl MultiQuality {
    pub const TWIN: MultiQuality = MultiQuality {
        azimuths: MULTI_AZIMUTHS,
        bands: MULTI_BANDS,
        steps: STEPS[1],
        all_orders: true,
        horizon: true,
    };
    /// The paper's sampling: 8 × 8 directions uniform on the sphere, 20 uniform steps.
    pub const PAPER: MultiQuality = MultiQuality {
        azimuths: 8,
        bands: 8,
        steps: 20,
        all_orders: true,
        horizon: false,
    };
}

/// Multiple-scattering texel (i, j).
pub fn multi_scattering_texel(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    i: usize,
    j: usize,
) -> [f32; 4] {
    multi_scattering_texel_with(p, trans, i, j, MultiQuality::TWIN)
}

/// Multiple-scattering texel (i, j) with the sampling `q`.
pub fn multi_scattering_texel_with(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    i: usize,
    j: usize,
    q: MultiQuality,
) -> [f32; 4] {
    let [w, h] = MULTI_SCATTERING_SIZE;
    let mu_s = 2.0 * unit(i, w) - 1.0;
    let y = unit(j, h);
    let r = p.ground() + y * y * (p.top() - p.ground());
    quad(multi_scattering_at(p, trans, r, mu_s, q), 1.0)
}

/// Ψ_ms at radius `r` for sun zenith cosine `mu_s`, computed (not looked up) with the
/// sampling `q`.
pub fn multi_scattering_at(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    r: f32,
    mu_s: f32,
    q: MultiQuality,
) -> Vec3 {
    let o = Vec3::new(0.0, r, 0.0);
    let sun = Vec3::new((1.0 - mu_s * mu_s).max(0.0).sqrt(), mu_s, 0.0);
    let mu_h = horizon_cosine(p, r);
    // Sums weighted by each direction's share of the sphere: averages over it (the isotropic
    // phase is inside L₂ already; f_ms is ∫T·σ_s averaged over directions).
    let (mut l2, mut fms) = (Vec3::ZERO, Vec3::ZERO);
    for a in 0..q.azimuths {
        let theta = 2.0 * std::f32::consts::PI * (a as f32 + 0.5) / q.azimuths as f32;
        for b in 0..q.bands {
            let (cos_phi, share) = band(b, q.bands, mu_h, q.horizon);
            let sin_phi = (1.0 - cos_phi * cos_phi).max(0.0).sqrt();
            let dir = Vec3::new(theta.cos() * sin_phi, cos_phi, theta.sin() * sin_phi);
            let (l, f) = multi_direction(p, trans, o, dir, sun, q.steps, q.horizon);
            let w = share / q.azimuths as f32;
            l2 += l * w;
            fms += f * w;
        }
    }
    if !q.all_orders {
        return l2;
    }
    l2 / (Vec3::ONE - fms)
}

/// Band `b` of `bands` in cos φ (the direction's zenith cosine): its node and its share of
/// the sphere. Uniform: midpoints of equal bands. Crowded (`horizon`): the first half spans
/// [μ_h, 1] above the horizon (zenith cosine `mu_h`), the second [−1, μ_h] below it, each with
/// cos φ = μ_h ± span·s² at the midpoints s of equal steps of [0, 1] (share span·s / half):
/// the radiance of grazing directions, through the most air, is where the nodes are.
pub fn band(b: usize, bands: usize, mu_h: f32, horizon: bool) -> (f32, f32) {
    if !horizon {
        return (
            1.0 - 2.0 * (b as f32 + 0.5) / bands as f32,
            1.0 / bands as f32,
        );
    }
    let half = bands / 2;
    let (k, up) = if b < half {
        (half - 1 - b, true)
    } else {
        (b - half, false)
    };
    let s = (k as f32 + 0.5) / half as f32;
    let span = if up { 1.0 - mu_h } else { 1.0 + mu_h };
    let c = if up {
        mu_h + span * s * s
    } else {
        mu_h - span * s * s
    };
    (c, span * s / half as f32)
}

/// The sky / aerial raymarch from the eye along `dir` over `[0, t_max]` with `n` steps
/// (quadratic spacing when `quadratic`): (in-scattering, transmittance).
#[allow(clippy::too_many_arguments)]
pub fn march(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    ms: &[[f32; 4]],
    dir: Vec3,
    t_max: f32,
    n: u32,
    quadratic: bool,
) -> (Vec3, Vec3) {
    let o = p.eye();
    let sun = p.sun_dir();
    let mu = dir.dot(sun);
    let g = p.mie_extinction[3];
    let (pr, pm) = (rayleigh_phase(mu), cornette_shanks_phase(mu, g));
    let e = v3(p.sun_illuminance);
    let (mut l, mut thr) = (Vec3::ZERO, Vec3::ONE);
    for k in 0..n {
        let (t0, t1) = step_span(k, n, t_max, quadratic);
        let dt = t1 - t0;
        let x = o + dir * (0.5 * (t0 + t1));
        let r = x.length();
        let (sr, sm, ext) = medium(p, r - p.ground());
        let (shadow, ts, mu_s) = sun_light(p, trans, x, sun);
        let psi = multi_scattering(p, ms, r, mu_s);
        let s = e * ((sr * pr + sm * pm) * ts * shadow + psi * (sr + sm));
        let step_t = (-ext * dt).exp();
        let inv = Vec3::ONE / ext.max(Vec3::splat(1e-12));
        l += thr * (s - s * step_t) * inv;
        thr *= step_t;
    }
    (l, thr)
}

/// Distance from the eye along `dir` to the ground or, missing it, the top.
pub fn exit_distance(p: &AtmosphereGpu, dir: Vec3) -> f32 {
    let o = p.eye();
    let t_ground = ray_sphere_nearest(o, dir, p.ground());
    if t_ground >= 0.0 {
        t_ground
    } else {
        ray_sphere_nearest(o, dir, p.top()).max(0.0)
    }
}

/// Sky-view texel (i, j).
pub fn sky_view_texel(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    ms: &[[f32; 4]],
    i: usize,
    j: usize,
) -> [f32; 4] {
    let [w, h] = SKY_VIEW_SIZE;
    let (theta, phi) = sky_view_angles(p, p.eye().y, unit(i, w), unit(j, h));
    let dir = frame_dir(p, theta, phi);
    let (l, t) = march(p, trans, ms, dir, exit_distance(p, dir), STEPS[2], true);
    quad(l, (t.x + t.y + t.z) / 3.0)
}

/// The direction of zenith `theta` and azimuth `phi` measured from the sun's azimuth.
pub fn frame_dir(p: &AtmosphereGpu, theta: f32, phi: f32) -> Vec3 {
    let sun = p.sun_dir();
    let ls = (sun.x * sun.x + sun.z * sun.z).sqrt();
    let (cx, cz) = if ls > 1e-6 {
        (sun.x / ls, sun.z / ls)
    } else {
        (1.0, 0.0)
    };
    let d = angles_dir(theta, phi);
    // Rotate the +X-based azimuth to the sun's: (cx, cz) is the sun's horizontal direction.
    Vec3::new(d.x * cx - d.z * cz, d.y, d.x * cz + d.z * cx)
}

/// Aerial-perspective cell (i, j, k): (in-scattering texel, transmittance texel).
pub fn aerial_texels(
    p: &AtmosphereGpu,
    trans: &[[f32; 4]],
    ms: &[[f32; 4]],
    i: usize,
    j: usize,
    k: usize,
) -> [[f32; 4]; 2] {
    let [nx, ny, nz] = AERIAL_SIZE;
    let (theta, phi) = sky_view_angles(p, p.eye().y, unit(i, nx), unit(j, ny));
    let dir = frame_dir(p, theta, phi);
    let w = unit(k, nz);
    let (dir, s) = aerial_target(p, dir, p.radii[3] * w * w);
    let (l, t) = march(p, trans, ms, dir, s, STEPS[3], false);
    [quad(l, 0.0), quad(t, 0.0)]
}

/// The segment an aerial cell marches: from the eye along `dir` for `s` km, but a cell whose
/// point lies under the ground is lifted onto it (1 m above, straight up) and marched to
/// there, after Hillaire's implementation. Clamping such a cell at the ground instead gives
/// it the light of a shorter path than its neighbours', and a surface seen between the two
/// rows read 10 % too little in-scattering (−5° at 17 km from a 1.5 km eye); lifted, 3 %.
/// Cells past the top of the air stop there.
pub fn aerial_target(p: &AtmosphereGpu, dir: Vec3, s: f32) -> (Vec3, f32) {
    let o = p.eye();
    let t_ground = ray_sphere_nearest(o, dir, p.ground());
    if t_ground < 0.0 || s <= t_ground {
        return (dir, s.min(exit_distance(p, dir)));
    }
    let x = o + dir * s;
    let v = x * ((p.ground() + 1e-3) / x.length()) - o;
    let len = v.length();
    (v / len.max(1e-12), len)
}

impl Luts {
    /// Build every table on the CPU (the twin of `gpu::atmosphere`).
    pub fn build(params: &AtmosphereGpu) -> Luts {
        Luts::build_with(params, MultiQuality::TWIN)
    }

    /// Build every table with the multiple-scattering sampling `q` (CPU only).
    pub fn build_with(params: &AtmosphereGpu, q: MultiQuality) -> Luts {
        let p = params;
        let [tw, th] = TRANSMITTANCE_SIZE;
        let transmittance: Vec<_> = (0..tw * th)
            .into_par_iter()
            .map(|n| transmittance_texel(p, n % tw, n / tw))
            .collect();
        let [mw, mh] = MULTI_SCATTERING_SIZE;
        let multi_scattering: Vec<_> = (0..mw * mh)
            .into_par_iter()
            .map(|n| multi_scattering_texel_with(p, &transmittance, n % mw, n / mw, q))
            .collect();
        let [sw, sh] = SKY_VIEW_SIZE;
        let sky_view: Vec<_> = (0..sw * sh)
            .into_par_iter()
            .map(|n| sky_view_texel(p, &transmittance, &multi_scattering, n % sw, n / sw))
            .collect();
        let [ax, ay, az] = AERIAL_SIZE;
        let aerial: Vec<_> = (0..ax * ay * az)
            .into_par_iter()
            .flat_map_iter(|n| {
                aerial_texels(
                    p,
                    &transmittance,
                    &multi_scattering,
                    n % ax,
                    (n / ax) % ay,
                    n / (ax * ay),
                )
            })
            .collect();
        Luts {
            params: *p,
            transmittance,
            multi_scattering,
            sky_view,
            aerial,
        }
    }

    /// Sky radiance (in-scattering from the eye to the ground or space) along unit `dir`.
    pub fn sky_radiance(&self, dir: Vec3) -> Vec3 {
        let p = &self.params;
        let (theta, phi) = view_angles(dir, p.sun_dir());
        let (u, v) = sky_view_uv(p, p.eye().y, theta, phi);
        let [w, h] = SKY_VIEW_SIZE;
        sample2(&self.sky_view, w, h, u, v)
    }

    /// In-scattering and transmittance from the eye along unit `dir` over `distance_km`
    /// (clamped to the volume's range s_max).
    pub fn aerial_perspective(&self, dir: Vec3, distance_km: f32) -> (Vec3, Vec3) {
        let p = &self.params;
        let (theta, phi) = view_angles(dir, p.sun_dir());
        let (u, v) = sky_view_uv(p, p.eye().y, theta, phi);
        let w = (distance_km / p.radii[3]).clamp(0.0, 1.0).sqrt();
        sample_aerial(&self.aerial, u, v, w)
    }

    /// Hillaire's raymarch evaluated directly for one segment (no sky-view or aerial table;
    /// the per-pixel option and the check of the tables' interpolation).
    pub fn march_segment(&self, dir: Vec3, distance_km: f32, steps: u32) -> (Vec3, Vec3) {
        let p = &self.params;
        let s = distance_km.min(exit_distance(p, dir));
        march(
            p,
            &self.transmittance,
            &self.multi_scattering,
            dir,
            s,
            steps,
            false,
        )
    }
}

/// The constant-density fog (Vyatkin et al. 2018) in f32 (the twin of `fog` in WGSL): radiance of
/// `l0` seen through `s` km of constant air with extinction `ext`, Rayleigh and Mie scattering
/// `sr`, `sm` (1/km), Mie g, sun illuminance `e`, view–sun cosine `mu`.
#[allow(clippy::too_many_arguments)]
pub fn fog(l0: Vec3, s: f32, mu: f32, ext: Vec3, sr: Vec3, sm: Vec3, g: f32, e: Vec3) -> Vec3 {
    let t = (-ext * s).exp();
    let sc = sr * twin::rayleigh_phase(mu) + sm * twin::cornette_shanks_phase(mu, g);
    l0 * t + e * sc / ext.max(Vec3::splat(1e-12)) * (Vec3::ONE - t)
}
