//! Recursive multilevel ray casting (RMLRC, Vyatkin et al. 2018), level by level.
//!
//! The screen is covered by square tiles of `2^top` pixels. Each tile carries a log-depth range
//! `[s_lo, s_hi]` that holds the first surface point of every pixel ray under it. A level's pass
//! walks its tile's range front to back in cells of log size `2^L · θ₀` (θ₀ = one pixel's angle,
//! so cells are about cubic) and bounds the field over each cell ([`bounds::field_range`]):
//! - a cell whose range excludes 0 holds no surface and is culled;
//! - the first cell that may hold surface starts the tile's new range;
//! - a cell where the field is negative everywhere is wholly solid, so every ray of the tile
//!   has already entered the solid: the range ends there (when the camera is outside).
//!
//! The four child tiles of the next level start from their parent's range. At the pixel level
//! the centre ray's range is bisected depth-first, front to back, down to cells of `θ₀ / 2^refine`;
//! the first finest cell whose bound holds 0 is the hit: its sign change is bisected to full
//! precision, or, without one (a shell thinner than the cell, a tangent graze), its midpoint is
//! taken. A surface point is never culled, because every cell that holds one has a bound that
//! holds 0: the caster cannot miss a hit the bounds can see.
//!
//! Each level is one parallel pass over its tiles (the GPU runs one compute pass per level);
//! results are independent of the thread count.

use super::bounds::{field_range, Bound, Work};
use super::field::Field;
use super::view::{line_cell, View};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Knobs of the multilevel caster.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RmlrcParams {
    pub bound: Bound,
    /// Tiles of the first level are `2^top_level` pixels wide.
    pub top_level: u32,
    /// The finest depth cell is one pixel's angle over `2^refine`.
    pub refine: u32,
}

impl Default for RmlrcParams {
    fn default() -> Self {
        RmlrcParams {
            bound: Bound::Affine,
            top_level: 5,
            refine: 6,
        }
    }
}

/// The counts the caster reports.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CastStats {
    /// Cells whose bound was evaluated, per level (index 0 = the pixel level).
    pub nodes_per_level: Vec<u64>,
    /// Cells whose bound was evaluated, all levels.
    pub nodes: u64,
    /// Quadric terms evaluated inside those bounds.
    pub bound_terms: u64,
    /// Point evaluations of the field (sign checks and root bisection).
    pub point_evals: u64,
}

/// One pixel's result: the distance along its unit ray, or `None`.
pub type PixelHit = Option<f64>;

#[derive(Clone, Copy, Debug)]
struct TileRange {
    lo: f64,
    hi: f64,
}

const EMPTY: TileRange = TileRange {
    lo: f64::INFINITY,
    hi: f64::NEG_INFINITY,
};

#[derive(Default, Clone, Copy)]
struct Counts {
    nodes: u64,
    terms: u64,
    points: u64,
}

impl std::ops::Add for Counts {
    type Output = Counts;
    fn add(self, o: Counts) -> Counts {
        Counts {
            nodes: self.nodes + o.nodes,
            terms: self.terms + o.terms,
            points: self.points + o.points,
        }
    }
}

/// True when the field is positive over the whole near end of the view: the camera is outside
/// the solid and wholly-solid cells may end a range.
pub fn camera_outside(field: &Field, view: &View, bound: Bound) -> bool {
    let s0 = view.near.ln();
    let cell = view.cell(
        [-view.tan_x, view.tan_x],
        [-view.tan_y, view.tan_y],
        [s0, s0 + 1e-3],
    );
    field_range(field, &cell, bound, &mut Work::default()).lo > 0.0
}

/// Walk one tile's range at cell size `ds` and return its new range.
#[allow(clippy::too_many_arguments)]
fn tile_pass(
    field: &Field,
    view: &View,
    bound: Bound,
    x: [f64; 2],
    y: [f64; 2],
    parent: TileRange,
    ds: f64,
    prune: bool,
    counts: &mut Counts,
) -> TileRange {
    if parent.lo > parent.hi {
        return EMPTY;
    }
    let s_near = view.near.ln();
    let first = ((parent.lo - s_near) / ds).floor() as i64;
    let last = ((parent.hi - s_near) / ds).ceil() as i64;
    let mut out = EMPTY;
    let mut work = Work::default();
    for k in first..last.max(first + 1) {
        let s0 = (s_near + k as f64 * ds).max(parent.lo);
        let s1 = (s_near + (k + 1) as f64 * ds).min(parent.hi);
        if s1 <= s0 {
            continue;
        }
        let r = field_range(field, &view.cell(x, y, [s0, s1]), bound, &mut work);
        counts.nodes += 1;
        if r.straddles() {
            if out.lo.is_infinite() {
                out.lo = s0;
            }
            out.hi = s1;
        }
        if prune && r.hi < 0.0 {
            if out.lo.is_finite() {
                out.hi = s1;
            }
            break;
        }
    }
    counts.terms += work.terms;
    out
}

/// Depth-first search of a line's range `[s0, s1]` (log of the line parameter) for the first
/// surface point. `cell_of(s0, s1)` builds the cell; `point(t)` is the line at parameter t.
#[allow(clippy::too_many_arguments)]
pub fn line_search(
    field: &Field,
    bound: Bound,
    o: [f64; 3],
    d: [f64; 3],
    range: [f64; 2],
    min_cell: f64,
    any_solid_is_hit: bool,
    counts: &mut (u64, u64, u64),
) -> Option<f64> {
    let mut stack = vec![range];
    let mut work = Work::default();
    let at = |t: f64| -> [f64; 3] { std::array::from_fn(|k| o[k] + t * d[k]) };
    let mut result = None;
    // A finest cell whose bound holds 0 without a sign change (a thin shell, a graze, or a
    // loose bound at a CSG crease): the hit unless a sign change follows within one pixel footprint (2^refine cells): at grazing incidence an interval bound holds 0 up to 1/cos(angle) cells before the crossing.
    let mut candidate: Option<(f64, f64)> = None;
    let pixel_cells = ((range[1] - range[0]) / min_cell).min(64.0);
    while let Some([s0, s1]) = stack.pop() {
        if candidate.is_some_and(|(_, limit)| s0 >= limit) {
            break;
        }
        let (t0, t1) = (s0.exp(), s1.exp());
        let r = field_range(field, &line_cell(o, d, t0, t1), bound, &mut work);
        counts.0 += 1;
        if !r.straddles() {
            if any_solid_is_hit && r.hi < 0.0 {
                result = Some(0.5 * (t0 + t1));
                break;
            }
            continue;
        }
        if s1 - s0 > min_cell {
            let m = 0.5 * (s0 + s1);
            stack.push([m, s1]);
            stack.push([s0, m]);
            continue;
        }
        // A finest cell that may hold surface: bisect a sign change, else take its middle.
        let (a, b) = (t0, t1);
        let (fa, fb) = (field.eval(at(a)), field.eval(at(b)));
        counts.2 += 2;
        if (fa <= 0.0) != (fb <= 0.0) {
            result = Some(illinois(|t| field.eval(at(t)), a, b, fa, fb, &mut counts.2));
            break;
        }
        if any_solid_is_hit || fa <= 0.0 {
            // Occlusion needs no depth; an end inside the solid is a hit at once.
            result = Some(if fa <= 0.0 { a } else { 0.5 * (a + b) });
            break;
        }
        if candidate.is_none() {
            candidate = Some((0.5 * (a + b), s1 + pixel_cells * min_cell));
        }
    }
    counts.1 += work.terms;
    result.or(candidate.map(|c| c.0))
}

/// The sign change of `f` in `[a, b]` by the Illinois variant of regula falsi (superlinear, never
/// leaves the bracket), to a relative width of 1e-12.
fn illinois(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
    evals: &mut u64,
) -> f64 {
    let mut side = 0;
    for _ in 0..64 {
        if (b - a) <= 1e-12 * a.abs().max(b.abs()) {
            break;
        }
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let fc = f(c);
        *evals += 1;
        if fc == 0.0 {
            return c;
        }
        if (fc < 0.0) == (fa < 0.0) {
            a = c;
            fa = fc;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = c;
            fb = fc;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}

/// Cast every pixel ray of `view`: per pixel (row-major) the distance along its unit ray to the
/// first surface point, and the counts.
pub fn cast(field: &Field, view: &View, params: &RmlrcParams) -> (Vec<PixelHit>, CastStats) {
    let (w, h) = (view.width as usize, view.height as usize);
    let theta = view.pixel_angle();
    let prune = camera_outside(field, view, params.bound);
    let root = TileRange {
        lo: view.near.ln(),
        hi: view.far.ln(),
    };
    let mut stats = CastStats {
        nodes_per_level: vec![0; params.top_level as usize + 1],
        ..Default::default()
    };
    // Tile levels, coarse to fine; `ranges` belongs to the previous (parent) level.
    let mut ranges: Vec<TileRange> = vec![root];
    let mut parent_cols = 1usize;
    for level in (1..=params.top_level).rev() {
        let size = 1usize << level;
        let (cols, rows) = (w.div_ceil(size), h.div_ceil(size));
        let is_top = level == params.top_level;
        let ds = theta * size as f64;
        let results: Vec<(TileRange, Counts)> = (0..cols * rows)
            .into_par_iter()
            .map(|i| {
                let (tx, ty) = (i % cols, i / cols);
                let parent = if is_top {
                    ranges[0]
                } else {
                    ranges[(ty / 2) * parent_cols + tx / 2]
                };
                let x = [
                    view.screen_x((tx * size) as f64),
                    view.screen_x(((tx + 1) * size).min(w) as f64),
                ];
                let y = [
                    view.screen_y(((ty + 1) * size).min(h) as f64),
                    view.screen_y((ty * size) as f64),
                ];
                let mut c = Counts::default();
                let r = tile_pass(field, view, params.bound, x, y, parent, ds, prune, &mut c);
                (r, c)
            })
            .collect();
        let total = results.iter().fold(Counts::default(), |a, r| a + r.1);
        stats.nodes_per_level[level as usize] = total.nodes;
        stats.nodes += total.nodes;
        stats.bound_terms += total.terms;
        ranges = results.into_iter().map(|r| r.0).collect();
        parent_cols = cols;
    }
    let min_cell = theta / (1u64 << params.refine) as f64;
    let top = params.top_level;
    let pixels: Vec<(PixelHit, (u64, u64, u64))> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let r = if top == 0 {
                ranges[0]
            } else {
                ranges[(py / 2) * parent_cols + px / 2]
            };
            let mut c = (0, 0, 0);
            if r.lo > r.hi {
                return (None, c);
            }
            let (dir, len) = view.pixel_ray(px as u32, py as u32);
            // Search in view depth z along the unnormalised direction, report distance.
            let dz = dir.map(|v| v * len);
            let hit = line_search(
                field,
                params.bound,
                view.eye,
                dz,
                [r.lo, r.hi],
                min_cell,
                false,
                &mut c,
            );
            (hit.map(|z| z * len), c)
        })
        .collect();
    let mut hits = Vec::with_capacity(w * h);
    let mut pixel_nodes = 0;
    for (hit, c) in pixels {
        hits.push(hit);
        pixel_nodes += c.0;
        stats.bound_terms += c.1;
        stats.point_evals += c.2;
    }
    stats.nodes_per_level[0] = pixel_nodes;
    stats.nodes += pixel_nodes;
    (hits, stats)
}

/// True when the segment from `p` toward `dir` (unit) meets the solid within `far`, by the same
/// bounded subdivision (any cell that is wholly solid proves the occlusion at once).
pub fn occluded(
    field: &Field,
    bound: Bound,
    p: [f64; 3],
    dir: [f64; 3],
    start: f64,
    far: f64,
    min_cell: f64,
) -> bool {
    let mut c = (0, 0, 0);
    line_search(
        field,
        bound,
        p,
        dir,
        [start.ln(), far.ln()],
        min_cell,
        true,
        &mut c,
    )
    .is_some()
}
