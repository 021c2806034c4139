//! Which patch a point on a surface belongs to: the patch of the point's voxel and its
//! triangle's dominant axis whose pieces are nearest to the point (searching the 26 neighbouring
//! voxels when the point sits on a voxel boundary). When the voxel holds exactly one patch of that
//! orientation, that patch is the answer without a distance test. A point under a coplanar cover (the Cornell
//! ceiling above the light) lies on the cover's piece, so it finds the cover's patch.
//!
//! Ray hits ([`PatchLocator::locate_hit`]) know their triangle, and a table of each triangle's
//! pieces by voxel ([`HitIndex`], built on the first hit) finds the answer from the hit
//! triangle's own piece and the few pieces within a hair of it, in O(1) per hit; it is the
//! answer of the full search, exactly (the argument is at [`HitIndex`]).

use crate::radiosity::geometry::group_key;
use crate::radiosity::geometry::{self, dominant_axis};
use crate::radiosity::PatchSet;
use crate::scene::Scene;
use glam::DVec3;
use std::sync::OnceLock;

/// Distance (grid units) within which a point counts as lying on a patch's piece.
pub const ON_SURFACE: f64 = 1e-3;
/// Farthest a hit may lie from every piece and still be assigned (grid units).
pub const MAX_DISTANCE: f64 = 0.05;

/// Point → patch queries over a [`PatchSet`].
pub struct PatchLocator {
    dims: [u32; 3],
    /// Group key of each patch (non-decreasing: patches are sorted by key).
    keys: Vec<u64>,
    /// (first piece, piece count) of each patch.
    ranges: Vec<(usize, usize)>,
    /// Vertices and unit normal of each piece.
    pieces: Vec<(Vec<DVec3>, DVec3)>,
    /// A bounding sphere (centre, radius) of each piece: the nearest-piece search skips a piece
    /// that cannot come nearer than the best so far (a patch of a finely meshed statue holds
    /// hundreds).
    spheres: Vec<(DVec3, f64)>,
    /// A sphere holding the spheres of each run of [`CHUNK`] consecutive pieces of a patch;
    /// patch i's runs start at `chunk_first[i]`.
    chunks: Vec<(DVec3, f64)>,
    chunk_first: Vec<usize>,
    /// Dominant axis of each scene triangle.
    triangle_axis: Vec<u8>,
    /// Scene triangle of each piece.
    piece_triangle: Vec<u32>,
    /// Dense (first patch, count) per group key when the grid is small enough, else empty (then
    /// a binary search over `keys`).
    table: Vec<(u32, u32)>,
    /// The ray hits' table, built on the first [`PatchLocator::locate_hit`] (the corner
    /// transfer's locator never needs it).
    hits: OnceLock<HitIndex>,
}

/// Where a hit on a triangle finds its patch without searching: for every piece lying in a
/// (voxel, axis) group of several patches, an entry keyed by (triangle, group key) with the
/// group's pieces of *other* patches that come within [`NEAR`] of it (bounding boxes).
///
/// Why the answer is [`PatchLocator::locate_on`]'s, bit for bit. Where the hit's voxel holds one
/// patch of the triangle's axis (or none) both take the same early exit or fallback. Otherwise
/// `locate_on` returns the group's patch whose pieces come nearest to `p` (distance from
/// [`geometry::closest_point_on_polygon`], ties to the lower patch index) when that distance
/// is at most [`ON_SURFACE`]. Let `d0` be the least distance from `p` to the hit triangle's
/// pieces in the group (ties to the lower patch), at piece `a` of patch `P`. If the triangle
/// has no piece there (a hidden or dropped part, a point rounded across a voxel face) or
/// `d0 > ON_SURFACE`, the table answers nothing and `locate_on` runs. Else `P`'s distance is
/// at most `d0`, and every other patch's is more: a piece `b` of another patch within `d0` of
/// `p` would lie within `2 d0 ≤ 2 ON_SURFACE` of `a`, so on `a`'s near list, and each piece on
/// it is either farther than `d0 + 1e-9` by its bounding box or has its distance computed (by
/// the same function on the same vertices as the search) — and if that is at most `d0` (a hit
/// on a seam between two patches) the table again answers nothing. Pieces off the list lie
/// farther than `NEAR − d0 ≥ 3 ON_SURFACE`. So `P` is the nearest patch, strictly, within
/// `ON_SURFACE`: `locate_on`'s answer. Coplanar covers (the Cornell light in its ceiling) need
/// nothing more: the covered triangle has no piece under the cover, so a hit reported on it
/// there is handed to the search, and one on the cover finds the cover's piece.
struct HitIndex {
    /// Triangle t's entries are `entries[tri_first[t]..tri_first[t + 1]]`, sorted by key.
    tri_first: Vec<u32>,
    entries: Vec<HitEntry>,
    /// Near lists (piece indices), entry e's at `near[e.near.0..e.near.1]`.
    near: Vec<u32>,
    /// Patch of each piece.
    piece_patch: Vec<u32>,
    /// Bounding box (lowest, highest corner) of each piece.
    bounds: Vec<(DVec3, DVec3)>,
}

#[derive(Clone, Copy)]
struct HitEntry {
    /// Group key (voxel, axis) of the piece's patch.
    key: u64,
    piece: u32,
    near: (u32, u32),
}

/// Reach of a near list (grid units): pieces whose bounding boxes come this close.
const NEAR: f64 = 4.0 * ON_SURFACE;

impl HitIndex {
    fn new(loc: &PatchLocator) -> Self {
        let mut piece_patch = vec![0u32; loc.pieces.len()];
        for (i, &(first, count)) in loc.ranges.iter().enumerate() {
            piece_patch[first..first + count].fill(i as u32);
        }
        let bounds: Vec<(DVec3, DVec3)> = loc
            .pieces
            .iter()
            .map(|(poly, _)| {
                poly.iter()
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                        (lo.min(v), hi.max(v))
                    })
            })
            .collect();
        // (triangle, key, piece, near list) of every piece in a group of several patches.
        let mut rows: Vec<(u32, u64, u32, (u32, u32))> = Vec::new();
        let mut near = Vec::new();
        let mut start = 0;
        while start < loc.keys.len() {
            let key = loc.keys[start];
            let end = start + loc.keys[start..].partition_point(|&k| k == key);
            if end - start > 1 {
                let mut members: Vec<u32> = (start..end)
                    .flat_map(|i| {
                        let (first, count) = loc.ranges[i];
                        first as u32..(first + count) as u32
                    })
                    .collect();
                // Sweep along x: pairs of different patches whose boxes come within NEAR on
                // every axis.
                members.sort_by(|&a, &b| {
                    let (ba, bb) = (bounds[a as usize].0.x, bounds[b as usize].0.x);
                    ba.total_cmp(&bb).then(a.cmp(&b))
                });
                let mut pairs: Vec<(u32, u32)> = Vec::new();
                for (n, &a) in members.iter().enumerate() {
                    let (alo, ahi) = bounds[a as usize];
                    for &b in &members[n + 1..] {
                        let (blo, bhi) = bounds[b as usize];
                        if blo.x > ahi.x + NEAR {
                            break;
                        }
                        if piece_patch[a as usize] != piece_patch[b as usize]
                            && (0..3).all(|k| blo[k] <= ahi[k] + NEAR && alo[k] <= bhi[k] + NEAR)
                        {
                            pairs.push((a, b));
                            pairs.push((b, a));
                        }
                    }
                }
                pairs.sort_unstable();
                members.sort_unstable();
                let mut rest = pairs.as_slice();
                for &a in &members {
                    let count = rest.iter().take_while(|e| e.0 == a).count();
                    let at = near.len() as u32;
                    near.extend(rest[..count].iter().map(|e| e.1));
                    rest = &rest[count..];
                    let t = loc.piece_triangle[a as usize];
                    rows.push((t, key, a, (at, near.len() as u32)));
                }
            }
            start = end;
        }
        rows.sort_unstable_by_key(|r| (r.0, r.1, r.2));
        let mut tri_first = vec![0u32; loc.triangle_axis.len() + 1];
        for r in &rows {
            tri_first[r.0 as usize + 1] += 1;
        }
        for t in 0..loc.triangle_axis.len() {
            tri_first[t + 1] += tri_first[t];
        }
        let entries = rows
            .into_iter()
            .map(|(_, key, piece, near)| HitEntry { key, piece, near })
            .collect();
        HitIndex {
            tri_first,
            entries,
            near,
            piece_patch,
            bounds,
        }
    }

    /// The patch of a hit at `p` on triangle `t` in the group `key` ([`PatchLocator::locate_on`]'s
    /// answer), or `None` when the full search must decide.
    fn locate(&self, loc: &PatchLocator, p: DVec3, t: u32, key: u64) -> Option<u32> {
        let ents = &self.entries
            [self.tri_first[t as usize] as usize..self.tri_first[t as usize + 1] as usize];
        let lo = ents.partition_point(|e| e.key < key);
        let run = &ents[lo..lo + ents[lo..].partition_point(|e| e.key == key)];
        let distance = |k: u32| {
            let (poly, n) = &loc.pieces[k as usize];
            (geometry::closest_point_on_polygon(p, poly, *n) - p).length()
        };
        // (distance, patch, entry): the least, ties to the lower patch.
        let mut best: Option<(f64, u32, &HitEntry)> = None;
        for e in run {
            let (d, j) = (distance(e.piece), self.piece_patch[e.piece as usize]);
            if best.is_none_or(|b| d < b.0 || (d == b.0 && j < b.1)) {
                best = Some((d, j, e));
            }
        }
        let (d0, patch, at) = best?;
        if d0.is_nan() || d0 > ON_SURFACE {
            return None;
        }
        for &k in &self.near[at.near.0 as usize..at.near.1 as usize] {
            let (lo, hi) = self.bounds[k as usize];
            if (lo - p).max(p - hi).max(DVec3::ZERO).length() > d0 + 1e-9 {
                continue;
            }
            if distance(k) <= d0 {
                return None;
            }
        }
        Some(patch)
    }
}

/// Pieces per bounding run in the nearest-piece search.
const CHUNK: usize = 16;

/// Largest grid (voxels × 8 axis slots) that gets a dense lookup table.
const DENSE_TABLE: u64 = 1 << 24;

impl PatchLocator {
    pub fn new(set: &PatchSet, scene: &Scene) -> Self {
        let keys: Vec<u64> = set
            .patches
            .iter()
            .map(|p| group_key(p.voxel, p.axis, set.dims))
            .collect();
        let ranges: Vec<(usize, usize)> = set
            .patches
            .iter()
            .map(|p| (p.first_piece as usize, p.piece_count as usize))
            .collect();
        let pieces: Vec<(Vec<DVec3>, DVec3)> = set
            .pieces
            .iter()
            .map(|p| {
                (
                    p.vertices.iter().map(|&v| DVec3::from(v)).collect(),
                    DVec3::from(p.normal),
                )
            })
            .collect();
        let spheres: Vec<(DVec3, f64)> = pieces
            .iter()
            .map(|(poly, _)| {
                let c = poly.iter().sum::<DVec3>() / poly.len().max(1) as f64;
                let r = poly.iter().map(|&v| (v - c).length()).fold(0.0, f64::max);
                (c, r)
            })
            .collect();
        let (mut chunks, mut chunk_first) = (Vec::new(), Vec::with_capacity(set.patches.len()));
        for &(first, count) in &ranges {
            chunk_first.push(chunks.len());
            for run in spheres[first..first + count].chunks(CHUNK) {
                let c = run.iter().map(|s| s.0).sum::<DVec3>() / run.len() as f64;
                // Rounded up a little, so no piece's sphere pokes out by rounding.
                let r = run
                    .iter()
                    .map(|s| (s.0 - c).length() + s.1)
                    .fold(0.0, f64::max);
                chunks.push((c, r * (1.0 + 1e-12) + 1e-12));
            }
        }
        let triangle_axis = (0..scene.triangles.len())
            .map(|t| {
                let [a, b, c] = scene.corners(t).map(|v| v.as_dvec3());
                dominant_axis((b - a).cross(c - a))
            })
            .collect();
        let slots = set.dims.iter().map(|&d| d as u64).product::<u64>() * 8;
        let mut table = Vec::new();
        if slots <= DENSE_TABLE {
            table = vec![(0u32, 0u32); slots as usize];
            for (i, &k) in keys.iter().enumerate() {
                let e = &mut table[k as usize];
                if e.1 == 0 {
                    e.0 = i as u32;
                }
                e.1 += 1;
            }
        }
        PatchLocator {
            dims: set.dims,
            keys,
            ranges,
            pieces,
            spheres,
            chunks,
            chunk_first,
            triangle_axis,
            piece_triangle: set.pieces.iter().map(|p| p.triangle).collect(),
            table,
            hits: OnceLock::new(),
        }
    }

    /// Dominant axis of scene triangle `t`.
    pub fn triangle_axis(&self, t: u32) -> u8 {
        self.triangle_axis[t as usize]
    }

    /// The patches of a voxel (which may lie outside the grid) with the given axis.
    pub fn candidates(&self, voxel: [i64; 3], axis: u8) -> std::ops::Range<usize> {
        if (0..3).any(|a| voxel[a] < 0 || voxel[a] >= self.dims[a] as i64) {
            return 0..0;
        }
        let key = group_key(voxel.map(|v| v as u32), axis, self.dims);
        if !self.table.is_empty() {
            let (first, count) = self.table[key as usize];
            return first as usize..(first + count) as usize;
        }
        let lo = self.keys.partition_point(|&k| k < key);
        let hi = lo + self.keys[lo..].partition_point(|&k| k == key);
        lo..hi
    }

    /// The first of patch `i`'s pieces nearest to `p` — (distance, closest point, piece) — or
    /// (∞, p, 0) when none comes within `bound`. A piece whose bounding sphere lies farther than
    /// the best so far is skipped: no point of it is nearer than |p − c| − r, and the margin
    /// (1e-9 grid units, far above the rounding of either side) keeps every piece that could
    /// tie or win, so the answer is the one a full scan gives.
    ///
    /// Pieces are also bounded in runs of [`CHUNK`] (a sphere holding the run's spheres), and
    /// the run nearest to `p` is searched first so the best tightens at once. Runs are visited
    /// out of order, so a tie is settled by the lower piece index, as the in-order scan does.
    fn nearest_piece(&self, p: DVec3, i: usize, bound: f64) -> (f64, DVec3, usize) {
        let (first, count) = self.ranges[i];
        let chunks = self.runs(i);
        let lower = |s: &(DVec3, f64)| beyond(p, s);
        let start = (0..chunks.len())
            .min_by(|&a, &b| lower(&chunks[a]).total_cmp(&lower(&chunks[b])))
            .unwrap_or(0);
        let mut best = (f64::INFINITY, p, usize::MAX);
        for run in std::iter::once(start).chain((0..chunks.len()).filter(|&r| r != start)) {
            if lower(&chunks[run]) > best.0.min(bound) + 1e-9 {
                continue;
            }
            let lo = first + run * CHUNK;
            for k in lo..(lo + CHUNK).min(first + count) {
                if lower(&self.spheres[k]) > best.0.min(bound) + 1e-9 {
                    continue;
                }
                let (poly, n) = &self.pieces[k];
                let q = geometry::closest_point_on_polygon(p, poly, *n);
                let d = (q - p).length();
                if d < best.0 || (d == best.0 && k < best.2) {
                    best = (d, q, k);
                }
            }
        }
        if best.2 == usize::MAX {
            best.2 = 0;
        }
        best
    }

    /// Distance from `p` to patch `i`'s pieces, the closest point on them and the unit normal
    /// of the piece it lies on.
    pub fn nearest(&self, p: DVec3, i: usize) -> (f64, DVec3, DVec3) {
        match self.nearest_piece(p, i, f64::INFINITY) {
            (d, q, k) if d.is_finite() => (d, q, self.pieces[k].1),
            (d, q, _) => (d, q, DVec3::Z),
        }
    }

    /// The patch of `voxel` with `axis` nearest to `p`: (patch, distance, closest point).
    pub fn nearest_in_voxel(
        &self,
        p: DVec3,
        voxel: [i64; 3],
        axis: u8,
    ) -> Option<(u32, f64, DVec3)> {
        self.nearest_in_voxel_within(p, voxel, axis, f64::INFINITY)
    }

    /// [`PatchLocator::nearest_in_voxel`] given an upper bound of the answer's distance (the
    /// same answer: a patch that could reach or tie the nearest is never pruned).
    fn nearest_in_voxel_within(
        &self,
        p: DVec3,
        voxel: [i64; 3],
        axis: u8,
        bound: f64,
    ) -> Option<(u32, f64, DVec3)> {
        // Each patch is searched within the nearest distance found so far (a patch that cannot
        // tie it returns ∞), which changes no answer; the patches are searched in the order of
        // their nearest run's lower bound, so the bound tightens at the first, and a patch whose
        // every run lies beyond it is skipped whole. Ties still go to the lower patch index:
        // a patch that ties the nearest is never pruned, and the minimum is taken over all.
        // The order is kept on the stack for a voxel of up to 16 such patches (nearly all);
        // the keys are distinct (the index breaks ties), so an unstable sort gives the order a
        // stable one does.
        let mut bound = bound;
        let candidates = self.candidates(voxel, axis);
        let mut small = [(0.0, 0); 16];
        let mut large = Vec::new();
        let order: &mut [(f64, usize)] = if candidates.len() <= small.len() {
            for (slot, i) in small.iter_mut().zip(candidates.clone()) {
                *slot = (self.lower_bound(p, i), i);
            }
            &mut small[..candidates.len()]
        } else {
            large.extend(candidates.map(|i| (self.lower_bound(p, i), i)));
            &mut large
        };
        order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        order
            .iter()
            .map(|&(lower, i)| {
                if lower > bound + 1e-9 {
                    return (i as u32, f64::INFINITY, p);
                }
                let (d, q, _) = self.nearest_piece(p, i, bound);
                bound = bound.min(d);
                (i as u32, d, q)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
    }

    /// A lower bound of the distance from `p` to patch `i`'s pieces: the nearest of its runs'
    /// spheres.
    fn lower_bound(&self, p: DVec3, i: usize) -> f64 {
        self.runs(i)
            .iter()
            .map(|s| beyond(p, s))
            .fold(f64::INFINITY, f64::min)
    }

    /// The bounding spheres of patch `i`'s runs of [`CHUNK`] pieces.
    fn runs(&self, i: usize) -> &[(DVec3, f64)] {
        let first = self.chunk_first[i];
        &self.chunks[first..first + self.ranges[i].1.div_ceil(CHUNK)]
    }

    /// The patch a point `p` (grid coordinates) on a surface with dominant `axis` belongs to.
    pub fn locate(&self, p: DVec3, axis: u8) -> Option<u32> {
        self.locate_on(p, axis, None)
    }

    /// [`PatchLocator::locate`], where `p` is known to lie on scene triangle `on` (if given):
    /// the distance to that triangle's pieces in the voxel bounds the nearest-patch search from
    /// the start, which prunes the other patches' pieces without changing the answer.
    fn locate_on(&self, p: DVec3, axis: u8, on: Option<u32>) -> Option<u32> {
        let v = voxel_of(p, self.dims);
        let own = self.candidates(v, axis);
        if own.len() == 1 {
            // The common case: one patch of this orientation in the voxel (several only where a
            // wall thinner than a voxel separates surfaces; then the nearest one decides).
            return Some(own.start as u32);
        }
        self.search(p, axis, on, v, own)
    }

    /// The nearest-piece search of [`PatchLocator::locate_on`] past its early exit, in voxel `v`
    /// whose patches of `axis` are `own` (not exactly one).
    fn search(
        &self,
        p: DVec3,
        axis: u8,
        on: Option<u32>,
        v: [i64; 3],
        own: std::ops::Range<usize>,
    ) -> Option<u32> {
        let mut bound = f64::INFINITY;
        if let Some(t) = on {
            for i in own {
                let (first, count) = self.ranges[i];
                for k in first..first + count {
                    if self.piece_triangle[k] == t {
                        let (poly, n) = &self.pieces[k];
                        let q = geometry::closest_point_on_polygon(p, poly, *n);
                        bound = bound.min((q - p).length());
                    }
                }
            }
        }
        if let Some((i, d, _)) = self.nearest_in_voxel_within(p, v, axis, bound) {
            if d <= ON_SURFACE {
                return Some(i);
            }
        }
        let mut best: Option<(u32, f64, DVec3)> = None;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let w = [v[0] + dx, v[1] + dy, v[2] + dz];
                    if let Some(c) = self.nearest_in_voxel(p, w, axis) {
                        if best.is_none_or(|b| c.1 < b.1) {
                            best = Some(c);
                        }
                    }
                }
            }
        }
        best.filter(|b| b.1 <= MAX_DISTANCE).map(|b| b.0)
    }

    /// The patch of a ray hit on scene triangle `t` at `p`: [`PatchLocator::locate_hit_searching`]'s
    /// answer, found in O(1) by the triangle's own pieces ([`HitIndex`]) unless the point lies
    /// off them.
    pub fn locate_hit(&self, p: DVec3, t: u32) -> Option<u32> {
        let axis = self.triangle_axis(t);
        let v = voxel_of(p, self.dims);
        let own = self.candidates(v, axis);
        if own.len() == 1 {
            return Some(own.start as u32);
        }
        if !own.is_empty() {
            let key = group_key(v.map(|c| c as u32), axis, self.dims);
            let hits = self.hits.get_or_init(|| HitIndex::new(self));
            if let Some(i) = hits.locate(self, p, t, key) {
                return Some(i);
            }
        }
        self.search(p, axis, Some(t), v, own)
    }

    /// [`PatchLocator::locate_hit`] by the nearest-piece search alone (the reference the table
    /// is tested against).
    pub fn locate_hit_searching(&self, p: DVec3, t: u32) -> Option<u32> {
        self.locate_on(p, self.triangle_axis(t), Some(t))
    }
}

/// How far `p` lies beyond a sphere (centre, radius): no point in it is nearer.
fn beyond(p: DVec3, &(c, r): &(DVec3, f64)) -> f64 {
    (p - c).length() - r
}

/// The voxel containing `p` (clamped into the grid).
pub fn voxel_of(p: DVec3, dims: [u32; 3]) -> [i64; 3] {
    std::array::from_fn(|a| (p[a].floor() as i64).clamp(0, dims[a] as i64 - 1))
}
