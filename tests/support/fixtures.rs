//! Synthetic scenes with known answers, for the tests and benchmarks: the analytic configurations
//! of `relume::radiosity::formfactor::analytic`, closed boxes (furnace tests) and two rooms separated by a
//! thin wall (the transfer's leak test).
#![allow(dead_code)]

use glam::DVec3;
use relume::scene::builder::SceneBuilder;
use relume::scene::Scene;

/// `count` random triangles in the unit cube (each within 0.1 of a random centre; xorshift
/// from `seed`): the random soup of the visibility and memory tests.
pub fn random_soup(count: usize, seed: u64) -> Scene {
    let mut state = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    for _ in 0..count {
        let c = DVec3::new(next(), next(), next());
        let mut corner = || c + DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * 0.1;
        let corners = [corner(), corner(), corner()];
        s.triangle("soup", corners, m);
    }
    s.build()
}

/// Howell C-11: rectangles `a × b` at y = 0 (facing +y) and y = c (facing −y).
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> Scene {
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    let (u, v) = (DVec3::X * a / 2.0, DVec3::Z * b / 2.0);
    let centre = DVec3::new(a / 2.0, 0.0, b / 2.0);
    s.rectangle("bottom", centre, u, -v, m);
    s.rectangle("top", centre + DVec3::Y * c, u, v, m);
    s.build()
}

/// Howell C-14: `w × l` at y = 0 (facing +y, z ∈ [0, w]) and `h × l` at z = 0 (facing +z,
/// y ∈ [0, h]), sharing the edge x ∈ [0, l].
pub fn perpendicular_rectangles(w: f64, h: f64, l: f64) -> Scene {
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    let hx = DVec3::X * l / 2.0;
    s.rectangle(
        "floor",
        DVec3::new(l / 2.0, 0.0, w / 2.0),
        hx,
        -DVec3::Z * w / 2.0,
        m,
    );
    s.rectangle(
        "wall",
        DVec3::new(l / 2.0, h / 2.0, 0.0),
        hx,
        DVec3::Y * h / 2.0,
        m,
    );
    s.build()
}

/// Coaxial discs (regular `segments`-gons): radius `r1` at y = 0 facing +y, `r2` at y = h
/// facing −y.
pub fn coaxial_discs(r1: f64, r2: f64, h: f64, segments: usize) -> Scene {
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    s.disc("bottom", DVec3::ZERO, DVec3::Y, r1, segments, m);
    s.disc("top", DVec3::Y * h, -DVec3::Y, r2, segments, m);
    s.build()
}

/// Radius of the circle with the area of a regular `segments`-gon of circumradius `r`.
pub fn equal_area_radius(r: f64, segments: usize) -> f64 {
    let k = segments as f64;
    r * (k * (std::f64::consts::TAU / k).sin() / std::f64::consts::TAU).sqrt()
}

/// Howell B-3: a small square element of side `e` centred at the origin facing +y, and the
/// rectangle x ∈ [0, a], z ∈ [0, b] at y = c facing −y (the element's normal passes through a
/// corner).
pub fn element_and_rectangle(e: f64, a: f64, b: f64, c: f64) -> Scene {
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    s.rectangle(
        "element",
        DVec3::ZERO,
        DVec3::X * e / 2.0,
        -DVec3::Z * e / 2.0,
        m,
    );
    s.rectangle(
        "rectangle",
        DVec3::new(a / 2.0, c, b / 2.0),
        DVec3::X * a / 2.0,
        DVec3::Z * b / 2.0,
        m,
    );
    s.build()
}

/// A closed box `[0, size]` (inward faces) with uniform albedo and emitted radiance.
pub fn closed_box(size: [f64; 3], albedo: f32, emission: f32) -> Scene {
    let mut s = SceneBuilder::new();
    let m = s.material("uniform", [albedo; 3], [emission; 3]);
    s.box_inside("box", DVec3::ZERO, DVec3::from(size), m);
    s.build()
}

/// Two closed unit rooms side by side, x ∈ [0, 1] and [1 + t, 2 + t], separated by a wall of
/// thickness `t`; room A (the first) has a light quad in its ceiling plane.
pub fn thin_wall_rooms(t: f64) -> Scene {
    let mut s = SceneBuilder::new();
    let white = s.material("white", [0.7; 3], [0.0; 3]);
    let light = s.material("light", [0.7; 3], [10.0; 3]);
    s.box_inside("room_a", DVec3::ZERO, DVec3::ONE, white);
    s.box_inside(
        "room_b",
        DVec3::new(1.0 + t, 0.0, 0.0),
        DVec3::new(2.0 + t, 1.0, 1.0),
        white,
    );
    s.rectangle(
        "light",
        DVec3::new(0.5, 1.0, 0.5),
        DVec3::X * 0.15,
        DVec3::Z * 0.15,
        light,
    );
    s.build()
}

/// A square floor at y = 0 (`floor` = (lowest x and z, side), albedo `floor_albedo`) and above
/// it, at y = 1, a square leaf (`leaf` = (lowest x and z, side)) whose texture (`texels`, `n`×`n`
/// RGBA8, factor 1) cuts it away where alpha is below 0.5; the leaf's u runs along x and v
/// along z, one image over the square.
pub fn masked_leaf_over_floor(
    floor: (f32, f32),
    floor_albedo: f32,
    leaf: (f32, f32),
    n: u32,
    texels: Vec<u8>,
) -> Scene {
    use relume::scene::texture::{AlphaMask, Channel, Texture, TextureRef};
    use relume::scene::Material;
    let r = TextureRef::new(0);
    let mut masked = Material::plain("leaf", [1.0; 3], [0.0; 3]);
    masked.albedo_texture = Some(r.clone());
    masked.alpha = Some(AlphaMask {
        factor: 1.0,
        texture: Some((r, Channel::Alpha)),
        cutoff: 0.5,
    });
    let quad = |(lo, side): (f32, f32), y: f32| {
        let hi = lo + side;
        [[lo, y, lo], [lo, y, hi], [hi, y, hi], [hi, y, lo]]
    };
    let mut positions = quad(floor, 0.0).to_vec();
    positions.extend(quad(leaf, 1.0));
    let uv = [[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
    Scene {
        positions,
        triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        triangle_material: vec![0, 0, 1, 1],
        triangle_object: vec![0, 0, 1, 1],
        objects: vec!["floor".into(), "leaf".into()],
        materials: vec![
            Material::plain("floor", [floor_albedo; 3], [0.0; 3]),
            masked,
        ],
        uvs: [uv, uv].concat(),
        textures: vec![Texture::from_rgba8("leaf".into(), n, n, texels).unwrap()],
        ..Default::default()
    }
}
