//! Coplanar overlapping faces: the visible part of every triangle.
//!
//! Scenes often lay one face on top of another in the same plane: the Cornell box's light is a
//! quad in the ceiling's plane, decals sit on walls, exporters duplicate faces. Summing such faces
//! would double the area, and averaging them would dilute the emission. The rule:
//!
//! * Two triangles *overlap* when they face the same way (normals within ~1°), every vertex of
//!   each lies within `tolerance` of the other's plane, and their intersection has positive area.
//! * Of two overlapping triangles the one with higher *priority* covers the other: emissive
//!   triangles (any emission > 0) cover non-emissive ones; otherwise the triangle that comes later
//!   in the scene covers the earlier one (the decal convention: drawn later is on top).
//! * The visible part of a triangle is the triangle minus every triangle that covers it, as a
//!   list of convex polygons (exact: each subtraction splits by the coverer's edge lines).
//!
//! So a covered region counts once, with the albedo and emission of the face on top: the Cornell
//! ceiling gets a hole where the light is, and the light keeps all its emission.

use crate::radiosity::geometry::{self, Polygon};
use glam::DVec3;

/// One triangle for the overlap test.
pub struct Face {
    pub corners: [DVec3; 3],
    /// Unit normal from the counter-clockwise winding.
    pub normal: DVec3,
    pub emissive: bool,
}

/// The result: visible polygons per face, and how much area was covered.
pub struct Visible {
    pub polygons: Vec<Vec<Polygon>>,
    /// Number of faces that lost some area to a coverer.
    pub covered_faces: usize,
    /// Total area removed (in the coordinates of the faces).
    pub covered_area: f64,
}

/// The visible part of every face. `tolerance` is the plane distance below which two faces count
/// as coplanar (in the faces' coordinates).
pub fn visible_parts(faces: &[Face], tolerance: f64) -> Visible {
    let mut polygons: Vec<Vec<Polygon>> = faces.iter().map(|f| vec![f.corners.to_vec()]).collect();
    let mut covered = std::collections::BTreeSet::new();
    let mut covered_area = 0.0;
    for (a, b) in candidate_pairs(faces, tolerance) {
        // Order the pair so that `top` covers `under`.
        let key = |i: usize| (faces[i].emissive, i);
        let (top, under) = if key(a) > key(b) { (a, b) } else { (b, a) };
        if !coplanar(&faces[top], &faces[under], tolerance) {
            continue;
        }
        let before: f64 = polygons[under].iter().map(|p| geometry::area(p)).sum();
        let inter = intersection(&faces[under].corners, &faces[top]);
        if geometry::area(&inter) <= 1e-9 * before.max(f64::MIN_POSITIVE) {
            continue;
        }
        let pieces = std::mem::take(&mut polygons[under]);
        polygons[under] = pieces
            .into_iter()
            .flat_map(|p| subtract(&p, &faces[top]))
            .collect();
        let after: f64 = polygons[under].iter().map(|p| geometry::area(p)).sum();
        if after < before {
            covered.insert(under);
            covered_area += before - after;
        }
    }
    Visible {
        polygons,
        covered_faces: covered.len(),
        covered_area,
    }
}

/// Pairs of faces facing the same way whose planes are close and whose bounds overlap, found by
/// bucketing on (dominant axis, plane offset) and sweeping along x. Deterministic order.
fn candidate_pairs(faces: &[Face], tolerance: f64) -> Vec<(usize, usize)> {
    let width = (4.0 * tolerance).max(f64::MIN_POSITIVE);
    let key = |f: &Face| {
        (
            geometry::dominant_axis(f.normal),
            (f.normal.dot(f.corners[0]) / width).floor() as i64,
        )
    };
    let mut order: Vec<(u8, i64, usize)> = faces
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let (a, k) = key(f);
            (a, k, i)
        })
        .collect();
    order.sort_unstable();
    let lo = |f: &Face| f.corners.iter().fold(DVec3::INFINITY, |m, &c| m.min(c));
    let hi = |f: &Face| f.corners.iter().fold(DVec3::NEG_INFINITY, |m, &c| m.max(c));
    let mut pairs = Vec::new();
    // Group runs of the same axis whose offsets are within one bucket of each other.
    let mut start = 0;
    while start < order.len() {
        let axis = order[start].0;
        let mut end = start;
        while end < order.len()
            && order[end].0 == axis
            && (end == start || order[end].1 - order[end - 1].1 <= 1)
        {
            end += 1;
        }
        let mut group: Vec<usize> = order[start..end].iter().map(|e| e.2).collect();
        group.sort_by(|&a, &b| lo(&faces[a]).x.total_cmp(&lo(&faces[b]).x).then(a.cmp(&b)));
        for (gi, &a) in group.iter().enumerate() {
            let (la, ha) = (lo(&faces[a]), hi(&faces[a]));
            for &b in &group[gi + 1..] {
                let (lb, hb) = (lo(&faces[b]), hi(&faces[b]));
                if lb.x > ha.x + tolerance {
                    break;
                }
                let overlap = (la - DVec3::splat(tolerance)).cmple(hb)
                    & (lb - DVec3::splat(tolerance)).cmple(ha);
                if overlap.all() && (key(&faces[a]).1 - key(&faces[b]).1).abs() <= 1 {
                    pairs.push((a.min(b), a.max(b)));
                }
            }
        }
        start = end;
    }
    pairs.sort_unstable();
    pairs
}

fn coplanar(a: &Face, b: &Face, tolerance: f64) -> bool {
    a.normal.dot(b.normal) > 0.9998
        && b.corners
            .iter()
            .all(|&c| a.normal.dot(c - a.corners[0]).abs() <= tolerance)
        && a.corners
            .iter()
            .all(|&c| b.normal.dot(c - b.corners[0]).abs() <= tolerance)
}

/// The inward half-planes of a triangle's edges, as (normal, offset): inside when `n·x ≥ d`.
fn edge_planes(f: &Face) -> [(DVec3, f64); 3] {
    std::array::from_fn(|i| {
        let a = f.corners[i];
        let b = f.corners[(i + 1) % 3];
        let m = f.normal.cross(b - a);
        (m, m.dot(a))
    })
}

fn intersection(poly: &[DVec3], top: &Face) -> Polygon {
    let mut rest = poly.to_vec();
    for (m, d) in edge_planes(top) {
        rest = geometry::split(&rest, m, d).1;
        if rest.is_empty() {
            break;
        }
    }
    rest
}

/// `poly` minus the triangle `top`, as convex pieces.
fn subtract(poly: &[DVec3], top: &Face) -> Vec<Polygon> {
    let mut out = Vec::new();
    let mut rest = poly.to_vec();
    for (m, d) in edge_planes(top) {
        let (outside, inside) = geometry::split(&rest, m, d);
        if !outside.is_empty() && geometry::area(&outside) > 0.0 {
            out.push(outside);
        }
        rest = inside;
        if rest.is_empty() {
            break;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face(c: [[f64; 3]; 3], emissive: bool) -> Face {
        let corners = c.map(DVec3::from);
        let normal = (corners[1] - corners[0])
            .cross(corners[2] - corners[0])
            .normalize();
        Face {
            corners,
            normal,
            emissive,
        }
    }

    #[test]
    fn emitter_on_a_larger_face_cuts_a_hole() {
        let base = face([[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]], false);
        let light = face([[1.0, 1.0, 0.0], [2.0, 1.0, 0.0], [1.0, 2.0, 0.0]], true);
        let v = visible_parts(&[light, base], 1e-9);
        let a: f64 = v.polygons[1].iter().map(|p| geometry::area(p)).sum();
        assert!((a - (8.0 - 0.5)).abs() < 1e-12, "{a}");
        assert_eq!(v.polygons[0].len(), 1);
        assert_eq!(v.covered_faces, 1);
    }

    #[test]
    fn duplicates_count_once_and_neighbours_are_untouched() {
        let t = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let v = visible_parts(&[face(t, false), face(t, false)], 1e-9);
        let total: f64 = v.polygons.iter().flatten().map(|p| geometry::area(p)).sum();
        assert!((total - 0.5).abs() < 1e-12);
        // Sharing an edge is not an overlap; facing away is not either.
        let n = face([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]], true);
        let back = face([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], true);
        let v = visible_parts(&[face(t, false), n, back], 1e-9);
        assert_eq!(v.covered_faces, 0);
        assert_eq!(v.polygons[0], vec![t.map(DVec3::from).to_vec()]);
    }
}
