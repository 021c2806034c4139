//! Hard shadows of analytic shapes agree with geometry to within one texel: a wall's shadow is
//! h/tan e long, a cone's shadow apex lies h/tan e from its apex, and the shadow boundaries of a
//! hemisphere on flat ground and of a hemispherical bowl (crater) match their closed forms
//! everywhere except within one texel of the analytic boundary.

use relume::heightmap::HeightMap;
use relume::terrain::generate::{centre, generate, Shape};
use relume::terrain::hard::relief::{shadow_mask, HardMethod};
use relume::terrain::Sun;

fn mask(map: &HeightMap, sun: &Sun) -> Vec<bool> {
    shadow_mask(
        map,
        sun,
        HardMethod::Accelerated,
        None,
        &relume::progress::Silent,
    )
}

/// Texel-space x (column direction) of the last shadowed texel centre on `row`.
fn last_shadowed_x(map: &HeightMap, m: &[bool], row: usize) -> f64 {
    let c = (0..map.width)
        .rev()
        .find(|&c| m[row * map.width + c])
        .expect("some shadow");
    c as f64 + 0.5
}

#[test]
fn wall_shadow_is_h_over_tan_e_long() {
    let n = 256;
    let map = generate(Shape::Wall, n);
    let h = n as f64 / 8.0;
    // The wall's east face is at x = n/2 + n/32; its last full-height texel centre half a texel
    // before. Sun in the west: the shadow falls east.
    let east_centre = (n / 2 + n / 32) as f64 - 0.5;
    for el in [20.0f64, 30.0, 45.0, 60.0, 75.0] {
        let m = mask(&map, &Sun::new(270.0, el).unwrap());
        let expected = east_centre + h / el.to_radians().tan();
        for row in [0, n / 2, n - 1] {
            let got = last_shadowed_x(&map, &m, row);
            assert!(
                (got - expected).abs() <= 1.0,
                "el {el}: shadow ends at {got}, expected {expected}"
            );
        }
        // West of the wall (sunny side) nothing is shadowed.
        assert!(!m[(n / 2) * n + n / 2 - 2]);
    }
}

#[test]
fn cone_shadow_apex_is_h_over_tan_e_from_the_apex() {
    let n = 256;
    let map = generate(Shape::Cone, n);
    let (cx, cy) = centre(n);
    let h = n as f64 / 4.0;
    for el in [30.0f64, 35.0, 40.0] {
        // Sun in the west: the apex's shadow lies east of it on the apex row.
        let m = mask(&map, &Sun::new(270.0, el).unwrap());
        let got = last_shadowed_x(&map, &m, cy as usize);
        let expected = cx + h / el.to_radians().tan();
        assert!(
            (got - expected).abs() <= 1.0,
            "el {el}: tip at {got}, expected {expected}"
        );
        // Sun in the north: the shadow points south (down the image, larger rows).
        let m = mask(&map, &Sun::new(0.0, el).unwrap());
        let col = cx as usize;
        let last_row = (0..n).rev().find(|&r| m[r * n + col]).unwrap() as f64 + 0.5;
        assert!(
            (last_row - (cy + h / el.to_radians().tan())).abs() <= 1.0,
            "el {el}: {last_row}"
        );
    }
}

/// World position (x east, y north, z up) of texel (col, row) of an analytic map.
fn world(map: &HeightMap, col: usize, row: usize) -> [f64; 3] {
    [
        col as f64 + 0.5,
        -(row as f64 + 0.5),
        map.at(col, row) as f64,
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Compare a mask with an analytic classification: mismatches are allowed only on texels whose
/// 3×3 neighbourhood (one texel around) holds both analytic classes, or both flat ground and
/// the sphere — at the rim the sphere's tangent is vertical, which a bilinear height field
/// cannot represent: the ramp from the rim texel to the ground texel beside it is the only place
/// where the two surfaces differ by more than a texel's worth.
fn assert_matches_within_one_texel(
    map: &HeightMap,
    m: &[bool],
    analytic: &dyn Fn(usize, usize) -> bool,
    what: &str,
) {
    let (w, h) = (map.width, map.height);
    let truth: Vec<bool> = (0..w * h).map(|i| analytic(i % w, i / w)).collect();
    let on_sphere = |c: usize, r: usize| map.at(c, r) != 0.0;
    let mut bad = Vec::new();
    let mut boundary = 0;
    for r in 0..h {
        for c in 0..w {
            let t = truth[r * w + c];
            let mut mixed = false;
            for dr in -1i64..=1 {
                for dc in -1i64..=1 {
                    let (rr, cc) = (r as i64 + dr, c as i64 + dc);
                    if rr >= 0 && cc >= 0 && rr < h as i64 && cc < w as i64 {
                        mixed |= truth[rr as usize * w + cc as usize] != t
                            || on_sphere(cc as usize, rr as usize) != on_sphere(c, r);
                    }
                }
            }
            boundary += mixed as usize;
            if !mixed && m[r * w + c] != t {
                bad.push((c, r, t));
            }
        }
    }
    assert!(
        truth.iter().any(|t| *t) && boundary > 0,
        "{what}: the analytic shadow is empty"
    );
    assert!(
        bad.is_empty(),
        "{what}: {} texels off by more than one texel, e.g. {:?}",
        bad.len(),
        &bad[..bad.len().min(8)]
    );
}

#[test]
fn hemisphere_shadow_matches_the_sphere() {
    let n = 192;
    let map = generate(Shape::Hemisphere, n);
    let (cx, cy) = centre(n);
    let r = n as f64 / 4.0;
    let c = [cx, -cy, 0.0];
    for (az, el) in [(270.0, 30.0), (135.0, 40.0), (20.0, 55.0)] {
        let sun = Sun::new(az, el).unwrap();
        let s = sun.direction();
        let analytic = |col: usize, row: usize| {
            let p = world(&map, col, row);
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            if p[2] > 0.0 {
                // On the dome (convex): shadowed iff it faces away from the sun.
                dot(d, s) < 0.0
            } else {
                // On the ground: shadowed iff the ray toward the sun enters the ball.
                let b = dot(d, s);
                let cc = dot(d, d) - r * r;
                b < 0.0 && b * b > cc
            }
        };
        assert_matches_within_one_texel(
            &map,
            &mask(&map, &sun),
            &analytic,
            &format!("hemisphere az {az} el {el}"),
        );
    }
}

#[test]
fn crater_shadow_matches_the_bowl() {
    let n = 192;
    let map = generate(Shape::Crater, n);
    let (cx, cy) = centre(n);
    let c = [cx, -cy, 0.0];
    for (az, el) in [(270.0, 30.0), (45.0, 20.0), (180.0, 60.0)] {
        let sun = Sun::new(az, el).unwrap();
        let s = sun.direction();
        let analytic = |col: usize, row: usize| {
            let p = world(&map, col, row);
            if p[2] >= 0.0 {
                return false; // flat ground around the bowl is lit
            }
            // P is on the sphere: the ray leaves it again at P − 2((P−C)·s)s; if that point is
            // below ground the ray hits the bowl's wall.
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            p[2] - 2.0 * dot(d, s) * s[2] < 0.0
        };
        assert_matches_within_one_texel(
            &map,
            &mask(&map, &sun),
            &analytic,
            &format!("crater az {az} el {el}"),
        );
    }
}

#[test]
fn flat_ground_is_lit_and_the_horizon_shadows_everything() {
    let map = generate(Shape::Flat, 33);
    assert!(mask(&map, &Sun::new(10.0, 0.001).unwrap())
        .iter()
        .all(|s| !s));
    assert!(mask(&map, &Sun::new(10.0, 0.0).unwrap()).iter().all(|s| *s));
    assert!(mask(&map, &Sun::new(10.0, -5.0).unwrap())
        .iter()
        .all(|s| *s));
    assert!(mask(&map, &Sun::new(10.0, 90.0).unwrap())
        .iter()
        .all(|s| !s));
}
