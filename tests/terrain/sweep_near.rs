//! The certified sweep's near stencil (terrain::hard::sweep::near) against the exact test: on random
//! maps and suns (exactly axis-aligned, 1e-12 and 1e-10 off an axis, 45°, elevations just above
//! 0 and near 90°, anisotropic cells), for every pixel whose taps lie on the map, a stencil
//! "shadowed" means a texel of the track's first `lines` major-axis lines passes the exact test
//! (and `shadowed_exact` is true), a stencil "clear" means none does; "undecided" is allowed.

use crate::terrain_common;

use proptest::prelude::*;
use relume::heightmap::HeightMap;
use relume::terrain::hard::exact_traversal::{shadowed_exact, texel_sample, track_texels};
use relume::terrain::hard::sweep::near::{decide, Axes, NearStencil};
use relume::terrain::transpose::transpose;
use relume::terrain::{Sun, Track, TrackKind};
use terrain_common::random_map;
use terrain_common::strategies::{azimuth, cell, elevation};

/// Check the stencil on every pixel it covers; returns (decided, undecided).
fn check_stencil(map: &HeightMap, sun: &Sun, lines: i64) -> (usize, usize) {
    let track = Track::new(sun, map.cell_size);
    if track.kind != TrackKind::Ray {
        return (0, 0);
    }
    // The sweep's canonical frame: rows along the major axis.
    let transposed = track.ux.abs() > track.uy.abs();
    let x_axis = (track.ux, track.step_x, track.inv_ux);
    let y_axis = (track.uy, track.step_y, track.inv_uy);
    let (w, h, z, axes) = if transposed {
        let z = transpose(&map.heights, map.width, map.height);
        let axes = Axes {
            x: y_axis,
            y: x_axis,
        };
        (map.height, map.width, z, axes)
    } else {
        let axes = Axes {
            x: x_axis,
            y: y_axis,
        };
        (map.width, map.height, map.heights.clone(), axes)
    };
    let (lo, hi) = map.min_max();
    let st = NearStencil::new(axes, track.rise_per_t, lines, hi as f64 - lo as f64);
    let (mut decided, mut undecided) = (0, 0);
    let (a, b) = st.x_range(w);
    for y in 0..h {
        if !st.row_inside(y, h) || a > b {
            continue;
        }
        let mut near = vec![0.0f32; (b - a + 1) as usize];
        st.row_max(&z, w, y, a as usize, &mut near);
        for x in a..=b {
            let (col, row) = if transposed {
                (y, x as usize)
            } else {
                (x as usize, y)
            };
            let zp = map.heights[row * map.width + col] as f64;
            let p = [col as f64 + 0.5, row as f64 + 0.5];
            let major = |t: &(i64, i64, f64, f64)| if transposed { t.0 } else { t.1 };
            let own = if transposed { col } else { row } as i64;
            let near_texels: Vec<_> = track_texels(map, &track, col, row)
                .into_iter()
                .take_while(|t| (major(t) - own).abs() < lines)
                .collect();
            let above = near_texels.iter().any(|t| {
                let (t_mid, hq) = texel_sample(map, &track, p, [t.0, t.1], t.2, t.3);
                hq - zp > track.rise_per_t * t_mid
            });
            match decide(near[(x - a) as usize], st.margin) {
                Some(v) => {
                    decided += 1;
                    assert_eq!(
                        v, above,
                        "stencil says {v} at ({col}, {row}) of {}x{}, sun {sun:?}, lines {lines}, v {}",
                        map.width, map.height, near[(x - a) as usize]
                    );
                    if v {
                        let (_, max) = map.min_max();
                        assert!(shadowed_exact(map, &track, col, row, max));
                    }
                }
                None => undecided += 1,
            }
        }
    }
    (decided, undecided)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn the_stencil_agrees_with_the_exact_test(
        w in 1usize..=97, h in 1usize..=71, seed in any::<u64>(),
        az in azimuth(), el in elevation(false), cell in cell(),
        lines in prop::sample::select(vec![1i64, 2, 3, 8]),
        scale in prop::sample::select(vec![1.0f32, 1e-3, 1e3]),
    ) {
        let map = random_map(w, h, seed, cell, scale);
        check_stencil(&map, &Sun::new(az, el).unwrap(), lines);
    }
}

#[test]
fn the_stencil_decides_almost_every_pixel_of_smooth_terrain() {
    // A smooth map with no ties: the margin leaves (almost) nothing undecided.
    let (w, h) = (80, 60);
    let heights: Vec<f32> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            30.0 * (x * 0.21).sin() * (y * 0.17).cos() + 0.3 * x
        })
        .collect();
    let map = HeightMap::new(w, h, heights, [10.0, 10.0]);
    for (az, el) in [(300.0, 5.0), (30.0, 2.0), (135.0, 45.0), (90.0, 10.0)] {
        let (decided, undecided) = check_stencil(&map, &Sun::new(az, el).unwrap(), 8);
        assert!(
            decided > 1000 && undecided * 100 <= decided,
            "{az} {el}: {decided} {undecided}"
        );
    }
}
