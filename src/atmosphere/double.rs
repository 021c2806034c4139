//! Double scattering by nested quadrature, to check the Monte Carlo tracer's order two
//! independently of its sampling: along the view segment (the reference's nodes),
//! `L₂ = ∫ T(0,t)·Σₖ σₖ(x_t)·∫_{4π} Φₖ(v·ω)·L₁(x_t, ω) dω dt`, where `L₁(x, ω)` is the single
//! scattering seen from x along ω up to the ground or the top of the air
//! (`reference::single_scattering`, by rotating x onto the +Y axis). No ground reflection: that
//! matches the tracer's `McResult::order2` (the sun estimate at the second vertex when it is in
//! the air).
//!
//! The sphere is integrated in elevation and azimuth about x's vertical, with Gauss–Legendre
//! panels (8 nodes, each split `Quadrature::split` times) that break at the horizon (where L₁ jumps from a
//! ground-ended to a grazing ray), and ±0.3 rad around the view direction and the sun (the
//! Cornette–Shanks forward peaks, width ≈ 1 − g = 0.2 rad).

use super::reference::{gauss, single_scattering_scaled, view_nodes, ViewRay};
use super::{cornette_shanks_phase, rayleigh_phase, Atmosphere};
use glam::{DQuat, DVec3};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

const PEAK: f64 = 0.3;

/// Sorted, de-duplicated break points within [lo, hi] (inclusive of both).
fn breaks(lo: f64, hi: f64, extra: &[f64]) -> Vec<f64> {
    let mut b: Vec<f64> = extra
        .iter()
        .copied()
        .filter(|v| *v > lo && *v < hi)
        .collect();
    b.push(lo);
    b.push(hi);
    b.sort_by(f64::total_cmp);
    b.dedup_by(|a, c| (*a - *c).abs() < 1e-9);
    b
}

/// Gauss–Legendre nodes of the panels `ends`, each split into `split` equal parts.
fn nodes(ends: &[f64], split: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for w in ends.windows(2) {
        let h = (w[1] - w[0]) / split as f64;
        for k in 0..split {
            let a = w[0] + k as f64 * h;
            out.extend(gauss(a, a + h));
        }
    }
    out
}

/// Elevation and azimuth of unit `d` in the frame (e1, up, e2).
fn angles(d: DVec3, up: DVec3, e1: DVec3, e2: DVec3) -> (f64, f64) {
    (
        d.dot(up).clamp(-1.0, 1.0).asin(),
        d.dot(e2).atan2(d.dot(e1)),
    )
}

/// `∫ Φ_R(v·ω) L₁(x, ω) dω` and `∫ Φ_CS(v·ω) L₁(x, ω) dω` (RGB each).
fn sphere(atm: &Atmosphere, x: DVec3, v: DVec3, sun: DVec3, q: Quadrature) -> [[f64; 3]; 2] {
    let up = x.normalize();
    let a = if up.x.abs() > 0.9 { DVec3::Z } else { DVec3::X };
    let e1 = up.cross(a).normalize();
    let e2 = e1.cross(up);
    let dip = (atm.ground_radius / x.length()).clamp(-1.0, 1.0).acos();
    let (av, pv) = angles(v, up, e1, e2);
    let (asun, psun) = angles(sun, up, e1, e2);
    let el = breaks(
        -FRAC_PI_2,
        FRAC_PI_2,
        &[-dip, av - PEAK, av + PEAK, asun - PEAK, asun + PEAK],
    );
    let wrap = |p: f64| (p + PI).rem_euclid(2.0 * PI) - PI;
    let az = breaks(
        -PI,
        PI,
        &[
            wrap(pv - PEAK),
            wrap(pv + PEAK),
            wrap(psun - PEAK),
            wrap(psun + PEAK),
        ],
    );
    let rot = DQuat::from_rotation_arc(up, DVec3::Y);
    let (el_nodes, az_nodes) = (nodes(&el, q.split), nodes(&az, q.split));
    let mut out = [[0.0; 3]; 2];
    for (alpha, wa) in &el_nodes {
        let (sa, ca) = alpha.sin_cos();
        for (psi, wp) in &az_nodes {
            let w = (psi.cos() * e1 + psi.sin() * e2) * ca + up * sa;
            let l1 = single_scattering_scaled(
                atm,
                &ViewRay {
                    eye_altitude: atm.altitude(x),
                    dir: rot * w,
                    sun: rot * sun,
                    length: None,
                },
                q.panel_scale,
            )
            .inscatter;
            let mu = v.dot(w);
            let dw = wa * wp * ca;
            let (pr, pm) = (rayleigh_phase(mu), cornette_shanks_phase(mu, atm.mie_g));
            for c in 0..3 {
                out[0][c] += dw * pr * l1[c];
                out[1][c] += dw * pm * l1[c];
            }
        }
    }
    out
}

/// Resolution of the nested quadrature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadrature {
    /// Splits of each sphere panel (1: 8 Gauss nodes per panel and axis).
    pub split: usize,
    /// Panel-length factor of the inner single scattering (1: the reference's panels).
    pub panel_scale: f64,
}

/// Double-scattered radiance (no ground) of the view segment `ray`, RGB. View nodes run in
/// parallel (rayon).
pub fn double_scattering(atm: &Atmosphere, ray: &ViewRay, q: Quadrature) -> [f64; 3] {
    let (eye, _) = ray.start_and_length(atm);
    let (view, _) = view_nodes(atm, ray);
    let parts: Vec<[f64; 3]> = view
        .par_iter()
        .map(|n| {
            let x = eye + n.t * ray.dir;
            let m = atm.medium(atm.altitude(x));
            let [ir, im] = sphere(atm, x, ray.dir, ray.sun, q);
            std::array::from_fn(|c| {
                n.weight * n.transmittance[c] * (m.rayleigh[c] * ir[c] + m.mie[c] * im[c])
            })
        })
        .collect();
    let mut out = [0.0; 3];
    for p in parts {
        for c in 0..3 {
            out[c] += p[c];
        }
    }
    out
}
