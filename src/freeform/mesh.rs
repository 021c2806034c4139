//! Polygonisation of a freeform field: marching tetrahedra on a uniform grid, cells skipped in
//! bulk by an interval octree, vertices refined on the field itself.
//!
//! **Algorithm.** A grid of cells of sides ≤ `h` spans the box exactly. An octree over its index
//! ranges bounds the field on each block with [`field_range`] ([`Bound::Interval`]); a block
//! whose range excludes 0 (by a margin far above rounding) has no sign change and is dropped
//! whole, so the cost follows the surface's area, not the box's volume. Blocks of ≤ 8³ cells
//! evaluate a copy of the field without the perturbations whose support misses them (the same
//! values there). A cell is split into the 6 Kuhn tetrahedra about its main diagonal — the same
//! split everywhere, so faces match — and a tetrahedron with a sign change (inside is
//! `field < 0`) gives 1 triangle or a quad (split on its shorter diagonal) with vertices on its
//! edges, placed by Illinois regula falsi with interleaved bisection on `field.eval` (to 1e-12
//! of the edge). The mesh has the combinatorics of the piecewise-linear level set, so it is a
//! 2-manifold, closed where the surface stays inside the box and cut open at the box. Winding is
//! decided exactly from each tetrahedron's integer corners: counter-clockwise seen from outside.
//!
//! **Spacing rule.** A triangle lies in a tetrahedron of diameter ≤ `h√3`, so (Jung) in a ball
//! of radius `R ≤ h`, and linear interpolation errs by at most `½R²·max|f''|` (Waldron 1998):
//! with vertices on a surface of principal curvatures ≤ κ a triangle is within `½h²κ` of it.
//! So `h = 0.8·√(2·tolerance/κ)` (0.8 for the slope term and curvature between vertices),
//! clamped to `[tolerance, extent/16]`: at `h ≤ tolerance` any triangle point is within `h` of a
//! vertex whatever the curvature, and that floor is also used when some triangle joins two
//! surfaces (a CSG crease, where curvature is unbounded) or lies on a shape texture (bilinear
//! per sample cell, its slope jumps across sample lines). κ is measured: the exact principal
//! curvatures (analytic Hessian of quadrics and perturbations) at every vertex of a pilot mesh,
//! starting at `extent/16` and re-meshing at the rule's spacing until the spacing used meets the
//! rule for what was seen (at most 8 passes).
//!
//! **Preconditions** of mesh → surface ≤ tolerance: the surface is C² between creases, with no
//! feature (bump, handle, gap) smaller than a few cells of the pilot grids — one missed by every
//! pilot is neither meshed nor measured. Each axis has a prime number of cells (the least prime
//! ≥ extent/h), so a plane at `lo + extent·p/q` meets nodes only if `q` is that prime: nodes
//! avoid the round coordinates planes sit on (a node with field exactly 0 counts as outside).
//!
//! **Determinism.** The octree is walked in a fixed child order (in parallel, results
//! concatenated in order), vertices are numbered by sorted edge key, triangles in walk order:
//! the same output for any rayon thread count.
//!
//! A scene that is one shape texture is meshed by its carrier's sample grid instead
//! ([`super::mesh_texture`]).
//!
//! [`hausdorff_to_surface`] and [`coverage_distance`] measure the error both ways (for tests
//! and reports); [`write_obj`] writes Wavefront OBJ.

use super::bounds::{field_range, Bound, Cell, Work};
use super::field::{dot, Field, Leaf, Op};
use crate::error::{Error, Result};
use rayon::prelude::*;

/// What to mesh and how closely.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshParams {
    /// The box meshed (world units); the surface is cut at its border.
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// The largest distance from the mesh to the true surface (world units).
    pub tolerance: f64,
}

/// An indexed triangle mesh, counter-clockwise seen from outside (positive field).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
}

/// How a mesh was made.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshStats {
    /// The spacing bound `h` of the final pass.
    pub spacing: f64,
    /// The largest principal curvature seen at the vertices.
    pub curvature: f64,
    /// Whether some triangle joins two surfaces (a CSG crease).
    pub crease: bool,
    /// Passes run (pilots and the final one).
    pub passes: u32,
    /// Cells of the final grid along x, y, z (marching tetrahedra; 0 for a carrier grid).
    pub grid: [u32; 3],
    /// Points per sample cell and axis of a shape texture meshed by its carrier grid
    /// ([`super::mesh_texture`]); 0 when marching tetrahedra made the mesh.
    pub subdivision: u32,
}

const SAFETY: f64 = 0.8;
const MIN_CELLS: f64 = 16.0;
const MAX_GRID_CELLS: f64 = 2147483648.0;
const MAX_PASSES: u32 = 8;
/// Octree blocks of at most this many cells a side get their own restricted field.
const BLOCK: u32 = 8;
/// The 6 Kuhn tetrahedra of a cell (corner bit masks: 1 = +x, 2 = +y, 4 = +z), each a chain.
const TETS: [[u8; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];
const NO_VERTEX: u64 = u64::MAX;

/// Polygonise the surface `field = 0` inside `params`' box.
pub fn polygonise(field: &Field, params: &MeshParams) -> Result<Mesh> {
    polygonise_with_stats(field, params).map(|(m, _)| m)
}

/// [`polygonise`], also reporting the spacing, curvature and passes.
pub fn polygonise_with_stats(field: &Field, params: &MeshParams) -> Result<(Mesh, MeshStats)> {
    // One textured surface: its own sample grid is the better mesh (no creases to floor at).
    if let ([Op::Leaf(0)], [leaf]) = (field.ops.as_slice(), field.leaves.as_slice()) {
        if let Some(t) = leaf.texture {
            let g = super::mesh_texture::polygonise(&field.textures[t], params.tolerance)?;
            let stats = MeshStats {
                spacing: g.spacing,
                crease: true,
                passes: 1,
                subdivision: g.subdivision,
                ..MeshStats::default()
            };
            let mesh = Mesh {
                positions: g.positions,
                triangles: g.triangles,
            };
            return Ok((mesh, stats));
        }
    }
    let MeshParams { lo, hi, tolerance } = *params;
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(Error::knob(format!(
            "mesh tolerance must be a positive finite number, got {tolerance}"
        )));
    }
    if !(0..3).all(|k| lo[k].is_finite() && hi[k].is_finite() && hi[k] > lo[k]) {
        return Err(Error::knob(format!(
            "mesh box must be finite and non-empty on every axis, got {lo:?}..{hi:?}"
        )));
    }
    let h_cap = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max) / MIN_CELLS;
    let floor = tolerance.min(h_cap);
    let rule = |kappa: f64, crease: bool| match crease {
        true => floor,
        false => (SAFETY * (2.0 * tolerance / kappa).sqrt()).clamp(floor, h_cap),
    };
    let (mut h, mut stats) = (h_cap, MeshStats::default());
    loop {
        let grid = Grid::new(lo, hi, h)?;
        let (mesh, kappa, crease) = grid.mesh(field)?;
        stats.curvature = stats.curvature.max(kappa);
        stats.crease |= crease;
        stats.passes += 1;
        let target = rule(stats.curvature, stats.crease);
        if h <= target * (1.0 + 1e-9) || stats.passes == MAX_PASSES {
            stats.spacing = h;
            stats.grid = grid.n;
            return Ok((mesh, stats));
        }
        h = target;
    }
}

/// The grid: `n[k]` cells of side `h[k]` from `lo[k]` along each axis.
struct Grid {
    lo: [f64; 3],
    h: [f64; 3],
    n: [u32; 3],
}

/// A block's polygons (edge keys; `NO_VERTEX` ends a triangle), its vertices by edge key, their
/// largest curvature and whether a polygon joins two surfaces.
struct Block {
    polys: Vec<[u64; 4]>,
    verts: Vec<(u64, [f64; 3])>,
    kappa: f64,
    crease: bool,
}

/// `field` without the perturbations whose support misses the box: the same values in the box
/// (a skipped term is exactly 0 there), at a fraction of the cost.
pub(super) fn restrict(field: &Field, lo: [f64; 3], hi: [f64; 3]) -> Field {
    let mut bumps = Vec::new();
    let mut leaves = Vec::with_capacity(field.leaves.len());
    for l in &field.leaves {
        let start = bumps.len();
        bumps.extend(
            field.bumps[l.bumps.clone()]
                .iter()
                .filter(|b| match b.support {
                    Some((bl, bh)) => (0..3).all(|k| bh[k] >= lo[k] && bl[k] <= hi[k]),
                    None => true,
                }),
        );
        let bumps = start..bumps.len();
        leaves.push(Leaf { bumps, ..l.clone() });
    }
    let ops = field.ops.clone();
    Field {
        leaves,
        bumps,
        ops,
        textures: field.textures.clone(),
    }
}

fn is_prime(n: u64) -> bool {
    n >= 2
        && (2..)
            .take_while(|d| d * d <= n)
            .all(|d| !n.is_multiple_of(d))
}

pub(super) fn bits(m: u8) -> [u32; 3] {
    [(m & 1) as u32, ((m >> 1) & 1) as u32, ((m >> 2) & 1) as u32]
}

fn add(a: [u32; 3], b: [u32; 3]) -> [u32; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    let c = |i: usize, j: usize| a[i] * b[j] - a[j] * b[i];
    [c(1, 2), c(2, 0), c(0, 1)]
}

pub(super) fn lerp(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
}

pub(super) fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d).sqrt()
}

impl Grid {
    fn new(lo: [f64; 3], hi: [f64; 3], h: f64) -> Result<Grid> {
        let n: [f64; 3] = std::array::from_fn(|k| ((hi[k] - lo[k]) / h).ceil().max(2.0));
        if n[0] * n[1] * n[2] > MAX_GRID_CELLS {
            return Err(Error::knob(format!(
                "mesh grid of {}×{}×{} cells at spacing {h:.3e} is over 2^31 cells: \
                 raise the tolerance or shrink the box",
                n[0], n[1], n[2]
            )));
        }
        let n = n.map(|v| (v as u64..).find(|&p| is_prime(p)).expect("primes go on") as u32);
        let h = std::array::from_fn(|k| (hi[k] - lo[k]) / n[k] as f64);
        Ok(Grid { lo, h, n })
    }

    fn node(&self, i: [u32; 3]) -> [f64; 3] {
        std::array::from_fn(|k| self.lo[k] + self.h[k] * i[k] as f64)
    }

    fn node_id(&self, i: [u32; 3]) -> u64 {
        let (nx, ny) = (self.n[0] as u64 + 1, self.n[1] as u64 + 1);
        i[0] as u64 + nx * (i[1] as u64 + ny * i[2] as u64)
    }

    /// One pass: the mesh, the largest curvature at its vertices, whether it has a crease.
    fn mesh(&self, field: &Field) -> Result<(Mesh, f64, bool)> {
        let blocks = self.blocks(field, [0; 3], self.n);
        let kappa = blocks.iter().map(|b| b.kappa).fold(0.0, f64::max);
        let crease = blocks.iter().any(|b| b.crease);
        // Stable sort: a vertex on a block face keeps its first copy (all copies are equal).
        let mut verts: Vec<(u64, [f64; 3])> = blocks.iter().flat_map(|b| b.verts.clone()).collect();
        verts.sort_by_key(|v| v.0);
        verts.dedup_by_key(|v| v.0);
        if verts.len() > u32::MAX as usize {
            return Err(Error::knob(
                "mesh has over 2^32 vertices: raise the tolerance",
            ));
        }
        let index = |k: u64| match k {
            NO_VERTEX => 0,
            k => verts
                .binary_search_by_key(&k, |v| v.0)
                .expect("every key has a vertex") as u32,
        };
        let len = |a: u32, b: u32| dist(verts[a as usize].1, verts[b as usize].1);
        let mut triangles = Vec::new();
        for p in blocks.iter().flat_map(|b| &b.polys) {
            let v = p.map(index);
            if p[3] == NO_VERTEX {
                triangles.push([v[0], v[1], v[2]]);
            } else if len(v[0], v[2]) <= len(v[1], v[3]) {
                triangles.extend([[v[0], v[1], v[2]], [v[0], v[2], v[3]]]);
            } else {
                triangles.extend([[v[1], v[2], v[3]], [v[1], v[3], v[0]]]);
            }
        }
        let positions = verts.iter().map(|v| v.1).collect();
        Ok((
            Mesh {
                positions,
                triangles,
            },
            kappa,
            crease,
        ))
    }

    /// True when the field's interval range over cells `a..b` may hold 0.
    fn may_hold_surface(&self, field: &Field, a: [u32; 3], b: [u32; 3]) -> bool {
        let (lo, hi) = (self.node(a), self.node(b));
        let half = |k: usize| 0.5 * (hi[k] - lo[k]);
        let cell = Cell {
            c: std::array::from_fn(|k| 0.5 * (lo[k] + hi[k])),
            v: [
                [half(0), 0.0, 0.0],
                [0.0, half(1), 0.0],
                [0.0, 0.0, half(2)],
                [0.0; 3],
                [0.0; 3],
            ],
        };
        let r = field_range(field, &cell, Bound::Interval, &mut Work::default());
        let m = 1e-9 * (1.0 + r.lo.abs() + r.hi.abs());
        !(r.lo > m || r.hi < -m)
    }

    /// The octree children of cells `a..b`, in a fixed order.
    fn children(a: [u32; 3], b: [u32; 3]) -> Vec<([u32; 3], [u32; 3])> {
        let halves = |k: usize| match b[k] - a[k] {
            1 => vec![(a[k], b[k])],
            d => vec![(a[k], a[k] + d / 2), (a[k] + d / 2, b[k])],
        };
        let (x, y, z) = (halves(0), halves(1), halves(2));
        let mut out = Vec::with_capacity(8);
        for &(z0, z1) in &z {
            for &(y0, y1) in &y {
                out.extend(x.iter().map(|&(x0, x1)| ([x0, y0, z0], [x1, y1, z1])));
            }
        }
        out
    }

    /// The blocks of cells `a..b` that may hold surface, in walk order (in parallel).
    fn blocks(&self, field: &Field, a: [u32; 3], b: [u32; 3]) -> Vec<Block> {
        if !self.may_hold_surface(field, a, b) {
            return Vec::new();
        }
        if (0..3).all(|k| b[k] - a[k] <= BLOCK) {
            return vec![self.block(&restrict(field, self.node(a), self.node(b)), a, b)];
        }
        let parts: Vec<Vec<Block>> = (Self::children(a, b).par_iter())
            .map(|&(ca, cb)| self.blocks(field, ca, cb))
            .collect();
        parts.into_iter().flatten().collect()
    }

    /// One block, with the field restricted to it.
    fn block(&self, field: &Field, a: [u32; 3], b: [u32; 3]) -> Block {
        let mut polys = Vec::new();
        self.walk(field, a, b, &mut polys);
        let mut keys: Vec<u64> = polys.iter().flatten().copied().collect();
        keys.retain(|&k| k != NO_VERTEX);
        keys.sort_unstable();
        keys.dedup();
        let verts: Vec<(u64, [f64; 3])> =
            keys.iter().map(|&k| (k, self.vertex(field, k))).collect();
        let leaf: Vec<usize> = verts.iter().map(|v| field.eval_with_leaf(v.1).1).collect();
        let leaf_of = |k: &u64| leaf[keys.binary_search(k).expect("key of this block")];
        // A shape texture is bilinear per sample cell: its slope jumps across every sample
        // line, a crease as sharp as a CSG one.
        let textured = leaf.iter().any(|&l| field.leaves[l].texture.is_some());
        let crease = textured
            || polys.iter().any(|p| {
                let l0 = leaf_of(&p[0]);
                p.iter().any(|k| *k != NO_VERTEX && leaf_of(k) != l0)
            });
        let kappa = verts
            .iter()
            .zip(&leaf)
            .filter(|(_, &l)| field.leaves[l].texture.is_none())
            .map(|(v, _)| curvature(field, v.1))
            .fold(0.0, f64::max);
        Block {
            polys,
            verts,
            kappa,
            crease,
        }
    }

    fn walk(&self, field: &Field, a: [u32; 3], b: [u32; 3], out: &mut Vec<[u64; 4]>) {
        if !self.may_hold_surface(field, a, b) {
            return;
        }
        if (0..3).all(|k| b[k] - a[k] == 1) {
            return self.cell(field, a, out);
        }
        for (ca, cb) in Self::children(a, b) {
            self.walk(field, ca, cb, out);
        }
    }

    /// The polygons of cell `a`, oriented from inside corners to outside ones.
    fn cell(&self, field: &Field, a: [u32; 3], out: &mut Vec<[u64; 4]>) {
        let inside: [bool; 8] =
            std::array::from_fn(|m| field.eval(self.node(add(a, bits(m as u8)))) < 0.0);
        if inside.iter().all(|&s| s) || inside.iter().all(|&s| !s) {
            return;
        }
        // Edge between corners u ⊂ v (bit masks): its lower node and direction.
        let key = |u: u8, v: u8| self.node_id(add(a, bits(u.min(v)))) * 8 + (u ^ v) as u64;
        let twice = |m: u8| bits(m).map(|b| 2.0 * b as f64);
        for tet in TETS {
            let (ins, outs): (Vec<u8>, Vec<u8>) = tet.iter().partition(|&&m| inside[m as usize]);
            if ins.is_empty() || outs.is_empty() {
                continue;
            }
            let mean = |s: &[u8]| {
                let c = s.iter().fold([0.0; 3], |c, &m| {
                    std::array::from_fn(|k| c[k] + twice(m)[k])
                });
                c.map(|v| v / s.len() as f64)
            };
            let outward = sub(mean(&outs), mean(&ins));
            let mut poly: Vec<(u8, u8)> = match (ins.as_slice(), outs.as_slice()) {
                (&[p, q], &[c, d]) => vec![(p, c), (p, d), (q, d), (q, c)],
                (&[lone], rest) | (rest, &[lone]) => rest.iter().map(|&r| (lone, r)).collect(),
                _ => unreachable!("4 corners split 1-3, 2-2 or 3-1"),
            };
            let m: Vec<[f64; 3]> = poly
                .iter()
                .map(|&(u, v)| lerp(twice(u), twice(v), 0.5))
                .collect();
            if dot(cross(sub(m[1], m[0]), sub(m[2], m[0])), outward) < 0.0 {
                poly.reverse();
            }
            let mut k = [NO_VERTEX; 4];
            k.iter_mut()
                .zip(&poly)
                .for_each(|(s, &(u, v))| *s = key(u, v));
            out.push(k);
        }
    }

    /// The surface point on the grid edge `key`.
    fn vertex(&self, field: &Field, key: u64) -> [f64; 3] {
        let (id, nx, ny) = (key / 8, self.n[0] as u64 + 1, self.n[1] as u64 + 1);
        let i = [id % nx, (id / nx) % ny, id / (nx * ny)].map(|v| v as u32);
        let (p, q) = (self.node(i), self.node(add(i, bits((key % 8) as u8))));
        let (fp, fq) = (field.eval(p), field.eval(q));
        match fp < 0.0 {
            true => root(field, p, fp, q, fq),
            false => root(field, q, fq, p, fp),
        }
    }
}

/// The root of the field on segment `a`→`b` (`fa < 0 ≤ fb`): Illinois regula falsi with every
/// fourth step a bisection, to 1e-12 of the segment.
fn root(field: &Field, a: [f64; 3], fa: f64, b: [f64; 3], fb: f64) -> [f64; 3] {
    let (mut t0, mut f0, mut t1, mut f1, mut side) = (0.0, fa, 1.0, fb, 0);
    for it in 0..200 {
        if t1 - t0 <= 1e-12 {
            break;
        }
        let secant = (t0 * f1 - t1 * f0) / (f1 - f0);
        let t = match it % 4 == 3 || !(secant > t0 && secant < t1) {
            true => 0.5 * (t0 + t1),
            false => secant,
        };
        let ft = field.eval(lerp(a, b, t));
        if ft == 0.0 {
            return lerp(a, b, t);
        } else if ft < 0.0 {
            (t0, f0) = (t, ft);
            f1 *= if side == -1 { 0.5 } else { 1.0 };
            side = -1;
        } else {
            (t1, f1) = (t, ft);
            f0 *= if side == 1 { 0.5 } else { 1.0 };
            side = 1;
        }
    }
    lerp(a, b, 0.5 * (t0 + t1))
}

/// The field and its gradient at `p` (of the active surface, with its CSG sign), and the leaf.
pub(super) fn gradient(field: &Field, p: [f64; 3]) -> (f64, [f64; 3], usize) {
    let (f, leaf, sign) = field.eval_with_leaf(p);
    (f, field.leaf_gradient(leaf, p).map(|g| sign * g), leaf)
}

/// The Hessian of leaf `i` at `p`: `2A` of the base plus `3w(2q∇q∇qᵀ + q²·2A_q)` per live bump.
fn leaf_hessian(field: &Field, i: usize, p: [f64; 3]) -> [[f64; 3]; 3] {
    let leaf = &field.leaves[i];
    let mut h = leaf.base.a.map(|r| r.map(|v| 2.0 * v));
    for b in &field.bumps[leaf.bumps.clone()] {
        let q = b.q.eval(p);
        if q > 0.0 {
            let g = b.q.grad(p);
            for (r, row) in h.iter_mut().enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v += 3.0 * b.weight * (2.0 * q * g[r] * g[c] + q * q * 2.0 * b.q.a[r][c]);
                }
            }
        }
    }
    h
}

/// The largest |principal curvature| of the surface through `p` (0 where the gradient is 0).
pub fn curvature(field: &Field, p: [f64; 3]) -> f64 {
    let (_, g, leaf) = gradient(field, p);
    let len = dot(g, g).sqrt();
    if !(len > 0.0 && len.is_finite()) {
        return 0.0;
    }
    let n = g.map(|v| v / len);
    let axis = (0..3)
        .min_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))
        .unwrap_or(0);
    let t1 = cross(n, bits(1 << axis).map(|b| b as f64));
    let t1 = t1.map(|v| v / dot(t1, t1).sqrt());
    let t2 = cross(n, t1);
    let hm = leaf_hessian(field, leaf, p);
    let form = |u: [f64; 3], v: [f64; 3]| dot(u, std::array::from_fn(|r| dot(hm[r], v)));
    let (a, b, d) = (form(t1, t1), form(t1, t2), form(t2, t2));
    (0.5 * (a + d).abs() + (0.25 * (a - d) * (a - d) + b * b).sqrt()) / len
}

/// `x` with 9 significant digits, like C's `%.9g`.
fn g9(x: f64) -> String {
    let trim = |s: &str| match s.contains('.') {
        true => s.trim_end_matches('0').trim_end_matches('.').to_string(),
        false => s.to_string(),
    };
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { "0".into() } else { format!("{x}") };
    }
    let sci = format!("{x:.8e}"); // rounded first, so the exponent is the printed one
    let (mant, exp) = sci.split_once('e').expect("{:e} has an exponent");
    let e: i32 = exp.parse().expect("{:e} exponent is an integer");
    match (-5..9).contains(&e) {
        true => trim(&format!("{:.*}", (8 - e) as usize, x)),
        false => format!("{}e{e}", trim(mant)),
    }
}

/// Write `mesh` as Wavefront OBJ: `v x y z` lines (9 significant digits), then `f a b c` lines
/// (1-based, counter-clockwise seen from outside).
pub fn write_obj(mesh: &Mesh, out: &mut impl std::io::Write) -> std::io::Result<()> {
    use std::io::Write;
    let mut w = std::io::BufWriter::new(out);
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", g9(p[0]), g9(p[1]), g9(p[2]))?;
    }
    for t in &mesh.triangles {
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    w.flush()
}

/// The size in bytes of [`write_obj`]'s output.
pub fn obj_bytes(mesh: &Mesh) -> usize {
    struct Count(usize);
    impl std::io::Write for Count {
        fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
            self.0 += b.len();
            Ok(b.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }
    let mut c = Count(0);
    write_obj(mesh, &mut c).expect("counting never fails");
    c.0
}
pub use super::mesh_error::{
    coverage_distance, hausdorff_to_surface, point_triangle_distance, surface_distance,
    surface_samples,
};
