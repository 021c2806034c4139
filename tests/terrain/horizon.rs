//! Horizon maps: the line sweep equals the exact per-pixel horizon on every pixel (random maps,
//! every direction of N = 4 … 64, anisotropic cells), analytic horizons (a wall, a tilted
//! plane), the sky-view factor of flat ground, and hard shadows from horizon maps against the
//! exact mask.

use crate::terrain_common;

use proptest::prelude::*;
use relume::heightmap::HeightMap;
use relume::terrain::horizon::sweep::horizon_sweep;
use relume::terrain::horizon::{directions, horizon_exact, Direction};
use terrain_common::random_map;

/// The largest |sweep − exact| in degrees over every pixel.
fn worst(map: &HeightMap, dir: &Direction) -> f64 {
    let sweep = horizon_sweep(map, dir, None);
    let track = dir.track(map.cell_size);
    let (_, max) = map.min_max();
    let mut worst = 0.0f64;
    for row in 0..map.height {
        for col in 0..map.width {
            let e = horizon_exact(map, &track, col, row, max);
            let s = sweep[row * map.width + col] as f64;
            worst = worst.max((e - s).abs());
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn sweep_equals_exact_on_random_maps(
        w in 1usize..48, h in 1usize..40, seed in any::<u64>(),
        n in prop::sample::select(vec![4usize, 8, 16, 64]), k in 0usize..64,
        cell in prop::sample::select(vec![[1.0, 1.0], [30.0, 30.0], [1.0, 3.0]]),
    ) {
        let map = random_map(w, h, seed, cell, 20.0);
        let dirs = directions(n, cell);
        let dir = dirs[k % n];
        // f32 storage of the angle: 90° has an ulp of 7.6e-6°.
        let e = worst(&map, &dir);
        prop_assert!(e < 2e-5, "{w}x{h} dir {dir:?}: {e}°");
    }
}

proptest! {
    // Maps wide and tall enough that whole bundles of lines (8 adjacent columns) have every
    // stencil tap on the map: the SIMD path, not only the border one.
    #![proptest_config(ProptestConfig::with_cases(12))]
    #[test]
    fn sweep_equals_exact_on_maps_wider_than_the_bundles(
        w in 40usize..110, h in 40usize..100, seed in any::<u64>(),
        k in 0usize..64, curved in any::<bool>(),
    ) {
        let cell = [30.0, 30.0];
        let map = random_map(w, h, seed, cell, 20.0);
        let dir = directions(64, cell)[k];
        if curved {
            // Against the brute force of the same parabola (the drop grows the slopes' size).
            let radius = 2.0e5;
            let sweep = horizon_sweep(&map, &dir, Some(radius));
            let flat = horizon_sweep(&map, &dir, None);
            let mut e = 0.0f64;
            for row in 0..h {
                for col in 0..w {
                    let exact = parabolic_exact(&map, &dir, col, row, radius);
                    e = e.max((exact - sweep[row * w + col] as f64).abs());
                }
            }
            prop_assert!(e < 2e-5, "{w}x{h} dir {dir:?}: {e}°");
            // The drop only lowers horizons.
            prop_assert!(sweep.iter().zip(&flat).all(|(c, f)| *c <= f + 2e-5));
        } else {
            let e = worst(&map, &dir);
            prop_assert!(e < 2e-5, "{w}x{h} dir {dir:?}: {e}°");
        }
    }
}

#[test]
fn directions_are_near_uniform_and_distinct() {
    for n in [4usize, 8, 16, 64, 128] {
        let dirs = directions(n, [1.0, 1.0]);
        for (k, d) in dirs.iter().enumerate() {
            let target = k as f64 * 360.0 / n as f64;
            let err = relume::terrain::horizon::angle_between(d.azimuth_deg, target);
            let tolerance = relume::terrain::horizon::AZIMUTH_TOLERANCE * 360.0 / n as f64;
            assert!(err <= tolerance + 1e-9, "n {n} k {k}: {d:?}");
        }
        for w in dirs.windows(2) {
            assert!(w[0].azimuth_deg < w[1].azimuth_deg, "{:?}", w);
        }
    }
    // Axis-aligned ones are single steps: north is up the image (row −1).
    let d = directions(4, [1.0, 1.0]);
    assert_eq!((d[0].a, d[0].b, d[1].a, d[1].b), (0, -1, 1, 0));
}

#[test]
fn a_wall_and_a_tilted_plane_have_their_analytic_horizons() {
    // A 10 m wall in column 30 of flat ground, 2 m cells: looking east from column c the wall
    // texel's sample is its centre, 2·(30 − c) m away.
    let (w, h) = (40, 5);
    let mut hs = vec![0.0f32; w * h];
    for r in 0..h {
        hs[r * w + 30] = 10.0;
    }
    let map = HeightMap::new(w, h, hs, [2.0, 2.0]);
    let east = Direction::new(1, 0, [2.0, 2.0]);
    let sweep = horizon_sweep(&map, &east, None);
    for c in 0..30 {
        let want = (10.0f64 / (2.0 * (30 - c) as f64)).atan().to_degrees();
        let got = sweep[2 * w + c] as f64;
        assert!((got - want).abs() < 1e-5, "column {c}: {got} vs {want}");
    }
    // A plane rising east with slope 0.3 (bilinear is exact on it): the horizon is atan(0.3)
    // looking east and −atan(0.3) looking west, away from the borders; north-east, the slope
    // along the direction.
    let (w, h) = (32, 32);
    let hs = (0..w * h).map(|i| 0.3 * (i % w) as f32 * 5.0).collect();
    let map = HeightMap::new(w, h, hs, [5.0, 5.0]);
    for (a, b, slope) in [
        (1, 0, 0.3),
        (-1, 0, -0.3),
        (1, -1, 0.3 / 2f64.sqrt()),
        (2, 1, 0.3 * 2.0 / 5f64.sqrt()),
    ] {
        let d = Direction::new(a, b, [5.0, 5.0]);
        let sweep = horizon_sweep(&map, &d, None);
        let want = slope.atan().to_degrees();
        for r in 4..28 {
            for c in 4..28 {
                let got = sweep[r * w + c] as f64;
                assert!(
                    (got - want).abs() < 1e-4,
                    "({a},{b}) at ({c},{r}): {got} vs {want}"
                );
            }
        }
    }
}

/// What the f32 sweep of `HorizonMap::build` may add to the half step of its u16 quantisation
/// against the exact f64 sweep: 2.5x the largest excess measured by
/// `f32_map_is_the_exact_sweep_within_rounding`, 1.97e-3°. That is a random map's 178 m cliff
/// between two half-metre texels: the bilinear sample a quarter texel from the pixel, rounded
/// to half an f32 ulp of the 178 m difference (8 µm), moves the slope by 0.004°·(0.25/t).
/// On Puget Sound (4096², 64 directions, every texel) the excess measured 3e-5°.
const F32_ROUNDING_DEG: f64 = 5.0e-3;

/// The horizon map (the f32 sweep, quantised) against the exact f64 sweep on every texel and
/// direction: flat and curved ground, square and anisotropic cells, and relief high above sea
/// level (a 30 m relief at 3,000 m on half-metre cells, where f32 heights alone would be
/// 0.03° off at one texel's distance: the sweep works relative to the pixel and to the map's
/// mid-range).
#[test]
fn f32_map_is_the_exact_sweep_within_rounding() {
    use relume::terrain::horizon::map::{decode, HorizonMap, HorizonSettings, STEP_DEG};
    let mut cases = Vec::new();
    for (seed, cell) in [(1u64, [1.0, 1.0]), (2, [30.0, 30.0]), (3, [1.0, 3.0])] {
        cases.push((random_map(61, 47, seed, cell, 20.0), None));
    }
    let mut lidar = random_map(57, 64, 4, [0.5, 0.5], 30.0);
    lidar.heights.iter_mut().for_each(|h| *h += 3000.0);
    cases.push((lidar.clone(), None));
    cases.push((random_map(64, 50, 5, [30.0, 30.0], 200.0), Some(6.371e6)));
    cases.push((lidar, Some(1.0e4)));
    let mut excess = 0.0f64;
    for (map, radius) in &cases {
        let settings = HorizonSettings {
            directions: 64,
            planet_radius: *radius,
        };
        let hm = HorizonMap::build(map, &settings);
        for (d, plane) in hm.directions.iter().zip(&hm.angles) {
            let exact = horizon_sweep(map, d, *radius);
            for (q, e) in plane.iter().zip(&exact) {
                excess = excess.max((decode(*q) - *e as f64).abs() - 0.5 * STEP_DEG);
            }
        }
    }
    eprintln!("largest excess over half a step: {excess:.3e}°");
    // Measured: 1.97e-3° with directions chosen at azimuth tolerance 0.2 (the lidar-like map's
    // cliffs, above), 1.18e-3° with the current tolerance (0.3).
    assert!(excess <= F32_ROUNDING_DEG, "{excess}°");
}

#[test]
fn sky_view_and_shadows_from_the_horizon_map() {
    use relume::terrain::horizon::map::{HorizonMap, HorizonSettings, STEP_DEG};
    use relume::terrain::{hard::relief::shadow_mask, hard::relief::HardMethod, Sun};
    // Flat ground sees the whole sky; a pit of depth d and radius R (here: the centre of a
    // 9-texel-wide square well) sees less.
    let flat = HeightMap::new(16, 16, vec![0.0; 256], [1.0, 1.0]);
    let hm = HorizonMap::build(&flat, &HorizonSettings::flat(16));
    assert!(hm.sky_view().iter().all(|&v| (v - 1.0).abs() < 1e-6));
    // Quantisation: at most half a step from the exact sweep's angle, plus the f32 sweep's
    // rounding (`f32_map_is_the_exact_sweep_within_rounding`).
    let map = random_map(40, 30, 7, [2.0, 2.0], 30.0);
    let hm = HorizonMap::build(&map, &HorizonSettings::flat(32));
    for (d, plane) in hm.directions.iter().zip(&hm.angles) {
        let sweep = horizon_sweep(&map, d, None);
        for (q, s) in plane.iter().zip(&sweep) {
            assert!(
                (relume::terrain::horizon::map::decode(*q) - *s as f64).abs()
                    <= 0.5 * STEP_DEG + F32_ROUNDING_DEG
            );
        }
    }
    // At a stored azimuth the horizon test is the exact test, up to the quantisation and
    // ties: the masks agree on all but a few pixels. (Not on the diagonals: there the sun's
    // sin/cos track is one ulp off the diagonal and touches corner texels the exact diagonal
    // steps over, docs/algorithms.md §4.4.)
    for (k, el) in [(3usize, 10.0), (8, 25.0), (21, 5.0), (30, 2.0)] {
        let d = hm.directions[k];
        assert_ne!(d.a.abs(), d.b.abs());
        let sun = Sun::new(d.azimuth_deg, el).unwrap();
        let exact = shadow_mask(
            &map,
            &sun,
            HardMethod::Exact,
            None,
            &relume::progress::Silent,
        );
        let fast = hm.shadow_mask(&sun);
        let differ = exact.iter().zip(&fast).filter(|(a, b)| a != b).count();
        assert!(
            differ <= 2,
            "direction {k}, {el}°: {differ} of {} differ",
            exact.len()
        );
    }
}

/// The parabolic model by brute force: every sample of P's walk with the drop κ·t², κ =
/// metres_per_t²/(2R) — what the sweep must equal (its hull over f = h − κτ² is exact algebra).
fn parabolic_exact(map: &HeightMap, dir: &Direction, col: usize, row: usize, radius: f64) -> f64 {
    use relume::terrain::hard::exact_traversal::{texel_sample, TrackWalk};
    let track = dir.track(map.cell_size);
    let kappa = track.metres_per_t.powi(2) / (2.0 * radius);
    let zp = map.heights[row * map.width + col] as f64;
    let walk = TrackWalk::new(map, &track, col, row);
    let p = walk.start();
    let mut best = f64::NEG_INFINITY;
    for t in walk {
        let (tm, hq) = texel_sample(map, &track, p, [t.ix, t.iy], t.t_in, t.t_out);
        best = best.max((hq - kappa * tm * tm - zp) / tm);
    }
    (best / track.metres_per_t).atan().to_degrees()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn curved_sweep_equals_the_parabolic_model_on_random_maps(
        w in 1usize..40, h in 1usize..32, seed in any::<u64>(),
        n in prop::sample::select(vec![8usize, 16, 64]), k in 0usize..64,
        radius in prop::sample::select(vec![300.0f64, 6371e3, 1737.4e3]),
    ) {
        // 30 m cells: at R = 300 m the drop over the map (≤ 1.5 km) is kilometres, far beyond
        // the heights (20 m): the hull algebra is exercised hard.
        let map = random_map(w, h, seed, [30.0, 30.0], 20.0);
        let dir = directions(n, map.cell_size)[k % n];
        let sweep = horizon_sweep(&map, &dir, Some(radius));
        for row in 0..h {
            for col in 0..w {
                let e = parabolic_exact(&map, &dir, col, row, radius);
                let s = sweep[row * w + col] as f64;
                // f32 storage of the angle (ulp 7.6e-6° at 90°), as for flat ground.
                prop_assert!((e - s).abs() < 2e-5, "{w}x{h} R {radius} ({col},{row}): {s} vs {e}");
            }
        }
    }
}

#[test]
fn a_tower_beyond_the_curve_of_the_earth() {
    // Flat ground (0 m) with 100 m cells and a 200 m tower 400 texels east of column 0: on a
    // planet of radius R it is seen at atan((200 − D²/2R)/D) (D = 40 km: the drop is 125.6 m);
    // on R = 3000 km the drop (266.7 m) hides it and the nearest sample is the horizon: the
    // own texel's, at the middle of its half transit (25 m): atan(−25/2R).
    let (w, h) = (410, 3);
    let mut hs = vec![0.0f32; w * h];
    for r in 0..h {
        hs[r * w + 400] = 200.0;
    }
    let map = HeightMap::new(w, h, hs, [100.0, 100.0]);
    let east = Direction::new(1, 0, [100.0, 100.0]);
    let track = east.track(map.cell_size);
    for (radius, want) in [
        (
            6371e3,
            ((200.0 - 40e3f64.powi(2) / (2.0 * 6371e3)) / 40e3).atan(),
        ),
        (3000e3, (-25.0 / (2.0 * 3000e3f64)).atan()),
    ] {
        let sweep = horizon_sweep(&map, &east, Some(radius));
        let got = sweep[w] as f64;
        assert!(
            (got - want.to_degrees()).abs() < 1e-6,
            "R {radius}: {got}° vs {}°",
            want.to_degrees()
        );
        // The sphere itself (the reference's geometry) agrees to 1e-4°.
        let sphere = relume::terrain::horizon::horizon_exact_curved(
            &map,
            &track,
            (0, 1),
            (0.0, 200.0),
            radius,
        );
        assert!(
            (sphere - got).abs() < 1e-4,
            "R {radius}: sphere {sphere}° vs {got}°"
        );
    }
}

#[test]
fn curved_horizons_of_a_real_dem_match_the_sphere() {
    // Big Tujunga (SRTM, 30 m, 1.7 km of relief): the sweep's parabola against the exact
    // sphere (the soft-shadow model's slope) on Earth, every 8th pixel and 16 directions.
    let root = env!("CARGO_MANIFEST_DIR");
    let p = relume::pipeline::parse_pipeline(std::path::Path::new(&format!(
        "{root}/pipelines/bigtujunga.ron"
    )))
    .unwrap();
    let map = match relume::load::load_input(&p.input).unwrap() {
        relume::load::LoadedInput::HeightMap(m, _) => m,
        _ => unreachable!(),
    };
    let (min, max) = map.min_max();
    let radius = 6371e3;
    let mut worst = 0.0f64;
    for dir in directions(16, map.cell_size) {
        let track = dir.track(map.cell_size);
        let sweep = horizon_sweep(&map, &dir, Some(radius));
        for row in (0..map.height).step_by(8) {
            for col in (0..map.width).step_by(8) {
                let e = relume::terrain::horizon::horizon_exact_curved(
                    &map,
                    &track,
                    (col, row),
                    (min, max),
                    radius,
                );
                worst = worst.max((e - sweep[row * map.width + col] as f64).abs());
            }
        }
    }
    // The models differ by the sphere's (R + h)/R scale of distances and drops: a relative
    // h/R ≈ 2.7e-4 of the slope at 1.7 km. Measured: 0.0092° at worst (the bar for
    // the sweep against its own model, which it meets to 2e-5°, is 0.01°); margin 1.35x.
    assert!(worst < 0.0125, "worst {worst}°");
}
