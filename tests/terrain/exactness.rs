//! Hard shadows: the accelerated traversal (A2 over the min/max mipmap) equals the exact
//! traversal (A1) on every pixel — on random maps of every small size with plateaus, cliffs and
//! spikes and random suns including exactly axis-aligned ones, 1e-12 off an axis, 45°,
//! elevations just above 0 and near 90°; and on the relief-shadow paper's stress maps. Also: the mipmap's
//! bounds cover every sample the exact traversal can take in a block. The certified sweep
//! equals them too, including the pixels it settles line by line.

use crate::terrain_common;

use proptest::prelude::*;
use relume::heightmap::HeightMap;
use relume::terrain::generate::{generate, Shape};
use relume::terrain::hard::accelerated_traversal::shadowed_accelerated;
use relume::terrain::hard::exact_traversal::{sample_bilinear, shadowed_exact, track_texels};
use relume::terrain::hard::sweep::shadow_mask_sweep;
use relume::terrain::{MinMaxMipmap, Sun, Track};
use terrain_common::strategies::{azimuth, cell, elevation};
use terrain_common::{random_map, Rng};

/// Compare exact (with and without the early stop) and accelerated on every pixel.
fn assert_equal_everywhere(map: &HeightMap, sun: &Sun) -> usize {
    let mip = MinMaxMipmap::build(map);
    let track = Track::new(sun, map.cell_size);
    let (_, max) = map.min_max();
    let (swept, _) = shadow_mask_sweep(map, &track);
    let mut shadowed = 0;
    for row in 0..map.height {
        for col in 0..map.width {
            let exact = shadowed_exact(map, &track, col, row, max);
            let no_stop = shadowed_exact(map, &track, col, row, f32::INFINITY);
            let fast = shadowed_accelerated(map, &mip, &track, col, row);
            assert_eq!(
                exact, no_stop,
                "early stop changed pixel ({col}, {row}) sun {sun:?}"
            );
            assert_eq!(
                exact, fast,
                "accelerated differs at pixel ({col}, {row}) of {}x{} sun {sun:?}",
                map.width, map.height
            );
            assert_eq!(
                exact,
                swept[row * map.width + col],
                "sweep differs at pixel ({col}, {row}) of {}x{} sun {sun:?}",
                map.width,
                map.height
            );
            shadowed += exact as usize;
        }
    }
    shadowed
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn accelerated_equals_exact_on_random_maps(
        w in 1usize..=257, h in 1usize..=129, seed in any::<u64>(),
        az in azimuth(), el in elevation(true), cell in cell(),
    ) {
        let map = random_map(w, h, seed, cell, 1.0);
        assert_equal_everywhere(&map, &Sun::new(az, el).unwrap());
    }

    #[test]
    fn mipmap_bounds_cover_every_sample(w in 1usize..=67, h in 1usize..=41, seed in any::<u64>()) {
        let map = random_map(w, h, seed, [1.0, 1.0], 1.0);
        let mip = MinMaxMipmap::build(&map);
        let mut rng = Rng(seed ^ 0x5eed);
        for iy in 0..h {
            for ix in 0..w {
                // Points of the texel's closed square: corners, edges, random interior.
                let mut points = vec![(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5), (0.5, 0.0), (1.0, 0.5)];
                for _ in 0..4 {
                    points.push((rng.unit(), rng.unit()));
                }
                for (fx, fy) in points {
                    let v = sample_bilinear(&map.heights, w, h, ix as f64 + fx, iy as f64 + fy);
                    for (level, _) in mip.levels.iter().enumerate() {
                        let shift = level + 1;
                        let (max, min) = mip.texel(level, ix >> shift, iy >> shift);
                        prop_assert!(min as f64 <= v && v <= max as f64,
                            "level {level} texel of ({ix},{iy}) bounds [{min}, {max}] miss {v}");
                    }
                }
            }
        }
    }
}

#[test]
fn stress_maps_equal_exact_for_many_suns() {
    for shape in [Shape::Spikes, Shape::Steps, Shape::Cone, Shape::Crater] {
        let map = generate(shape, 96);
        for az in [0.0, 33.0, 90.0, 135.0, 200.0, 270.0, 300.0] {
            for el in [2.0, 10.0, 30.0, 60.0] {
                assert_equal_everywhere(&map, &Sun::new(az, el).unwrap());
            }
        }
    }
}

#[test]
fn termination_with_adversarial_inputs() {
    // Huge heights, tiny and huge cells, one-texel-wide maps: every traversal terminates and
    // the two agree.
    let mut rng = Rng(7);
    for (w, h) in [(1, 1), (1, 200), (200, 1), (2, 2), (63, 17)] {
        for cell in [[1e-6, 1e-6], [1e6, 1e6], [1e-6, 1e6]] {
            let heights: Vec<f32> = (0..w * h)
                .map(|_| match rng.below(3) {
                    0 => 1e30,
                    1 => -1e30,
                    _ => rng.unit() as f32,
                })
                .collect();
            let map = HeightMap::new(w, h, heights, cell);
            for az in [0.0, 45.0, 90.0, 91.0, 180.0 + 1e-12, 359.0] {
                for el in [1e-9, 0.1, 45.0, 89.999_999] {
                    assert_equal_everywhere(&map, &Sun::new(az, el).unwrap());
                }
            }
        }
    }
}

#[test]
fn tracks_touch_at_most_w_plus_h_texels() {
    let map = HeightMap::new(50, 30, vec![0.0; 1500], [1.0, 1.0]);
    for az in [0.0, 10.0, 45.0, 89.0, 90.0, 123.4, 225.0] {
        let track = Track::new(&Sun::new(az, 5.0).unwrap(), map.cell_size);
        for (c, r) in [(0, 0), (49, 29), (25, 15)] {
            let texels = track_texels(&map, &track, c, r);
            assert!(texels.len() <= 80);
            let last = texels.last().unwrap();
            // The track ends at the border of the map.
            assert!(
                last.0 == 0 || last.0 == 49 || last.1 == 0 || last.1 == 29,
                "{last:?}"
            );
        }
    }
}

#[test]
fn ridges_beyond_a_super_block_are_settled_line_by_line() {
    // A long valley (48 × 700) closed by a rough ridge at its north end: with the sun low in the
    // north, rays from the south end graze the ridge more than 256 lines (one super-block of
    // 16 blocks of 16) away, so the sweep settles them through its super-block maxima
    // (terrain::hard::sweep::bands::SUPER). Both outcomes must occur and equal A1.
    let (w, h) = (48, 700);
    let mut rng = Rng(23);
    let heights: Vec<f32> = (0..w * h)
        .map(|i| {
            let ground = rng.unit() as f32;
            if i / w < 12 {
                ground + 60.0 * rng.unit() as f32
            } else {
                ground
            }
        })
        .collect();
    let map = HeightMap::new(w, h, heights, [1.0, 1.0]);
    assert_settled_both_ways(&map, &[0.0, 4.0, 357.0], &[2.0, 3.0, 5.0]);
}

#[test]
fn distant_ridges_are_settled_line_by_line() {
    // Low ground ringed by a rough ridge: at a low sun many rays graze the ridge far from
    // their pixel, the band bound cannot clear them and the sweep settles them line by line
    // from its block history (terrain::hard::sweep::bands). Both outcomes must occur and equal A1.
    let n = 200;
    let mut rng = Rng(11);
    let heights: Vec<f32> = (0..n * n)
        .map(|i| {
            let (x, y) = (i % n, i / n);
            let edge = x.min(y).min(n - 1 - x).min(n - 1 - y);
            let ground = rng.unit() as f32;
            if edge < 8 {
                ground + 24.0 * rng.unit() as f32
            } else {
                ground
            }
        })
        .collect();
    let map = HeightMap::new(n, n, heights, [1.0, 1.0]);
    assert_settled_both_ways(&map, &[0.0, 17.0, 100.0, 181.0, 300.0], &[2.0, 4.0, 6.0]);
}

/// For every sun of `azimuths` × `elevations`: the sweep equals A1 and A2 on every pixel; over
/// all of them, the line-by-line settling found some pixels shadowed and some lit.
fn assert_settled_both_ways(map: &HeightMap, azimuths: &[f64], elevations: &[f64]) {
    let (mut settled, mut shadowed) = (0, 0);
    for &az in azimuths {
        for &el in elevations {
            let sun = Sun::new(az, el).unwrap();
            assert_equal_everywhere(map, &sun);
            let (_, stats) = shadow_mask_sweep(map, &Track::new(&sun, map.cell_size));
            settled += stats.traversed;
            shadowed += stats.traversed_shadowed;
        }
    }
    assert!(
        shadowed > 0 && settled > shadowed,
        "{settled} settled, {shadowed} shadowed"
    );
}
