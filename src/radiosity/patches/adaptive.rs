//! Adaptive patches: `Resolution::Adaptive(target: n)` spends the patch budget where a single
//! patch would misrepresent its surface, instead of one voxel size everywhere.
//!
//! It starts from the uniform voxelization of a coarser grid (about `base_share · n` patches,
//! default 0.75;
//! [`crate::radiosity::patches::voxel_size`]) and refines each voxel as an octree of *cells*:
//!
//! 1. **Materials.** Each cluster of mutually visible pieces of a (voxel, axis) group
//!    ([`crate::radiosity::patches::clip::clusters`]) is split into classes whose albedos differ by at most
//!    `albedo_tolerance` per channel and whose emissions agree within the same relative
//!    tolerance: a picture frame on a wall or a hinge on a door keeps its own patch instead of
//!    taking the light of what it touches.
//! 2. **Geometry.** Cells whose pieces do not face one way (|Σ aᵢ nᵢ| / Σ aᵢ below [`FLAT`]:
//!    curved or folded surfaces) are split into their octants, most bent (× √area) first,
//!    until half of the remaining budget is spent.
//! 3. **Light.** A coarse bake of the scene's emitters over the cells gives each cell its
//!    gathered light H (the caller's `light`; [`crate::radiosity::patches::voxelize`] uses reciprocal hemisphere
//!    form factors and Gauss–Seidel). A cell's *variation* is the largest relative difference
//!    `|H_i − H_j| / (H_i + H_j)` to a neighbouring cell of the same orientation that touches it,
//!    lies within half a cell of its plane and sees it. Cells are split in order of variation ×
//!    √area until the count reaches the target; a split cell's octants inherit its variation.
//!
//! A split cuts the cell's pieces at its three mid-planes (a piece within [`SNAP`] of a plane
//! is not cut) and clusters each octant's pieces by visibility again, so the wall rule of the
//! uniform grid holds at every level. A cell is split at most `max_level` times. Cells stay
//! inside their voxel: every cell is an ordinary patch of its (voxel, axis) group, so the
//! locator, the form factors, the transfer to the mesh and the baked format are those of the
//! uniform grid (which already allows several patches per group).
//!
//! Preconditions: pieces in grid coordinates of the base grid, keyed by (voxel, axis) group;
//! `groups` lists every piece once.

use crate::radiosity::geometry::{self, split_key};
use crate::radiosity::patches::clip::{split_visible, MIN_PIECE_AREA, SNAP};
use crate::radiosity::Piece;
use crate::raytrace::visibility::Visibility;
use crate::scene::Scene;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

/// Knobs of `Resolution::Adaptive`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptiveParams {
    /// Patches wanted in all (lands within ±20 % or the stage says why not).
    pub target: u32,
    /// Largest per-channel albedo difference of pieces that may share a patch.
    #[serde(default = "default_albedo_tolerance")]
    pub albedo_tolerance: f64,
    /// Most octree splits of a voxel (cells down to voxel / 2^max_level).
    #[serde(default = "default_max_level")]
    pub max_level: u8,
    /// Share of the target the base grid is sized for; the rest goes to refinement.
    #[serde(default = "default_base_share")]
    pub base_share: f64,
}

/// Default `albedo_tolerance`.
pub const ALBEDO_TOLERANCE: f64 = 0.1;

fn default_albedo_tolerance() -> f64 {
    ALBEDO_TOLERANCE
}
fn default_max_level() -> u8 {
    2
}
/// Default `base_share`: on the door-ajar room 0.75 misses Mitsuba by 24 / 11 / 4.9 % (worst
/// dark object at 1,000 / 2,000 / 4,000 patches) where 0.5 missed by 31 / 9.7 / 5.1 %, and its
/// display-mesh figure is better at 1,000 and 2,000 (docs/radiosity.md).
fn default_base_share() -> f64 {
    0.75
}

impl AdaptiveParams {
    /// The defaults for `target` patches.
    pub fn new(target: u32) -> Self {
        AdaptiveParams {
            target,
            albedo_tolerance: default_albedo_tolerance(),
            max_level: default_max_level(),
            base_share: default_base_share(),
        }
    }

    /// Why the knobs cannot work, if they cannot.
    pub fn check(&self) -> Result<(), String> {
        if self.target == 0 {
            return Err("out of range: Adaptive target 0 (must be at least 1)".into());
        }
        if !(self.albedo_tolerance.is_finite() && self.albedo_tolerance >= 0.0) {
            return Err(format!(
                "out of range: albedo_tolerance {} (must be a finite number ≥ 0)",
                self.albedo_tolerance
            ));
        }
        if self.max_level > 6 {
            return Err(format!(
                "out of range: max_level {} (at most 6: cells of voxel / 64)",
                self.max_level
            ));
        }
        if !(self.base_share > 0.0 && self.base_share <= 1.0) {
            return Err(format!(
                "out of range: base_share {} (must be in (0, 1])",
                self.base_share
            ));
        }
        Ok(())
    }
}

/// Flatness below which a cell counts as bent: |Σ a n| / Σ a (0.95 ≈ normals ±18° apart).
pub const FLAT: f64 = 0.95;

/// One cell: an axis-aligned box inside a voxel (grid coordinates) and the mutually visible,
/// same-material pieces of one orientation it holds.
#[derive(Clone, Debug)]
pub struct Cell {
    /// The (voxel, axis) group.
    pub key: u64,
    /// Lowest corner and edge length of the box.
    pub lo: DVec3,
    pub size: f64,
    pub level: u8,
    /// Indices into the piece arena.
    pub members: Vec<usize>,
}

/// What refinement made of the budget.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Refinement {
    /// Cells after the material split (the input of [`refine`]).
    pub after_materials: usize,
    /// Octree splits for geometry and for light.
    pub geometry_splits: usize,
    pub light_splits: usize,
    /// False when the scene has no emitter (light refinement then splits the largest cells).
    pub lit: bool,
}

/// Split each cluster of `groups` (pieces by (voxel, axis) group) into cells of matching
/// material (by each material's mean albedo over its texture); also returns how many cells the split added.
pub fn by_material(
    scene: &Scene,
    groups: Vec<(u64, Vec<usize>)>,
    pieces: &[(u64, Piece)],
    dims: [u32; 3],
    tolerance: f64,
) -> (Vec<Cell>, usize) {
    let mut cells: Vec<Cell> = Vec::new();
    let mut added = 0;
    let means = scene.mean_albedos();
    for (key, members) in groups {
        let (voxel, _) = split_key(key, dims);
        let classes = material_classes(scene, &means, &members, pieces, tolerance);
        added += classes.len() - 1;
        cells.extend(classes.into_iter().map(|members| Cell {
            key,
            lo: DVec3::from(voxel.map(|v| v as f64)),
            size: 1.0,
            level: 0,
            members,
        }));
    }
    (cells, added)
}

/// Refine `cells` ([`by_material`]) by geometry, then by light, up to the target. `light(cells,
/// pieces)` returns the coarse gathered light (one value per cell, in the order given), or
/// `None` when the scene has no emitter. New pieces are appended to `pieces`.
pub fn refine(
    pieces: &mut Vec<(u64, Piece)>,
    cells: Vec<Cell>,
    dims: [u32; 3],
    vis: &Visibility,
    params: &AdaptiveParams,
    light: impl FnOnce(&[Cell], &[(u64, Piece)]) -> Option<Vec<f64>>,
) -> (Vec<Cell>, Refinement) {
    let mut report = Refinement {
        after_materials: cells.len(),
        ..Default::default()
    };
    let target = params.target as usize;
    let mut tree = Tree {
        cells: cells.into_iter().map(Some).collect(),
        live: report.after_materials,
        max_level: params.max_level,
    };

    // Geometry: bent cells, up to half of what the budget has left.
    let geometry_budget = tree.live + target.saturating_sub(tree.live) / 2;
    let mut heap: BinaryHeap<Queued> = BinaryHeap::new();
    for (i, c) in tree.cells.iter().enumerate() {
        let c = c.as_ref().unwrap();
        let flat = flatness(c, pieces);
        if flat < FLAT {
            heap.push(Queued::new((1.0 - flat) * cell_area(c, pieces).sqrt(), i));
        }
    }
    while tree.live < geometry_budget {
        let Some(q) = heap.pop() else { break };
        let Some(children) = tree.split(q.cell, pieces, vis) else {
            continue;
        };
        report.geometry_splits += 1;
        for i in children {
            let c = tree.cells[i].as_ref().unwrap();
            let flat = flatness(c, pieces);
            if flat < FLAT {
                heap.push(Queued::new((1.0 - flat) * cell_area(c, pieces).sqrt(), i));
            }
        }
    }

    // Light: where the coarse bake varies between neighbours.
    if tree.live < target {
        let order = tree.ordered();
        let view: Vec<Cell> = order
            .iter()
            .map(|&i| tree.cells[i].clone().unwrap())
            .collect();
        let h = light(&view, pieces);
        report.lit = h.is_some();
        let variation = match h {
            Some(h) => variation(&view, &h, pieces, dims, vis),
            None => vec![1.0; view.len()],
        };
        let mut heap: BinaryHeap<Queued> = order
            .iter()
            .zip(&variation)
            .map(|(&i, &v)| {
                let c = tree.cells[i].as_ref().unwrap();
                Queued::new(v * cell_area(c, pieces).sqrt(), i)
            })
            .collect();
        let mut inherited: HashMap<usize, f64> = order.iter().copied().zip(variation).collect();
        while tree.live < target {
            let Some(q) = heap.pop() else { break };
            let v = inherited[&q.cell];
            let Some(children) = tree.split(q.cell, pieces, vis) else {
                continue;
            };
            report.light_splits += 1;
            for i in children {
                inherited.insert(i, v);
                let c = tree.cells[i].as_ref().unwrap();
                heap.push(Queued::new(v * cell_area(c, pieces).sqrt(), i));
            }
        }
    }
    let order = tree.ordered();
    let cells = order
        .into_iter()
        .map(|i| tree.cells[i].take().unwrap())
        .collect();
    (cells, report)
}

/// Split `members` into classes of matching material, in order of first appearance.
fn material_classes(
    scene: &Scene,
    means: &[[f32; 3]],
    members: &[usize],
    pieces: &[(u64, Piece)],
    tolerance: f64,
) -> Vec<Vec<usize>> {
    let mut classes: Vec<([f32; 3], [f32; 3], Vec<usize>)> = Vec::new();
    for &i in members {
        let t = pieces[i].1.triangle as usize;
        let material = scene.triangle_material[t] as usize;
        let (m, albedo) = (&scene.materials[material], means[material]);
        let fits = |a: &[f32; 3], e: &[f32; 3]| {
            (0..3).all(|c| {
                (a[c] - albedo[c]).abs() as f64 <= tolerance
                    && (e[c] - m.emission[c]).abs() as f64
                        <= tolerance * e[c].max(m.emission[c]) as f64
            })
        };
        match classes.iter_mut().find(|(a, e, _)| fits(a, e)) {
            Some(class) => class.2.push(i),
            None => classes.push((albedo, m.emission, vec![i])),
        }
    }
    classes.into_iter().map(|c| c.2).collect()
}

fn cell_area(c: &Cell, pieces: &[(u64, Piece)]) -> f64 {
    c.members.iter().map(|&i| pieces[i].1.area).sum()
}

/// |Σ a n| / Σ a over the cell's pieces: 1 when they face one way.
fn flatness(c: &Cell, pieces: &[(u64, Piece)]) -> f64 {
    let (mut sum, mut area) = (DVec3::ZERO, 0.0);
    for &i in &c.members {
        let p = &pieces[i].1;
        sum += p.area * DVec3::from(p.normal);
        area += p.area;
    }
    if area > 0.0 {
        sum.length() / area
    } else {
        1.0
    }
}

fn centroid(c: &Cell, pieces: &[(u64, Piece)]) -> (DVec3, DVec3) {
    let (area, sum, normal) =
        crate::radiosity::piece_moments(c.members.iter().map(|&i| &pieces[i].1));
    (
        sum / area.max(f64::MIN_POSITIVE),
        normal.normalize_or_zero(),
    )
}

/// The largest relative difference of each cell's light `h` to a touching, coplanar, visible
/// neighbour of the same orientation (0 where it has none).
fn variation(
    cells: &[Cell],
    h: &[f64],
    pieces: &[(u64, Piece)],
    dims: [u32; 3],
    vis: &Visibility,
) -> Vec<f64> {
    let lift = 4.0 * vis.epsilon as f64;
    let mut by_voxel: HashMap<([u32; 3], u8), Vec<usize>> = HashMap::new();
    for (i, c) in cells.iter().enumerate() {
        by_voxel.entry(split_key(c.key, dims)).or_default().push(i);
    }
    let frames: Vec<(DVec3, DVec3)> = cells.iter().map(|c| centroid(c, pieces)).collect();
    let scale = h.iter().sum::<f64>() / h.len().max(1) as f64;
    let floor = 1e-3 * scale;
    cells
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let (voxel, axis) = split_key(c.key, dims);
            let (ci, ni) = frames[i];
            let mut worst: f64 = 0.0;
            for d in 0..27 {
                let off = [d % 3, (d / 3) % 3, d / 9].map(|o| o as i64 - 1);
                let v: [i64; 3] = std::array::from_fn(|a| voxel[a] as i64 + off[a]);
                if (0..3).any(|a| v[a] < 0 || v[a] >= dims[a] as i64) {
                    continue;
                }
                let Some(list) = by_voxel.get(&(v.map(|x| x as u32), axis)) else {
                    continue;
                };
                for &j in list {
                    let o = &cells[j];
                    let (cj, nj) = frames[j];
                    if j == i || !touching(c, o) || ni.dot(nj) < 0.5 {
                        continue;
                    }
                    if ni.dot(cj - ci).abs() > 0.5 * c.size.max(o.size) {
                        continue;
                    }
                    if vis.occluded(ci + ni * lift, cj + nj * lift) {
                        continue;
                    }
                    let r = (h[i] - h[j]).abs() / (h[i] + h[j] + floor);
                    worst = worst.max(r);
                }
            }
            worst
        })
        .collect()
}

/// Whether two cell boxes touch or overlap.
fn touching(a: &Cell, b: &Cell) -> bool {
    (0..3).all(|k| a.lo[k] <= b.lo[k] + b.size + SNAP && b.lo[k] <= a.lo[k] + a.size + SNAP)
}

/// The cells, split ones removed (`None`), and how many are live.
struct Tree {
    cells: Vec<Option<Cell>>,
    live: usize,
    max_level: u8,
}

impl Tree {
    /// Split cell `i` into its octants' visibility clusters; their indices, or `None` when the
    /// cell is at the deepest level (or already split).
    fn split(
        &mut self,
        i: usize,
        pieces: &mut Vec<(u64, Piece)>,
        vis: &Visibility,
    ) -> Option<Vec<usize>> {
        if self.cells[i].as_ref()?.level >= self.max_level {
            return None;
        }
        let cell = self.cells[i].take()?;
        let half = cell.size / 2.0;
        let mid = cell.lo + DVec3::splat(half);
        let mut octants: [Vec<usize>; 8] = Default::default();
        for &m in &cell.members {
            let (key, piece) = (pieces[m].0, pieces[m].1.clone());
            let poly: Vec<DVec3> = piece.vertices.iter().map(|&v| DVec3::from(v)).collect();
            for (o, part) in octant_parts(poly, mid) {
                let area = geometry::area(&part);
                if area > MIN_PIECE_AREA {
                    pieces.push((
                        key,
                        Piece {
                            vertices: part.iter().map(|p| p.to_array()).collect(),
                            area,
                            ..piece.clone()
                        },
                    ));
                    octants[o].push(pieces.len() - 1);
                }
            }
        }
        let mut children = Vec::new();
        for (o, members) in octants.iter().enumerate() {
            if members.is_empty() {
                continue;
            }
            let offset = DVec3::new((o & 1) as f64, ((o >> 1) & 1) as f64, (o >> 2) as f64);
            for cluster in split_visible(members, pieces, vis) {
                self.cells.push(Some(Cell {
                    key: cell.key,
                    lo: cell.lo + offset * half,
                    size: half,
                    level: cell.level + 1,
                    members: cluster,
                }));
                children.push(self.cells.len() - 1);
            }
        }
        self.live = self.live - 1 + children.len();
        Some(children)
    }

    /// Indices of the live cells sorted by (group, box, first piece): the patch order.
    fn ordered(&self) -> Vec<usize> {
        let mut order: Vec<usize> = (0..self.cells.len())
            .filter(|&i| self.cells[i].is_some())
            .collect();
        let sort_key = |i: usize| {
            let c = self.cells[i].as_ref().unwrap();
            (c.key, [c.lo.z, c.lo.y, c.lo.x, c.size], c.members[0])
        };
        order.sort_by(|&a, &b| {
            let (ka, kb) = (sort_key(a), sort_key(b));
            ka.0.cmp(&kb.0)
                .then_with(|| {
                    ka.1.iter()
                        .zip(&kb.1)
                        .map(|(x, y)| x.total_cmp(y))
                        .find(|o| o.is_ne())
                        .unwrap_or(Ordering::Equal)
                })
                .then(ka.2.cmp(&kb.2))
        });
        order
    }
}

/// The parts of a polygon in the octants about `mid` (octant bit k set: above on axis k). A
/// polygon within [`SNAP`] of a mid-plane is not cut by it.
fn octant_parts(poly: Vec<DVec3>, mid: DVec3) -> Vec<(usize, Vec<DVec3>)> {
    let mut parts = vec![(0usize, poly)];
    for axis in 0..3 {
        let mut next = Vec::with_capacity(parts.len() * 2);
        for (o, q) in parts {
            let lo = q.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
            let hi = q.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
            if hi <= mid[axis] + SNAP {
                next.push((o, q));
            } else if lo >= mid[axis] - SNAP {
                next.push((o | 1 << axis, q));
            } else {
                let (below, above) = geometry::split_axis(&q, axis, mid[axis]);
                if !below.is_empty() {
                    next.push((o, below));
                }
                if !above.is_empty() {
                    next.push((o | 1 << axis, above));
                }
            }
        }
        parts = next;
    }
    parts
}

/// A cell waiting in a refinement queue: highest priority first, then lowest index.
#[derive(PartialEq)]
struct Queued {
    priority: f64,
    cell: usize,
}

impl Queued {
    fn new(priority: f64, cell: usize) -> Self {
        Queued { priority, cell }
    }
}

impl Eq for Queued {}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        self.priority
            .total_cmp(&other.priority)
            .then_with(|| other.cell.cmp(&self.cell))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octant_parts_cover_the_polygon_once() {
        let tri = vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(0.9, 0.4, 0.6),
            DVec3::new(0.3, 0.95, 0.8),
        ];
        let parts = octant_parts(tri.clone(), DVec3::splat(0.5));
        let sum: f64 = parts.iter().map(|(_, p)| geometry::area(p)).sum();
        assert!((sum - geometry::area(&tri)).abs() < 1e-12);
        for (o, p) in &parts {
            for q in p {
                for a in 0..3 {
                    let above = o >> a & 1 == 1;
                    assert!(if above {
                        q[a] >= 0.5 - 1e-12
                    } else {
                        q[a] <= 0.5 + 1e-12
                    });
                }
            }
        }
        // A polygon lying in a mid-plane goes to one side whole, not to both.
        let flat = vec![
            DVec3::new(0.1, 0.1, 0.5),
            DVec3::new(0.4, 0.1, 0.5),
            DVec3::new(0.1, 0.4, 0.5),
        ];
        let parts = octant_parts(flat.clone(), DVec3::splat(0.5));
        assert_eq!(parts.len(), 1);
        assert!((geometry::area(&parts[0].1) - geometry::area(&flat)).abs() < 1e-15);
    }

    #[test]
    fn queue_pops_highest_priority_then_lowest_index() {
        let mut h: BinaryHeap<Queued> = [(0.5, 3), (0.9, 7), (0.9, 2), (0.1, 0)]
            .into_iter()
            .map(|(p, c)| Queued::new(p, c))
            .collect();
        let order: Vec<usize> = std::iter::from_fn(|| h.pop().map(|q| q.cell)).collect();
        assert_eq!(order, vec![2, 7, 3, 0]);
    }
}
