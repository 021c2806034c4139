//! Multiple scattering by a Monte Carlo volumetric path tracer, independent of Hillaire's
//! isotropic approximation: every order, anisotropic phase functions, a Lambertian ground.
//!
//! The first vertex is a quadrature node of the view segment (`reference::view_nodes`) drawn
//! with probability ∝ weight·T̄·σ̄_s (bars: channel means), so every path scatters on the view
//! segment. From there: next-event estimation to the sun at every vertex (transmittance by the
//! reference quadrature, zero behind the planet), new directions from the phase mixture
//! (Rayleigh uniformly, Mie by Henyey–Greenstein, weighted by phase / pdf of the mixture),
//! free flights by *spectral delta tracking* (Kutz et al. 2017: one flight for RGB with the
//! channel-mean extinction, majorant twice the largest extinction in the shell, per-channel
//! weights at real and null collisions — unbiased), Lambertian ground bounces, Russian
//! roulette. The sun estimate at the first vertex is the single scattering (it must match the
//! quadrature within its standard error); all later ones are the orders ≥ 2.
//!
//! Deterministic: one PCG stream per call, seeded by [`McOptions::seed`].

// Per-channel loops index several RGB arrays at once.
#![allow(clippy::needless_range_loop)]

use super::reference::{self, ViewRay};
use super::{cornette_shanks_phase, henyey_greenstein_phase, rayleigh_phase, Atmosphere};
use glam::DVec3;
use rand_core::{RngCore, SeedableRng};
use std::f64::consts::PI;

/// Path count, seed and the cost knobs of the tracer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct McOptions {
    pub paths: usize,
    pub seed: u64,
    /// Most scattering or ground events per path.
    pub max_events: usize,
    /// Panel-length factor of the quadrature of the sun's transmittance at each event.
    pub sun_panel_scale: f64,
    /// Every phase function replaced by the isotropic 1/(4π) (Rayleigh + Mie scattering
    /// together): the medium Hillaire's Ψ_ms assumes, to separate the isotropic
    /// approximation's error from the table's.
    pub isotropic: bool,
}

impl Default for McOptions {
    fn default() -> Self {
        McOptions {
            paths: 2_000,
            seed: 0x0a7e_05be_1e5e_ed01,
            max_events: 64,
            sun_panel_scale: 4.0,
            isotropic: false,
        }
    }
}

/// Estimates with their standard errors (RGB).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct McResult {
    /// Single scattering (the sun estimate at the first vertex).
    pub single: [f64; 3],
    pub single_se: [f64; 3],
    /// Orders two and up (including light the ground reflected).
    pub multiple: [f64; 3],
    pub multiple_se: [f64; 3],
    /// Order two alone: the sun estimate at the second vertex when that vertex is in the air
    /// (scattered twice, no ground) — part of `multiple`, tallied to check it against
    /// `double::double_scattering`.
    pub order2: [f64; 3],
    pub order2_se: [f64; 3],
}

struct Rng(rand_pcg::Pcg64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// An orthonormal frame around unit `n`.
fn frame(n: DVec3) -> (DVec3, DVec3) {
    let a = if n.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
    let u = n.cross(a).normalize();
    (u, n.cross(u))
}

fn around(n: DVec3, cos_t: f64, phi: f64) -> DVec3 {
    let (u, v) = frame(n);
    let s = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    (u * phi.cos() * s + v * phi.sin() * s + n * cos_t).normalize()
}

/// Cosine of a Henyey–Greenstein sample about the forward direction.
fn sample_hg(g: f64, u: f64) -> f64 {
    if g.abs() < 1e-6 {
        return 1.0 - 2.0 * u;
    }
    let k = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - k * k) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// The scattering event at `x` for a path looking along `d`: the sun estimate (per channel,
/// times the path weight `w`) and the continued direction with its updated weight. `norm`
/// divides the scattering coefficients (σ̄ for delta tracking, 1 at the first vertex).
struct Scatter<'a> {
    atm: &'a Atmosphere,
    sun: DVec3,
    opts: &'a McOptions,
}

impl Scatter<'_> {
    fn at(
        &self,
        x: DVec3,
        d: DVec3,
        w: &mut [f64; 3],
        norm: f64,
        rng: &mut Rng,
    ) -> ([f64; 3], DVec3) {
        let atm = self.atm;
        let m = atm.medium(atm.altitude(x));
        let mu_sun = d.dot(self.sun);
        let ts = reference::sun_transmittance_scaled(atm, x, self.sun, self.opts.sun_panel_scale);
        let iso = self.opts.isotropic;
        let phases = |mu: f64| {
            if iso {
                (0.25 / PI, 0.25 / PI)
            } else {
                (rayleigh_phase(mu), cornette_shanks_phase(mu, atm.mie_g))
            }
        };
        let (pr, pm) = phases(mu_sun);
        let nee: [f64; 3] = std::array::from_fn(|c| {
            w[c] * (m.rayleigh[c] * pr + m.mie[c] * pm) / norm * ts[c] * atm.sun_illuminance[c]
        });
        // Continue: Rayleigh (uniform) or Mie (HG) by the channel-mean coefficients.
        let sr: f64 = m.rayleigh.iter().sum();
        let sm: f64 = m.mie.iter().sum();
        let p_r = if iso { 1.0 } else { sr / (sr + sm).max(1e-300) };
        let (u1, u2, u3) = (rng.uniform(), rng.uniform(), rng.uniform());
        let phi = 2.0 * PI * u3;
        let cos_t = if u1 < p_r {
            1.0 - 2.0 * u2
        } else {
            sample_hg(atm.mie_g, u2)
        };
        let nd = around(d, cos_t, phi);
        let q = p_r / (4.0 * PI) + (1.0 - p_r) * henyey_greenstein_phase(cos_t, atm.mie_g);
        let (pr, pm) = phases(cos_t);
        for c in 0..3 {
            w[c] *= (m.rayleigh[c] * pr + m.mie[c] * pm) / (norm * q);
        }
        (nee, nd)
    }
}

/// Runs the tracer for one view ray: single scattering (for checking) and orders ≥ 2.
pub fn trace(atm: &Atmosphere, ray: &ViewRay, opts: &McOptions) -> McResult {
    let (eye, _) = ray.start_and_length(atm);
    let (nodes, _) = reference::view_nodes(atm, ray);
    // First-vertex distribution ∝ weight · mean T · mean σ_s.
    let q: Vec<f64> = nodes
        .iter()
        .map(|n| {
            let m = atm.medium(atm.altitude(eye + n.t * ray.dir));
            let s = m.scattering();
            n.weight * (n.transmittance.iter().sum::<f64>() * s.iter().sum::<f64>()) / 9.0
        })
        .collect();
    let total: f64 = q.iter().sum();
    let mut out = McResult::default();
    if total.is_nan() || total <= 0.0 || opts.paths == 0 {
        return out;
    }
    let mut cdf = Vec::with_capacity(q.len());
    let mut acc = 0.0;
    for v in &q {
        acc += v / total;
        cdf.push(acc);
    }
    let mut rng = Rng(rand_pcg::Pcg64::seed_from_u64(opts.seed));
    let sc = Scatter {
        atm,
        sun: ray.sun,
        opts,
    };
    let majorant = 2.0 * atm.max_extinction().iter().cloned().fold(0.0, f64::max);
    let (mut s1, mut s2, mut m1, mut m2) = ([0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3]);
    let (mut o1, mut o2) = ([0.0; 3], [0.0; 3]);
    for _ in 0..opts.paths {
        let u = rng.uniform();
        let j = cdf.partition_point(|c| *c < u).min(nodes.len() - 1);
        let n = &nodes[j];
        let mut w: [f64; 3] = std::array::from_fn(|c| n.weight * n.transmittance[c] * total / q[j]);
        let x = eye + n.t * ray.dir;
        let (single, d) = sc.at(x, ray.dir, &mut w, 1.0, &mut rng);
        let (multiple, order2) = continue_path(&sc, x, d, w, majorant, &mut rng);
        for c in 0..3 {
            o1[c] += order2[c];
            o2[c] += order2[c] * order2[c];
            s1[c] += single[c];
            s2[c] += single[c] * single[c];
            m1[c] += multiple[c];
            m2[c] += multiple[c] * multiple[c];
        }
    }
    let nf = opts.paths as f64;
    let se = |a: f64, b: f64| ((b / nf - (a / nf).powi(2)).max(0.0) / (nf - 1.0).max(1.0)).sqrt();
    for c in 0..3 {
        out.single[c] = s1[c] / nf;
        out.single_se[c] = se(s1[c], s2[c]);
        out.multiple[c] = m1[c] / nf;
        out.multiple_se[c] = se(m1[c], m2[c]);
        out.order2[c] = o1[c] / nf;
        out.order2_se[c] = se(o1[c], o2[c]);
    }
    out
}

/// The orders ≥ 2 of a path that left vertex `x` along `d` with weight `w`, and its order 2
/// alone (the sun estimate at the next vertex if that is in the air).
fn continue_path(
    sc: &Scatter<'_>,
    mut x: DVec3,
    mut d: DVec3,
    mut w: [f64; 3],
    majorant: f64,
    rng: &mut Rng,
) -> ([f64; 3], [f64; 3]) {
    let atm = sc.atm;
    let mut sum = [0.0; 3];
    let mut order2 = [0.0; 3];
    // Russian roulette below a quarter of the weight the path started with.
    let floor = 0.25 * w.iter().cloned().fold(0.0, f64::max);
    for event in 0..sc.opts.max_events {
        let (exit, ground) = super::ray_exit(atm, x, d);
        // Spectral delta tracking to the next real collision.
        let mut t = 0.0;
        let collided = loop {
            t -= (1.0 - rng.uniform()).ln() / majorant;
            if t >= exit {
                break false;
            }
            let m = atm.medium(atm.altitude(x + t * d));
            let mean = m.extinction.iter().sum::<f64>() / 3.0;
            if rng.uniform() < mean / majorant {
                break true;
            }
            for c in 0..3 {
                w[c] *= (majorant - m.extinction[c]) / (majorant - mean);
            }
        };
        if collided {
            x += t * d;
            let mean = atm.medium(atm.altitude(x)).extinction.iter().sum::<f64>() / 3.0;
            let (nee, nd) = sc.at(x, d, &mut w, mean, rng);
            for c in 0..3 {
                sum[c] += nee[c];
            }
            if event == 0 {
                order2 = nee;
            }
            d = nd;
        } else if ground {
            x += exit * d;
            let n = x.normalize();
            x = n * (atm.ground_radius + 1e-3);
            let cos_sun = n.dot(sc.sun);
            if cos_sun > 0.0 {
                let ts =
                    reference::sun_transmittance_scaled(atm, x, sc.sun, sc.opts.sun_panel_scale);
                for c in 0..3 {
                    sum[c] +=
                        w[c] * atm.ground_albedo[c] / PI * cos_sun * ts[c] * atm.sun_illuminance[c];
                }
            }
            for c in 0..3 {
                w[c] *= atm.ground_albedo[c];
            }
            // Cosine-weighted bounce.
            let (u1, u2) = (rng.uniform(), rng.uniform());
            d = around(n, u1.sqrt(), 2.0 * PI * u2);
        } else {
            break;
        }
        let wmax = w.iter().cloned().fold(0.0, f64::max);
        if event >= 3 && wmax < floor {
            let survive = (wmax / floor).max(0.05);
            if rng.uniform() >= survive {
                break;
            }
            for v in &mut w {
                *v /= survive;
            }
        }
    }
    (sum, order2)
}
