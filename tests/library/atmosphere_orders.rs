//! The Monte Carlo tracer's order two against an independent nested quadrature
//! (`atmosphere::double::double_scattering`): both integrate the same double scattering (no
//! ground reflection), one by sampling directions and free flights, one by Gauss–Legendre over
//! the sphere of directions at each node of the view segment.

// Per-channel loops index several RGB arrays at once.
#![allow(clippy::needless_range_loop)]

use relume::atmosphere::double::{double_scattering, Quadrature};
use relume::atmosphere::lut::Luts;
use relume::atmosphere::monte_carlo::{trace, McOptions};
use relume::atmosphere::reference::{self, ViewRay};
use relume::atmosphere::twin::AtmosphereGpu;
use relume::atmosphere::{direction, Atmosphere};

#[test]
fn monte_carlo_order_two_matches_the_nested_quadrature() {
    let atm = Atmosphere::earth();
    let rays = [
        // 5 km, 10° up toward a 30° sun; 5 km, 5° down across a 60° sun.
        (direction(10.0, 0.0), direction(30.0, 0.0)),
        (direction(-5.0, 90.0), direction(60.0, 0.0)),
    ];
    for (dir, sun) in rays {
        let ray = ViewRay {
            eye_altitude: 1_500.0,
            dir,
            sun,
            length: Some(5_000.0),
        };
        // Sphere panels split once (8 Gauss nodes per panel and axis), inner single
        // scattering with 4× longer panels: measured against 2 splits (16 nodes) within
        // 5.6e-4 relative, and against the reference's panels (scale 1) within 1e-14.
        let quad = double_scattering(
            &atm,
            &ray,
            Quadrature {
                split: 1,
                panel_scale: 4.0,
            },
        );
        let mc = trace(
            &atm,
            &ray,
            &McOptions {
                paths: 200_000,
                ..McOptions::default()
            },
        );
        eprintln!(
            "order 2: quadrature {quad:?}, Monte Carlo {:?} ± {:?}",
            mc.order2, mc.order2_se
        );
        for c in 0..3 {
            let z = (mc.order2[c] - quad[c]).abs() / mc.order2_se[c];
            // Measured: at most 1.6 standard errors (ray 1, red; SE 0.5–0.65 % relative);
            // allowed 4 SE plus the quadrature's 2e-3 (4× its measured refinement change).
            assert!(
                (mc.order2[c] - quad[c]).abs() < 4.0 * mc.order2_se[c] + 2e-3 * quad[c],
                "channel {c}: {z:.2} standard errors"
            );
            assert!(mc.order2[c] < mc.multiple[c]);
        }
    }
}

/// Measurement, not an assertion (slow: 54 rays × 20,000 paths): Hillaire's march split into
/// its single part (Ψ_ms zeroed) against the single-scattering quadrature, and its multiple
/// part against the tracer's orders ≥ 2. Prints channels whose multiple part is off > 20 %.
#[test]
#[ignore]
fn hillaire_single_and_multiple_parts() {
    let atm = Atmosphere::earth();
    for sun_el in [90.0, 60.0, 30.0] {
        let sun = direction(sun_el, 0.0);
        let p = AtmosphereGpu::new(&atm, 1500.0, sun, 128_000.0);
        let luts = Luts::build(&p);
        let mut z = luts.clone();
        for v in &mut z.multi_scattering {
            *v = [0.0; 4];
        }
        let (mut ws, mut wm) = (0.0f64, 0.0f64);
        for el in [0.0, -5.0] {
            for az in [0.0, 90.0, 180.0] {
                for s in [1000.0, 10000.0, 100000.0] {
                    let ray = ViewRay {
                        eye_altitude: 1500.0,
                        dir: direction(el, az),
                        sun,
                        length: Some(s),
                    };
                    let (_, s) = ray.start_and_length(&atm);
                    let d = direction(el, az).as_vec3();
                    let (full, _) = luts.march_segment(d, (s / 1000.0) as f32, 64);
                    let (single, _) = z.march_segment(d, (s / 1000.0) as f32, 64);
                    let ss = reference::single_scattering(&atm, &ray).inscatter;
                    let mc = trace(
                        &atm,
                        &ray,
                        &McOptions {
                            paths: 20_000,
                            ..McOptions::default()
                        },
                    );
                    for c in 0..3 {
                        let es = (single[c] as f64 - ss[c]).abs() / ss[c];
                        let hm = (full[c] - single[c]) as f64;
                        let em = (hm - mc.multiple[c]) / mc.multiple[c];
                        ws = ws.max(es);
                        wm = wm.max(em.abs());
                        if em.abs() > 0.2 {
                            eprintln!("sun {sun_el} el {el} az {az} s {s:.0} c{c}: single rel {es:.4}, multi H {hm:.3e} MC {:.3e} ± {:.1e} ({em:+.3})", mc.multiple[c], mc.multiple_se[c]);
                        }
                    }
                }
            }
        }
        eprintln!("sun {sun_el}: Hillaire single part vs quadrature max rel {ws:.4}; multiple part vs MC orders>=2 max rel {wm:.4}");
    }
}

/// Measurement, not an assertion (slow): where Hillaire's multiple part goes wrong. For each
/// sun and view segment, Hillaire's multiple part (full march − march with Ψ_ms zeroed) with the
/// twin's table (8² directions, 20 steps) and a CPU-only fine one (32² directions, 100 steps),
/// against the tracer's orders ≥ 2 with the real phase functions and with every phase
/// isotropic (the medium Ψ_ms assumes). Then with a black ground: the table's order two alone
/// (L₂, no series) against the isotropic tracer's order two, and the full series against its
/// orders ≥ 2. `RELUME_MC_PATHS` sets the paths (default 10,000).
#[test]
#[ignore]
fn hillaire_multiple_part_diagnosis() {
    use relume::atmosphere::lut::MultiQuality;
    let paths = std::env::var("RELUME_MC_PATHS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000);
    let fine = MultiQuality {
        azimuths: 16,
        bands: 64,
        steps: 100,
        all_orders: true,
        horizon: false,
    };
    let l2_only = MultiQuality {
        all_orders: false,
        ..MultiQuality::TWIN
    };
    for black in [false, true] {
        let mut atm = Atmosphere::earth();
        if black {
            atm.ground_albedo = [0.0; 3];
        }
        for sun_el in [90.0, 60.0, 30.0, 10.0] {
            let sun = direction(sun_el, 0.0);
            let p = AtmosphereGpu::new(&atm, 1500.0, sun, 128_000.0);
            let multi = |l: &Luts, d, s| {
                let mut z = l.clone();
                for v in &mut z.multi_scattering {
                    *v = [0.0; 4];
                }
                let (full, _) = l.march_segment(d, s, 64);
                let (single, _) = z.march_segment(d, s, 64);
                full - single
            };
            let twin = Luts::build(&p);
            let other = Luts::build_with(&p, if black { l2_only } else { fine });
            for (el, az, s) in [
                (0.0, 0.0, 10_000.0),
                (0.0, 90.0, 10_000.0),
                (0.0, 180.0, 10_000.0),
                (0.0, 90.0, 100_000.0),
                (-5.0, 90.0, 100_000.0),
            ] {
                let ray = ViewRay {
                    eye_altitude: 1500.0,
                    dir: direction(el, az),
                    sun,
                    length: Some(s),
                };
                let (_, len) = ray.start_and_length(&atm);
                let d = direction(el, az).as_vec3();
                let km = (len / 1000.0) as f32;
                let (ht, ho) = (multi(&twin, d, km), multi(&other, d, km));
                let opts = McOptions {
                    paths,
                    ..McOptions::default()
                };
                let mc = trace(&atm, &ray, &opts);
                let iso = trace(
                    &atm,
                    &ray,
                    &McOptions {
                        isotropic: true,
                        ..opts
                    },
                );
                let r = |h: f32, m: f64| h as f64 / m - 1.0;
                for c in 0..3 {
                    let head = format!(
                        "sun {sun_el:>2} el {el:>3} az {az:>3} s {:>3} km c{c}:",
                        s / 1000.0
                    );
                    if black {
                        eprintln!(
                            "black {head} L2/iso2 {:+.3} (se {:.3}) | twin/iso {:+.3} (se {:.3}) | twin/MC {:+.3}",
                            r(ho[c], iso.order2[c]),
                            iso.order2_se[c] / iso.order2[c],
                            r(ht[c], iso.multiple[c]),
                            iso.multiple_se[c] / iso.multiple[c],
                            r(ht[c], mc.multiple[c]),
                        );
                    } else {
                        eprintln!(
                            "{head} twin/MC {:+.3} fine/MC {:+.3} | twin/iso {:+.3} fine/iso {:+.3} | iso/MC {:+.3} (MC se {:.3}, iso se {:.3})",
                            r(ht[c], mc.multiple[c]),
                            r(ho[c], mc.multiple[c]),
                            r(ht[c], iso.multiple[c]),
                            r(ho[c], iso.multiple[c]),
                            iso.multiple[c] / mc.multiple[c] - 1.0,
                            mc.multiple_se[c] / mc.multiple[c],
                            iso.multiple_se[c] / iso.multiple[c],
                        );
                    }
                }
            }
        }
    }
}

/// The multiple-scattering table's sampling (4 azimuths × 16 bands crowded at the horizon, 20
/// quadratic steps: what the kernel computes) against the same integral by a fine quadrature
/// (32 × 256 directions, 400 steps), order two alone and the whole series, with and without
/// the ground's light, from 0.1 to 20 km and for suns from the zenith to below the horizon.
/// The paper's uniform 8 × 8 directions are checked to miss by more (the horizon peak).
#[test]
fn multiple_scattering_sampling_matches_a_fine_quadrature() {
    use relume::atmosphere::lut::{multi_scattering_at, MultiQuality};
    let fine = MultiQuality {
        azimuths: 32,
        bands: 256,
        steps: 400,
        all_orders: true,
        horizon: true,
    };
    let (mut worst, mut worst_paper) = (0.0f32, 0.0f32);
    for black in [true, false] {
        let mut atm = Atmosphere::earth();
        if black {
            atm.ground_albedo = [0.0; 3];
        }
        let p = AtmosphereGpu::new(&atm, 1500.0, direction(90.0, 0.0), 128_000.0);
        let luts = Luts::build(&p);
        for km in [0.1f32, 1.5, 5.0, 20.0] {
            let r = p.ground() + km;
            for mu_s in [1.0f32, 0.3, -0.05] {
                for all_orders in [false, true] {
                    let at = |q: MultiQuality| {
                        let q = MultiQuality { all_orders, ..q };
                        multi_scattering_at(&p, &luts.transmittance, r, mu_s, q)
                    };
                    let (twin, paper, reference) =
                        (at(MultiQuality::TWIN), at(MultiQuality::PAPER), at(fine));
                    for c in 0..3 {
                        let e = (twin[c] / reference[c] - 1.0).abs();
                        let ep = (paper[c] / reference[c] - 1.0).abs();
                        eprintln!("black {black} {km} km mu_s {mu_s} all {all_orders} c{c}: twin {e:.4} paper {ep:.4}");
                        worst = worst.max(e);
                        worst_paper = worst_paper.max(ep);
                    }
                }
            }
        }
    }
    eprintln!("worst relative error: twin sampling {worst:.4}, paper's {worst_paper:.4}");
    // Measured: 0.019 (20 km, sun 3° below the horizon, green); bound 1.5× that.
    assert!(worst < 0.03, "twin sampling off by {worst}");
    // Measured: 0.32 (20 km, same sun, red); the new sampling must stay 5× better.
    assert!(worst_paper > 5.0 * worst, "{worst_paper} vs {worst}");
}
