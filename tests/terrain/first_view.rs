//! The player's first view of a height map (`render::terrain_view`) on maps whose answer is
//! known by construction: a cone in one corner block is the target, the eye stands clear of the
//! ground, and side light wins over light from behind or ahead.

use relume::heightmap::HeightMap;
use relume::render::terrain_view::{relief_view, DISTANCE_PER_BLOCK};
use relume::terrain::sun::Sun;

const N: usize = 256;
const CELL: f64 = 30.0;

/// A flat map with a cone of height 1,500 m and radius 40 texels centred at (cx, cy).
fn cone(cx: f64, cy: f64) -> HeightMap {
    let heights = (0..N * N)
        .map(|i| {
            let (x, y) = ((i % N) as f64, (i / N) as f64);
            let d = ((x - cx).powi(2) + (y - cy).powi(2)).sqrt();
            (1500.0 * (1.0 - d / 40.0)).max(0.0) as f32
        })
        .collect();
    HeightMap {
        width: N,
        height: N,
        heights,
        cell_size: [CELL, CELL],
        height_scale: 1.0,
    }
}

#[test]
fn the_view_looks_at_the_most_rugged_block_from_clear_air() {
    // The cone's summit at texel (200, 60): north-east of the centre.
    let map = cone(200.0, 60.0);
    let sun = Sun::new(90.0, 30.0).unwrap();
    let cam = relief_view(&map, &sun, 2.0);
    let summit = glam::Vec3::new(200.5 * CELL as f32, 3000.0, 60.5 * CELL as f32);
    assert!(
        (cam.target - summit).length() < 1.0,
        "target {:?}",
        cam.target
    );
    // The eye sits 0.45 block widths away (32 texels × 30 m per block), or higher when the
    // ground under its line of sight asks for it: never closer.
    let dist = (cam.eye - cam.target).length() as f64;
    let block = (N / 8) as f64 * CELL;
    assert!(dist >= DISTANCE_PER_BLOCK * block * 0.999, "{dist}");
    // Every point of the line of sight before the target is above the ground.
    for k in 0..90 {
        let p = cam.eye + (cam.target - cam.eye) * (k as f32 / 100.0);
        let (c, r) = ((p.x as f64 / CELL - 0.5), (p.z as f64 / CELL - 0.5));
        if (0.0..N as f64).contains(&c) && (0.0..N as f64).contains(&r) {
            let g = map.heights[r as usize * N + c as usize] * 2.0;
            assert!(
                p.y > g,
                "line of sight under the ground at {p:?} (ground {g})"
            );
        }
    }
}

#[test]
fn side_light_wins() {
    // A cone in the middle lit from the east: seen from the north or the south, its lit and its
    // dark flank face the eye (the most varied shading); from the east only the lit one, from
    // the west mostly the dark one.
    let map = cone(128.0, 128.0);
    let cam = relief_view(&map, &Sun::new(90.0, 25.0).unwrap(), 1.0);
    let d = cam.eye - cam.target;
    assert!(
        d.z.abs() > 2.0 * d.x.abs(),
        "the eye should be north or south of the cone, not east or west: offset {d:?}"
    );
}
