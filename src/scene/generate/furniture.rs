//! Furniture for the bundled rooms: boxes on legs and finely tessellated surfaces of revolution.
//! Faces that rest on the floor or against a wall are left out (no one sees them, and they
//! would be coplanar with the surface they touch).

use crate::scene::builder::{Face, SceneBuilder};
use glam::DVec3;

const X: DVec3 = DVec3::X;
const Y: DVec3 = DVec3::Y;
const Z: DVec3 = DVec3::Z;

/// An axis-aligned box standing on the floor (no bottom face) or hanging in the air.
pub fn block(b: &mut SceneBuilder, object: &str, lo: DVec3, size: DVec3, m: u32) {
    let omit: &[Face] = if lo.y == 0.0 { &[Face::NegY] } else { &[] };
    b.cuboid(object, lo, [X * size.x, Y * size.y, Z * size.z], m, omit);
}

/// A table: a top of `size` (x, thickness, z) at `height`, four square legs of side `leg`.
pub fn table(
    b: &mut SceneBuilder,
    object: &str,
    corner: DVec3,
    size: DVec3,
    height: f64,
    leg: f64,
    m: u32,
) {
    block(b, object, corner + Y * (height - size.y), size, m);
    legs(b, object, corner, size, height - size.y, leg, m);
}

fn legs(
    b: &mut SceneBuilder,
    object: &str,
    corner: DVec3,
    size: DVec3,
    height: f64,
    leg: f64,
    m: u32,
) {
    for (fx, fz) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
        let at = corner + X * (fx * (size.x - leg)) + Z * (fz * (size.z - leg));
        // The top of a leg is against the underside of the seat or top: leave it out too.
        b.cuboid(
            object,
            at,
            [X * leg, Y * height, Z * leg],
            m,
            &[Face::NegY, Face::PosY],
        );
    }
}

/// A chair facing `facing` (±x or ±z): seat 0.45 m square at 0.45 m, a back rest 0.45 m tall.
pub fn chair(b: &mut SceneBuilder, object: &str, centre: DVec3, facing: DVec3, m: u32) {
    let (s, seat_h, t, leg) = (0.45, 0.45, 0.04, 0.04);
    let corner = centre - X * (s / 2.0) - Z * (s / 2.0);
    let seat = DVec3::new(s, t, s);
    block(b, object, corner + Y * (seat_h - t), seat, m);
    legs(b, object, corner, seat, seat_h - t, leg, m);
    // The back rest stands on the seat at the side away from `facing`.
    let back = if facing.x > 0.5 {
        (corner, DVec3::new(t, 0.45, s))
    } else if facing.x < -0.5 {
        (corner + X * (s - t), DVec3::new(t, 0.45, s))
    } else if facing.z > 0.5 {
        (corner, DVec3::new(s, 0.45, t))
    } else {
        (corner + Z * (s - t), DVec3::new(s, 0.45, t))
    };
    b.cuboid(
        object,
        back.0 + Y * seat_h,
        [X * back.1.x, Y * back.1.y, Z * back.1.z],
        m,
        &[Face::NegY],
    );
}

/// A bookshelf against the wall x = `wall_x` (opening toward −x): two sides, a top, `shelves`
/// boards, no back (the wall is its back).
pub fn bookshelf(
    b: &mut SceneBuilder,
    object: &str,
    wall_x: f64,
    z0: f64,
    size: DVec3,
    shelves: usize,
    m: u32,
) {
    let t = 0.025;
    let lo = DVec3::new(wall_x - size.x, 0.0, z0);
    let against_wall = [Face::NegY, Face::PosX];
    b.cuboid(
        object,
        lo,
        [X * size.x, Y * size.y, Z * t],
        m,
        &against_wall,
    );
    b.cuboid(
        object,
        lo + Z * (size.z - t),
        [X * size.x, Y * size.y, Z * t],
        m,
        &against_wall,
    );
    for k in 0..=shelves {
        let y = (size.y - t) * k as f64 / shelves as f64;
        let omit: &[Face] = if k == 0 { &against_wall } else { &[Face::PosX] };
        b.cuboid(
            object,
            lo + Y * y + Z * t,
            [X * size.x, Y * t, Z * (size.z - 2.0 * t)],
            m,
            omit,
        );
    }
}

/// A picture frame hanging on the wall z = `wall_z` (facing −z): a thin board.
pub fn picture(
    b: &mut SceneBuilder,
    object: &str,
    wall_z: f64,
    centre: DVec3,
    size: (f64, f64),
    m: u32,
) {
    let depth = 0.03;
    let lo = DVec3::new(
        centre.x - size.0 / 2.0,
        centre.y - size.1 / 2.0,
        wall_z - depth,
    );
    b.cuboid(
        object,
        lo,
        [X * size.0, Y * size.1, Z * depth],
        m,
        &[Face::PosZ],
    );
}

/// A statue-like figure of revolution, `height` tall, on the floor at `base`: a plinth, a
/// swelling body, a neck and a head, `rings` profile steps × `segments` around.
pub fn statue(
    b: &mut SceneBuilder,
    object: &str,
    base: DVec3,
    height: f64,
    rings: usize,
    segments: usize,
    m: u32,
) {
    let profile: Vec<(f64, f64)> = (0..=rings)
        .map(|k| {
            let t = k as f64 / rings as f64;
            let y = t * height;
            let r = if k == rings {
                0.0
            } else {
                let plinth: f64 = if t < 0.08 { 0.22 } else { 0.0 };
                let body = 0.16 * (std::f64::consts::PI * (t - 0.05) / 0.7).sin().max(0.0);
                let head = 0.09 * (1.0 - ((t - 0.87) / 0.12).powi(2)).max(0.0).sqrt();
                let ripple = 0.006 * (t * 60.0).sin();
                (plinth.max(body + 0.05 + ripple).max(head)).max(0.035)
            };
            (r, y)
        })
        .collect();
    // Open at the bottom: it stands on the floor.
    b.lathe(object, base, &profile, segments, m);
}

/// A vase of revolution on a surface at `base`, `height` tall, open at the bottom (it
/// stands on something), closed at the top.
pub fn vase(
    b: &mut SceneBuilder,
    object: &str,
    base: DVec3,
    height: f64,
    rings: usize,
    segments: usize,
    m: u32,
) {
    // Open at the bottom: it stands on a table.
    let mut profile: Vec<(f64, f64)> = (0..=rings)
        .map(|k| {
            let t = k as f64 / rings as f64;
            let r = 0.05 + 0.06 * (std::f64::consts::PI * t * 1.2).sin().max(0.0) + 0.02 * t * t;
            (r, t * height)
        })
        .collect();
    profile.push((0.0, height));
    b.lathe(object, base, &profile, segments, m);
}
