//! Clipping triangles into voxels and clustering the pieces into patches: the two steps of
//! [`crate::radiosity::patches::voxelize`] that the voxel-size search ([`crate::radiosity::patches::voxel_size`]) repeats to count
//! patches. Preconditions: polygons are convex, in grid coordinates (world / voxel size).

use crate::radiosity::geometry::{self, dominant_axis, group_key, Polygon};
use crate::radiosity::patches::overlap::Face;
use crate::radiosity::Piece;
use crate::raytrace::visibility::Visibility;
use glam::DVec3;

/// Largest grid accepted (voxels along all three axes together).
pub(super) const MAX_VOXELS: f64 = 1e12;
/// Pieces smaller than this (in voxel areas) are dropped as clipping slivers.
pub(super) const MIN_PIECE_AREA: f64 = 1e-12;
/// Distance (voxels) within which a polygon's extreme counts as lying on a voxel face.
pub(super) const SNAP: f64 = 1e-6;

/// The grid of voxel `size` over a scene of `extent`, or `None` when it is not finite or larger
/// than [`MAX_VOXELS`].
pub(super) fn grid_dims(extent: DVec3, size: f64) -> Option<[u32; 3]> {
    let dims_f = (extent / size - DVec3::splat(SNAP)).ceil().max(DVec3::ONE);
    (size.is_finite() && size > 0.0 && dims_f.x * dims_f.y * dims_f.z <= MAX_VOXELS).then_some([
        dims_f.x as u32,
        dims_f.y as u32,
        dims_f.z as u32,
    ])
}

/// Clip every visible polygon of the `live` triangles into the voxels of a `dims` grid of voxel
/// `size` (grid coordinates) and call `f(group key, index into live, piece, area)` for each
/// piece that is not a sliver, in clipping order.
pub(super) fn for_each_piece(
    live: &[u32],
    faces: &[Face],
    polys: &[Vec<Polygon>],
    size: f64,
    dims: [u32; 3],
    mut f: impl FnMut(u64, usize, Polygon, f64),
) {
    for k in 0..live.len() {
        let axis = dominant_axis(faces[k].normal);
        for poly in &polys[k] {
            let grid: Polygon = poly.iter().map(|&p| p / size).collect();
            for (voxel, piece) in clip_to_voxels(&grid, dims) {
                let area = geometry::area(&piece);
                if area > MIN_PIECE_AREA {
                    f(group_key(voxel, axis, dims), k, piece, area);
                }
            }
        }
    }
}

/// The pieces of [`for_each_piece`], keyed by (voxel, axis) group and sorted by (group,
/// triangle), clipping order kept within a triangle.
pub(super) fn clip_pieces(
    live: &[u32],
    faces: &[Face],
    polys: &[Vec<Polygon>],
    size: f64,
    dims: [u32; 3],
) -> Vec<(u64, Piece)> {
    let mut pieces: Vec<(u64, Piece)> = Vec::new();
    for_each_piece(live, faces, polys, size, dims, |key, k, piece, area| {
        pieces.push((
            key,
            Piece {
                triangle: live[k],
                normal: faces[k].normal.to_array(),
                vertices: piece.iter().map(|p| p.to_array()).collect(),
                area,
            },
        ));
    });
    pieces.sort_by_key(|(key, p)| (*key, p.triangle)); // stable: keeps clipping order
    pieces
}

/// Split each group of `pieces` (sorted by key) into clusters that see each other
/// ([`split_visible`]). One cluster is one patch.
/// Groups are clustered in parallel and concatenated in key order: the same output for any
/// thread count.
pub(super) fn clusters(pieces: &[(u64, Piece)], vis: &Visibility) -> Vec<(u64, Vec<usize>)> {
    use rayon::prelude::*;
    let mut groups = Vec::new();
    let mut start = 0;
    while start < pieces.len() {
        let key = pieces[start].0;
        let end = start + pieces[start..].iter().take_while(|p| p.0 == key).count();
        groups.push((key, start..end));
        start = end;
    }
    let split: Vec<Vec<(u64, Vec<usize>)>> = groups
        .into_par_iter()
        .map(|(key, range)| {
            let members: Vec<usize> = range.collect();
            split_visible(&members, pieces, vis)
                .into_iter()
                .map(|m| (key, m))
                .collect()
        })
        .collect();
    split.into_iter().flatten().collect()
}

/// Split `members` (indices into `pieces`) into clusters that see each other: a piece joins
/// the first cluster whose representative (its first piece's lifted centroid) it sees.
pub(super) fn split_visible(
    members: &[usize],
    pieces: &[(u64, Piece)],
    vis: &Visibility,
) -> Vec<Vec<usize>> {
    let lift = 4.0 * vis.epsilon as f64;
    let mut group: Vec<(DVec3, Vec<usize>)> = Vec::new();
    for &i in members {
        let c = lifted_centroid(&pieces[i].1, lift);
        match group.iter_mut().find(|(rep, _)| !vis.occluded(c, *rep)) {
            Some((_, m)) => m.push(i),
            None => group.push((c, vec![i])),
        }
    }
    group.into_iter().map(|(_, m)| m).collect()
}

fn lifted_centroid(p: &Piece, lift: f64) -> DVec3 {
    let poly: Vec<DVec3> = p.vertices.iter().map(|&v| DVec3::from(v)).collect();
    geometry::centroid(&poly) + DVec3::from(p.normal) * lift
}

/// Clip a polygon (grid coordinates) into the voxels of a `dims` grid. Coordinates outside the
/// grid are clamped into the border voxels.
pub fn clip_to_voxels(poly: &[DVec3], dims: [u32; 3]) -> Vec<([u32; 3], Polygon)> {
    let mut out = Vec::new();
    for (x, px) in slabs(poly.to_vec(), 0, dims[0]) {
        for (y, py) in slabs(px, 1, dims[1]) {
            for (z, pz) in slabs(py, 2, dims[2]) {
                out.push(([x, y, z], pz));
            }
        }
    }
    out
}

fn slabs(poly: Polygon, axis: usize, dim: u32) -> Vec<(u32, Polygon)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in &poly {
        lo = lo.min(p[axis]);
        hi = hi.max(p[axis]);
    }
    let cell = |x: f64| (x.floor().max(0.0) as u64).min(dim as u64 - 1) as u32;
    // A polygon that pokes less than SNAP past a voxel face (rounding of coordinates that lie
    // on the face) is not cut there: no sliver pieces, no sliver patches.
    let (i0, i1) = (cell(lo + SNAP), cell(hi - SNAP).max(cell(lo + SNAP)));
    let mut out = Vec::with_capacity((i1 - i0 + 1) as usize);
    let mut rest = poly;
    for i in i0..i1 {
        let (below, above) = geometry::split_axis(&rest, axis, (i + 1) as f64);
        if !below.is_empty() {
            out.push((i, below));
        }
        rest = above;
        if rest.is_empty() {
            return out;
        }
    }
    out.push((i1, rest));
    out
}
