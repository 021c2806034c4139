//! Shape textures: a flat grid on a plane carrier is that plane, a constant grid on a sphere
//! carrier is a larger sphere (both against closed forms, by the certified reference and by
//! the multilevel caster); the bounds contain every value (proptest against brute force); the
//! mipmap's range query contains every sample it covers; morphing and levels of detail do what
//! they say.

use proptest::prelude::*;
use relume::freeform::field::Field;
use relume::freeform::reference::first_hit;
use relume::freeform::rmlrc::{cast, RmlrcParams};
use relume::freeform::texture::Texture;
use relume::freeform::View;
use relume::heightmap::minmax_mipmap::MinMaxMipmap;
use relume::heightmap::HeightMap;
use relume::scene::freeform::{FreeformCamera, FreeformScene, Shape};
use std::path::Path;

fn grid(w: usize, h: usize, values: &[f32]) -> String {
    let v: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("Grid(width: {w}, height: {h}, values: [{}])", v.join(", "))
}

fn textured(carrier: &str, heights: &str, extra: &str) -> FreeformScene {
    let text = format!(
        "Freeform(shape: Textured(carrier: {carrier}, heights: {heights}, {extra}), camera: (eye: (3.0, 2.5, 4.0), target: (0.0, 0.0, 0.0), fov: 50.0))"
    );
    FreeformScene::parse(Path::new("test.ron"), &text).unwrap()
}

const PLANE: &str =
    "Plane(origin: (-4.0, 0.0, -4.0), u_axis: (0.0, 0.0, 1.0), v_axis: (1.0, 0.0, 0.0), size: (8.0, 8.0))";
const SPHERE: &str = "Sphere(centre: (0.2, -0.1, 0.3), radius: 1.0)";

fn rays(n: usize) -> Vec<([f64; 3], [f64; 3])> {
    // Deterministic rays from outside toward the origin region.
    (0..n)
        .map(|i| {
            let a = i as f64 * 2.399_963;
            let z = 0.3 + 0.6 * ((i * 7919) % 97) as f64 / 97.0;
            let o = [4.0 * a.cos() * z, 3.0 + z, 4.0 * a.sin() * z];
            let target = [0.3 * a.sin(), 0.1 * (i % 5) as f64 - 0.2, 0.3 * a.cos()];
            let d: [f64; 3] = std::array::from_fn(|k| target[k] - o[k]);
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            (o, d.map(|v| v / l))
        })
        .collect()
}

#[test]
fn a_flat_grid_on_a_plane_carrier_is_that_plane() {
    // A 5x4 grid of 0.25 everywhere, height_scale 2: the plane y = 0.5.
    let s = textured(PLANE, &grid(5, 4, &[0.25; 20]), "height_scale: 2.0");
    let field = Field::compile(&s.shape).unwrap();
    let mut worst = 0f64;
    for (o, d) in rays(200) {
        let exact = (0.5 - o[1]) / d[1];
        let hit = first_hit(&field, o, d, 0.0, 100.0).expect("every ray hits the plane");
        worst = worst.max((hit.t - exact).abs() / exact);
    }
    assert!(worst < 1e-9, "worst relative error {worst:e}");
    // The multilevel caster draws the same picture as the quadric plane y = 0.5.
    let plane = FreeformScene::parse(
        Path::new("plane.ron"),
        "Freeform(shape: Surface(base: Plane(normal: (0.0, 1.0, 0.0), offset: 0.5)))",
    )
    .unwrap();
    same_picture(
        &field,
        &Field::compile(&plane.shape).unwrap(),
        s.camera.as_ref().unwrap(),
    );
}

#[test]
fn a_constant_grid_on_a_sphere_carrier_is_a_larger_sphere() {
    let s = textured(SPHERE, &grid(8, 4, &[0.5; 32]), "");
    let field = Field::compile(&s.shape).unwrap();
    let c = [0.2, -0.1, 0.3];
    let mut worst = 0f64;
    let mut hits = 0;
    for (o, d) in rays(300) {
        // |o + t d − c|² = 1.5²
        let oc: [f64; 3] = std::array::from_fn(|k| o[k] - c[k]);
        let b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
        let cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - 2.25;
        let disc = b * b - cc;
        let got = first_hit(&field, o, d, 0.0, 100.0);
        if disc <= 1e-9 {
            assert!(got.is_none() || disc > -1e-6, "a miss hit");
            continue;
        }
        let exact = -b - disc.sqrt();
        let hit = got.expect("a hit missed");
        hits += 1;
        worst = worst.max((hit.t - exact).abs() / exact);
    }
    assert!(hits > 100, "{hits}");
    assert!(worst < 1e-9, "worst relative error {worst:e}");
    let sphere = FreeformScene::parse(
        Path::new("sphere.ron"),
        "Freeform(shape: Surface(base: Sphere(radius: 1.5), transform: (translate: (0.2, -0.1, 0.3))))",
    )
    .unwrap();
    same_picture(
        &field,
        &Field::compile(&sphere.shape).unwrap(),
        s.camera.as_ref().unwrap(),
    );
}

#[test]
fn a_constant_grid_on_a_cylinder_carrier_is_a_larger_cylinder() {
    let carrier = "Cylinder(base: (0.2, -3.0, 0.3), radius: 1.0, length: 6.0)";
    let s = textured(carrier, &grid(8, 4, &[0.5; 32]), "");
    let field = Field::compile(&s.shape).unwrap();
    let (mut worst, mut hits) = (0f64, 0);
    for (o, d) in rays(300) {
        // (o + t d − c)ₓ² + (o + t d − c)_z² = 1.5², from outside.
        let (ox, oz) = (o[0] - 0.2, o[2] - 0.3);
        let a = d[0] * d[0] + d[2] * d[2];
        let b = ox * d[0] + oz * d[2];
        let cc = ox * ox + oz * oz - 2.25;
        if cc <= 0.0 {
            continue;
        }
        let disc = b * b - a * cc;
        let got = first_hit(&field, o, d, 0.0, 100.0);
        if disc <= 1e-9 || b >= 0.0 {
            assert!(got.is_none() || disc > -1e-6, "a miss hit");
            continue;
        }
        let exact = (-b - disc.sqrt()) / a;
        let hit = got.expect("a hit missed");
        hits += 1;
        worst = worst.max((hit.t - exact).abs() / exact);
    }
    assert!(hits > 50, "{hits}");
    assert!(worst < 1e-9, "worst relative error {worst:e}");
    let cylinder = FreeformScene::parse(
        Path::new("cylinder.ron"),
        "Freeform(shape: Surface(base: Cylinder(radius: 1.5), transform: (translate: (0.2, 0.0, 0.3))))",
    )
    .unwrap();
    same_picture(
        &field,
        &Field::compile(&cylinder.shape).unwrap(),
        s.camera.as_ref().unwrap(),
    );
}

/// The multilevel caster on the textured field and on the equivalent quadric: the same hit
/// mask except on silhouette pixels (at most 0.1 %), depths within 2 finest depth cells.
fn same_picture(textured: &Field, quadric: &Field, camera: &FreeformCamera) {
    let view = View::new(camera, 64, 48);
    let params = RmlrcParams::default();
    let (a, _) = cast(textured, &view, &params);
    let (b, _) = cast(quadric, &view, &params);
    let cell = view.pixel_angle() / (1u64 << params.refine) as f64;
    let mut differ = 0;
    for (x, y) in a.iter().zip(&b) {
        match (x, y) {
            (Some(s), Some(t)) => {
                let cells = (s / t).ln().abs() / cell;
                assert!(cells <= 2.0, "depth off by {cells} cells");
            }
            (None, None) => {}
            _ => differ += 1,
        }
    }
    assert!(
        differ * 1000 <= a.len(),
        "{differ} of {} pixels differ",
        a.len()
    );
}

fn random_texture(carrier: &str, w: usize, h: usize, seed: &[f64]) -> Texture {
    let values: Vec<f32> = (0..w * h)
        .map(|i| (seed[i % seed.len()] * (1.0 + (i * 37 % 11) as f64)) as f32 * 0.1)
        .collect();
    let s = textured(carrier, &grid(w, h, &values), "");
    let Shape::Textured(t) = &s.shape else {
        unreachable!()
    };
    Texture::compile(t).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Every value at points of a box lies in the bound over the box (plane and sphere
    /// carriers, boxes from a hair to larger than the carrier).
    #[test]
    fn the_bound_over_a_box_contains_every_value(
        seed in prop::collection::vec(-1.0f64..1.0, 16),
        c in prop::array::uniform3(-2.0f64..2.0),
        log_size in -6.0f64..1.0,
        sphere in any::<bool>(),
        samples in prop::collection::vec(prop::array::uniform3(0.0f64..1.0), 24),
    ) {
        let tex = random_texture(if sphere { SPHERE } else { PLANE }, 9, 7, &seed);
        let e = 10f64.powf(log_size);
        let lo = c.map(|v| v - e);
        let hi = c.map(|v| v + e);
        let (rlo, rhi) = tex.range(lo, hi);
        for s in samples {
            let p: [f64; 3] = std::array::from_fn(|k| lo[k] + s[k] * (hi[k] - lo[k]));
            let v = tex.value(p);
            prop_assert!(rlo <= v && v <= rhi, "{v} outside [{rlo}, {rhi}] at {p:?}");
        }
    }

    /// The mipmap's range query contains every sample of the rectangle (brute force).
    #[test]
    fn the_mipmap_range_contains_every_sample(
        w in 2usize..40, h in 2usize..40,
        seed in prop::collection::vec(-100.0f32..100.0, 64),
        a in (0usize..40, 0usize..40), b in (0usize..40, 0usize..40),
    ) {
        let heights: Vec<f32> = (0..w * h).map(|i| seed[(i * 13) % 64] + i as f32 * 0.01).collect();
        let map = HeightMap { width: w, height: h, heights: heights.clone(), cell_size: [1.0; 2], height_scale: 1.0 };
        let mip = MinMaxMipmap::build(&map);
        let (x0, x1) = (a.0.min(b.0).min(w - 1), a.0.max(b.0).min(w - 1));
        let (y0, y1) = (a.1.min(b.1).min(h - 1), a.1.max(b.1).min(h - 1));
        let (hi, lo) = mip.sample_range((x0, x1), (y0, y1));
        for y in y0..=y1 {
            for x in x0..=x1 {
                let v = heights[y * w + x];
                prop_assert!(lo <= v && v <= hi);
            }
        }
    }
}

#[test]
fn a_morph_halfway_between_two_flat_grids_is_the_plane_between() {
    let s = textured(
        PLANE,
        &grid(3, 3, &[0.0; 9]),
        &format!("morph_to: {}", grid(3, 3, &[1.0; 9])),
    );
    let mut field = Field::compile(&s.shape).unwrap();
    for m in [0.0, 0.25, 0.5, 1.0] {
        field.set_morph(m);
        for (o, d) in rays(20) {
            let exact = (m - o[1]) / d[1];
            let hit = first_hit(&field, o, d, 0.0, 100.0).unwrap();
            assert!((hit.t - exact).abs() < 1e-9 * exact, "morph {m}");
        }
    }
}

#[test]
fn a_level_of_detail_is_the_grid_box_filtered() {
    let values: Vec<f32> = (0..6 * 4).map(|i| (i * i % 7) as f32).collect();
    let s = textured(PLANE, &grid(6, 4, &values), "lod: 1");
    let Shape::Textured(t) = &s.shape else {
        unreachable!()
    };
    let tex = Texture::compile(t).unwrap();
    assert_eq!((tex.width, tex.height), (3, 2));
    for by in 0..2 {
        for bx in 0..3 {
            let mean = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .iter()
                .map(|&(x, y)| values[(2 * by + y) * 6 + 2 * bx + x])
                .sum::<f32>()
                / 4.0;
            assert!((tex.heights[by * 3 + bx] - mean).abs() < 1e-6);
        }
    }
}
