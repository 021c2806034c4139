//! Soft shadows: the disc model's laws, a straight wall's analytic penumbra, the hard-shadow
//! limit α → 0, branch-and-bound equal to the exhaustive reference (random maps, both real
//! DEMs), dynamic programming never darker than the reference, the terminator on a planet
//! without relief, and extremes (sun below the horizon, axis-aligned and zenith suns, huge and
//! tiny scales).

use crate::terrain_common;

use proptest::prelude::*;
use relume::heightmap::HeightMap;
use relume::progress::Silent;
use relume::terrain::hard::relief::{shadow_mask, HardMethod};
use relume::terrain::soft::model::lit;
use relume::terrain::soft::{soft_shadow_map, SoftContext, SoftMethod, SoftShadowParams};
use relume::terrain::{MinMaxMipmap, Sun};
use terrain_common::random_map;

fn params(method: SoftMethod, radius_deg: f64, planet: Option<f64>) -> SoftShadowParams {
    SoftShadowParams {
        sun_radius_deg: radius_deg,
        planet_radius_m: planet,
        method,
    }
}

fn all(map: &HeightMap, sun: &Sun, p: &SoftShadowParams) -> Vec<f32> {
    soft_shadow_map(map, sun, p, None, &Silent).unwrap()
}

#[test]
fn lit_is_one_half_zero_and_monotone() {
    assert_eq!(lit(1.0), 1.0);
    assert!((lit(0.0) - 0.5).abs() < 1e-15);
    assert_eq!(lit(-1.0), 0.0);
    let v: Vec<f64> = (0..=400).map(|i| lit(-1.0 + i as f64 / 200.0)).collect();
    assert!(v.windows(2).all(|w| w[0] <= w[1]));
    // Symmetry: the hidden part at d is the visible part at −d.
    for d in [0.1, 0.5, 0.9] {
        assert!((lit(d) + lit(-d) - 1.0).abs() < 1e-12);
    }
}

/// A wall of height `wall_h` across the whole map (columns [x0, x1)), sun in the west.
fn wall_map(w: usize, h: usize, x0: usize, x1: usize, wall_h: f32) -> HeightMap {
    let mut heights = vec![0.0f32; w * h];
    for r in 0..h {
        for c in x0..x1 {
            heights[r * w + c] = wall_h;
        }
    }
    HeightMap::new(w, h, heights, [1.0, 1.0])
}

#[test]
fn a_straight_wall_casts_the_analytic_penumbra() {
    // The model is exact for a prism: behind a wall of height H at distance D the edge is at
    // β = atan(H/D), so lit = lit((e − β)/α). An axis-aligned track samples the wall's texel
    // centres exactly, so the match is to rounding.
    let (w, h, x0, x1, wall_h) = (160, 3, 20, 24, 10.0f32);
    let map = wall_map(w, h, x0, x1, wall_h);
    for (el, alpha) in [(10.0f64, 0.2666f64), (10.0, 2.0), (4.0, 1.0)] {
        let sun = Sun::new(270.0, el).unwrap();
        for method in [
            SoftMethod::Exhaustive,
            SoftMethod::BranchAndBound,
            SoftMethod::DynamicProgramming {
                start_level: -1,
                intervals: 0,
            },
        ] {
            let l = all(&map, &sun, &params(method, alpha, None));
            let mut penumbra = 0;
            for c in x1..w {
                let d = (c - x1 + 1) as f64; // from the wall's last texel centre
                let theta = el.to_radians() - (wall_h as f64 / d).atan();
                let expected = lit(theta / alpha.to_radians());
                let got = l[w + c] as f64;
                assert!(
                    (got - expected).abs() < 1e-5,
                    "{method:?} el {el} α {alpha}: column {c}: {got} vs {expected}"
                );
                penumbra += (expected > 0.01 && expected < 0.99) as usize;
            }
            assert!(penumbra >= 2, "the test should cross a penumbra");
        }
    }
}

#[test]
fn tiny_sun_reproduces_hard_shadows_off_the_boundary() {
    let maps = [
        random_map(97, 61, 11, [1.0, 1.0], 1.0),
        random_map(64, 64, 12, [30.0, 30.0], 20.0),
        relume::terrain::generate::generate(relume::terrain::generate::Shape::Spikes, 128),
    ];
    for map in &maps {
        for (az, el) in [
            (0.0, 10.0),
            (90.0, 3.0),
            (135.0, 25.0),
            (300.0, 7.0),
            (200.0, 45.0),
        ] {
            let sun = Sun::new(az, el).unwrap();
            let hard = shadow_mask(map, &sun, HardMethod::Exact, None, &Silent);
            let soft = all(map, &sun, &params(SoftMethod::Exhaustive, 1e-7, None));
            let mut boundary = 0;
            for (i, (&s, &l)) in hard.iter().zip(&soft).enumerate() {
                if l == 0.0 || l == 1.0 {
                    assert_eq!(s, l == 0.0, "pixel {i} az {az} el {el}: hard {s}, lit {l}");
                } else {
                    boundary += 1;
                }
            }
            assert!(boundary * 1000 <= hard.len(), "{boundary} boundary pixels");
        }
    }
}

fn assert_bnb_equals_exhaustive(
    map: &HeightMap,
    sun: &Sun,
    alpha: f64,
    planet: Option<f64>,
    rows: &[usize],
) -> f64 {
    let mip = MinMaxMipmap::build(map);
    let ex = SoftContext::new(
        map,
        &mip,
        sun,
        &params(SoftMethod::Exhaustive, alpha, planet),
    )
    .unwrap();
    let bb = SoftContext::new(
        map,
        &mip,
        sun,
        &params(SoftMethod::BranchAndBound, alpha, planet),
    )
    .unwrap();
    let dp = SoftContext::new(
        map,
        &mip,
        sun,
        &params(
            SoftMethod::DynamicProgramming {
                start_level: 3,
                intervals: 0,
            },
            alpha,
            planet,
        ),
    )
    .unwrap();
    let a = ex.rows(rows, &Silent);
    let b = bb.rows(rows, &Silent);
    let d = dp.rows(rows, &Silent);
    let mut penumbra = 0.0;
    for (i, ((x, y), z)) in a.iter().zip(&b).zip(&d).enumerate() {
        assert!(
            (x - y).abs() <= 1e-6,
            "pixel {i}: exhaustive {x}, branch and bound {y} (sun {sun:?})"
        );
        assert!(
            *z >= *x - 1e-6,
            "pixel {i}: dynamic programming {z} darker than exhaustive {x}"
        );
        penumbra += (*x > 0.0 && *x < 1.0) as u8 as f64;
    }
    penumbra / a.len() as f64
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn branch_and_bound_equals_exhaustive_on_random_maps(
        w in 1usize..=120, h in 1usize..=90, seed in any::<u64>(),
        az in prop_oneof![Just(0.0), Just(90.0), Just(225.0), 0.0..360.0f64],
        el in prop_oneof![Just(0.1), Just(89.9), -1.0..30.0f64],
        alpha in prop_oneof![Just(0.2666), 0.01..3.0f64],
        planet in prop_oneof![Just(None), Just(Some(1_737_400.0)), Just(Some(2_000.0))],
        cell in prop::sample::select(vec![[1.0, 1.0], [30.0, 30.0], [2.0, 0.5]]),
    ) {
        let map = random_map(w, h, seed, cell, 3.0);
        let rows: Vec<usize> = (0..h).collect();
        assert_bnb_equals_exhaustive(&map, &Sun::new(az, el).unwrap(), alpha, planet, &rows);
    }
}

fn load(pipeline: &str) -> HeightMap {
    let root = env!("CARGO_MANIFEST_DIR");
    let p = relume::pipeline::parse_pipeline(std::path::Path::new(&format!(
        "{root}/pipelines/{pipeline}"
    )))
    .unwrap();
    match relume::load::load_input(&p.input).unwrap() {
        relume::load::LoadedInput::HeightMap(m, _) => m,
        _ => unreachable!(),
    }
}

#[test]
fn branch_and_bound_equals_exhaustive_on_real_dems() {
    // Budget: the exhaustive reference walks the whole track at low sun; every 4th row of the
    // half-size SRTM map and of Puget Sound at 512² (all columns), 3 elevations × 4 azimuths.
    for (name, map) in [
        ("SRTM", load("bigtujunga.ron").downsample(2)),
        ("Puget", load("puget-sound.ron").downsample(8)),
    ] {
        let rows: Vec<usize> = (0..map.height).step_by(4).collect();
        let mut penumbra = 0.0;
        for az in [0.0, 100.0, 225.0, 300.0] {
            for el in [2.0, 5.0, 10.0] {
                penumbra += assert_bnb_equals_exhaustive(
                    &map,
                    &Sun::new(az, el).unwrap(),
                    0.2666,
                    None,
                    &rows,
                );
            }
        }
        assert!(penumbra > 0.0, "{name}: some penumbra");
    }
}

#[test]
fn terminator_on_a_planet_without_relief() {
    // A 96 km × 96 km flat map on the Moon with the sun on the horizon at its centre: the local
    // sun elevation varies by ±1.6° across it. Geometry: the texel at arc offset a from the centre
    // has the normal n = (sin(|a|/R)·â, cos(|a|/R)); sin e_P = n·s.
    let (n, cell, radius) = (96usize, 1000.0f64, 1_737_400.0f64);
    let map = HeightMap::new(n, n, vec![0.0; n * n], [cell, cell]);
    for (az, el) in [(90.0, 0.0), (210.0, 0.3), (0.0, -0.2)] {
        let sun = Sun::new(az, el).unwrap();
        let s = sun.direction();
        let alpha = 0.2666f64.to_radians();
        for method in [
            SoftMethod::Exhaustive,
            SoftMethod::BranchAndBound,
            SoftMethod::Uniform { steps: 16 },
        ] {
            let l = all(&map, &sun, &params(method, 0.2666, Some(radius)));
            let (mut dark, mut lit_count, mut penumbra) = (0, 0, 0);
            for r in 0..n {
                for c in 0..n {
                    let ax = (c as f64 + 0.5 - n as f64 / 2.0) * cell;
                    let ay = -(r as f64 + 0.5 - n as f64 / 2.0) * cell;
                    let len = ax.hypot(ay);
                    let ang = len / radius;
                    let nrm = if len > 0.0 {
                        [ang.sin() * ax / len, ang.sin() * ay / len, ang.cos()]
                    } else {
                        [0.0, 0.0, 1.0]
                    };
                    let e = (nrm[0] * s[0] + nrm[1] * s[1] + nrm[2] * s[2]).asin();
                    let got = l[r * n + c] as f64;
                    assert!(
                        (got - lit(e / alpha)).abs() < 1e-5,
                        "{method:?}: texel ({c}, {r}) e {e}: {got}"
                    );
                    if got == 0.0 {
                        assert!(e <= -alpha + 1e-9);
                        dark += 1;
                    } else if got == 1.0 {
                        assert!(e >= alpha - 1e-9);
                        lit_count += 1;
                    } else {
                        penumbra += 1;
                    }
                }
            }
            assert!(
                dark > 0 && lit_count > 0 && penumbra > 0,
                "{dark} {lit_count} {penumbra}"
            );
        }
    }
}

#[test]
fn extremes_stay_finite_and_below_the_horizon_is_dark() {
    let maps = [
        random_map(40, 30, 5, [1e-6, 1e-6], 1.0),
        random_map(40, 30, 6, [1e6, 1e6], 1e6),
        random_map(1, 50, 7, [1.0, 1.0], 1.0),
        HeightMap::new(
            3,
            3,
            vec![1e30, -1e30, 0.0, 5.0, 1e30, -1e30, 0.0, 1.0, 2.0],
            [1.0, 1.0],
        ),
    ];
    let methods = [
        SoftMethod::Exhaustive,
        SoftMethod::Uniform { steps: 100 },
        SoftMethod::DynamicProgramming {
            start_level: 4,
            intervals: 2,
        },
        SoftMethod::BranchAndBound,
    ];
    for map in &maps {
        for method in methods {
            for planet in [None, Some(1.0), Some(6.371e6), Some(1e15)] {
                for (az, el) in [
                    (0.0, 90.0),
                    (90.0, 45.0),
                    (180.0, 0.5),
                    (270.0 + 1e-12, 10.0),
                    (33.0, -0.5),
                ] {
                    let l = all(
                        map,
                        &Sun::new(az, el).unwrap(),
                        &params(method, 0.2666, planet),
                    );
                    assert!(
                        l.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)),
                        "{method:?} {planet:?} {az} {el}"
                    );
                }
                // More than α below the horizon: dark everywhere. On a planet the local
                // elevation varies by up to (map extent)/R, so check where that is under 0.5 rad
                // with the sun 60° below the centre's horizon.
                let extent =
                    (map.width as f64 * map.cell_size[0]).max(map.height as f64 * map.cell_size[1]);
                if planet.is_some_and(|r| extent / r > 0.5) {
                    continue;
                }
                let l = all(
                    map,
                    &Sun::new(10.0, if planet.is_some() { -60.0 } else { -0.3 }).unwrap(),
                    &params(method, 0.2666, planet),
                );
                assert!(l.iter().all(|v| *v == 0.0), "{method:?} {planet:?}");
            }
        }
    }
    // The zenith: fully lit on flat ground.
    let flat = HeightMap::new(8, 8, vec![0.0; 64], [1.0, 1.0]);
    assert!(all(
        &flat,
        &Sun::new(0.0, 90.0).unwrap(),
        &SoftShadowParams::default()
    )
    .iter()
    .all(|v| *v == 1.0));
}

#[test]
fn bad_knobs_are_refused() {
    let map = HeightMap::new(2, 2, vec![0.0; 4], [1.0, 1.0]);
    let sun = Sun::new(0.0, 10.0).unwrap();
    for p in [
        params(SoftMethod::Exhaustive, 0.0, None),
        params(SoftMethod::Exhaustive, f64::NAN, None),
        params(SoftMethod::Exhaustive, 0.2666, Some(-5.0)),
        params(SoftMethod::Uniform { steps: 0 }, 0.2666, None),
    ] {
        assert!(
            soft_shadow_map(&map, &sun, &p, None, &Silent).is_err(),
            "{p:?}"
        );
    }
}
