//! The f32 twin of the kernel's passes (`shaders/freeform.wgsl`): one tile pass per level,
//! then the pixel pass — the algorithm of [`super::rmlrc`] in f32 with the widened bound of
//! [`super::twin`], and the eye at the origin.

use super::twin::{exp32, field_range32, GpuField, GpuQuad, View32};
use super::twin_texture;

/// A tile's log-depth range; empty when `lo > hi`.
pub type Range32 = [f32; 2];

/// The empty range.
pub const EMPTY32: Range32 = [f32::INFINITY, f32::NEG_INFINITY];

/// One tile of one level: walk the parent's range at cell size `ds`.
#[allow(clippy::too_many_arguments)]
pub fn tile32(
    f: &GpuField,
    v: &View32,
    x: [f32; 2],
    y: [f32; 2],
    parent: Range32,
    ds: f32,
    prune: bool,
) -> Range32 {
    if parent[0] > parent[1] {
        return EMPTY32;
    }
    let first = ((parent[0] - v.near_ln) / ds).floor() as i32;
    let last = ((parent[1] - v.near_ln) / ds).ceil() as i32;
    let mut out = EMPTY32;
    let mut k = first;
    while k < last.max(first + 1) {
        let s0 = (v.near_ln + k as f32 * ds).max(parent[0]);
        let s1 = (v.near_ln + (k + 1) as f32 * ds).min(parent[1]);
        k += 1;
        if s1 <= s0 {
            continue;
        }
        let (lo, hi) = field_range32(f, &v.cell(x, y, [s0, s1]));
        if lo <= 0.0 && hi >= 0.0 {
            if out[0] == f32::INFINITY {
                out[0] = s0;
            }
            out[1] = s1;
        }
        if prune && hi < 0.0 {
            if out[0] != f32::INFINITY {
                out[1] = s1;
            }
            break;
        }
    }
    out
}

fn quad_eval(q: &GpuQuad, p: [f32; 3]) -> f32 {
    let [r0, r1, r2] = q.v;
    let (x, y, z) = (p[0], p[1], p[2]);
    r0[0] * x * x
        + r0[3] * y * y
        + r1[1] * z * z
        + 2.0 * (r0[1] * x * y + r0[2] * x * z + r1[0] * y * z)
        + 2.0 * (r1[2] * x + r1[3] * y + r2[0] * z)
        + r2[1]
}

fn quad_grad(q: &GpuQuad, p: [f32; 3]) -> [f32; 3] {
    let [r0, r1, r2] = q.v;
    let (x, y, z) = (p[0], p[1], p[2]);
    [
        2.0 * (r0[0] * x + r0[1] * y + r0[2] * z + r1[2]),
        2.0 * (r0[1] * x + r0[3] * y + r1[0] * z + r1[3]),
        2.0 * (r0[2] * x + r1[0] * y + r1[1] * z + r2[0]),
    ]
}

fn leaf_value(f: &GpuField, i: usize, p: [f32; 3]) -> f32 {
    let leaf = &f.leaves[i];
    if leaf.range[2] != 0 {
        return twin_texture::value32(&f.textures, leaf.range[3] as usize, p);
    }
    let mut v = quad_eval(&leaf.base, p);
    let (start, count) = (leaf.range[0] as usize, leaf.range[1] as usize);
    for b in &f.bumps[start..start + count] {
        let q = quad_eval(&b.q, p);
        if q > 0.0 {
            v += b.lo_weight[3] * q * q * q;
        }
    }
    v
}

/// The field at `p` (eye-relative), the active leaf and its CSG sign.
pub fn eval32(f: &GpuField, p: [f32; 3]) -> (f32, usize, f32) {
    let mut stack = [(0.0f32, 0usize, 1.0f32); super::twin::MAX_STACK];
    for &op in &f.ops {
        let (kind, slot, arg) = (op >> 24, ((op >> 16) & 0xff) as usize, op & 0xffff);
        match kind {
            0 => stack[slot] = (leaf_value(f, arg as usize, p), arg as usize, 1.0),
            3 => {
                stack[slot].0 = -stack[slot].0;
                stack[slot].2 = -stack[slot].2;
            }
            _ => {
                let (x, y) = (stack[slot], stack[slot + 1]);
                stack[slot] = if (kind == 1 && y.0 < x.0) || (kind == 2 && y.0 > x.0) {
                    y
                } else {
                    x
                };
            }
        }
    }
    stack[0]
}

/// The unit normal at `p` from the active leaf's gradient.
pub fn normal32(f: &GpuField, p: [f32; 3]) -> [f32; 3] {
    let (_, i, sign) = eval32(f, p);
    let leaf = &f.leaves[i];
    let mut g = quad_grad(&leaf.base, p);
    if leaf.range[2] != 0 {
        g = twin_texture::gradient32(&f.textures, leaf.range[3] as usize, p);
    }
    let (start, count) = (leaf.range[0] as usize, leaf.range[1] as usize);
    for b in &f.bumps[start..start + count] {
        let q = quad_eval(&b.q, p);
        if q > 0.0 {
            let k = 3.0 * b.lo_weight[3] * q * q;
            let gq = quad_grad(&b.q, p);
            (0..3).for_each(|j| g[j] += k * gq[j]);
        }
    }
    let len = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if len > 0.0 {
        g.map(|v| sign * v / len)
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// The pixel pass: the first surface point along `o + z·d` (z on a log scale within `range`),
/// as the kernel's `line_search`; `any_solid` for shadow rays.
pub fn line32(
    f: &GpuField,
    o: [f32; 3],
    d: [f32; 3],
    range: Range32,
    min_cell: f32,
    any_solid: bool,
) -> Option<f32> {
    line32_steps(f, o, d, range, min_cell, any_solid).0
}

/// [`line32`] and the number of steps it took (nodes bounded), which with the refinement's
/// evaluations sets the kernel's loop iterations for the pixel.
pub fn line32_steps(
    f: &GpuField,
    o: [f32; 3],
    d: [f32; 3],
    range: Range32,
    min_cell: f32,
    any_solid: bool,
) -> (Option<f32>, u32) {
    let mut st = Search32::START;
    let mut steps = 0;
    while !st.done {
        st = line32_resume(f, o, d, range, min_cell, any_solid, st, 1);
        steps += 1;
    }
    ((st.t >= 0.0).then_some(st.t), steps)
}

/// Where a pixel's search stands between rounds (the kernel's `Search`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search32 {
    /// Depth and index of the next node of the binary subdivision of the range.
    pub d: u32,
    pub i: u32,
    /// A cell where the field straddles zero without a sign change at its ends (−1: none), and
    /// how far past it the search still looks for a sign change.
    pub candidate: f32,
    pub limit: f32,
    pub done: bool,
    /// The result once done: t along `d`, or −1.
    pub t: f32,
}

impl Search32 {
    pub const START: Search32 = Search32 {
        d: 0,
        i: 0,
        candidate: -1.0,
        limit: f32::INFINITY,
        done: false,
        t: -1.0,
    };
}

/// Deepest node of the search (indices stay exact in f32).
pub const MAX_DEPTH: u32 = 24;
/// Illinois steps refining a sign change.
pub const REFINE_STEPS: usize = 24;

/// Bounds of node (d, i) of the subdivision of `range`, as the kernel's `node_bounds`.
pub fn node_bounds(range: Range32, d: u32, i: u32) -> Range32 {
    let len = range[1] - range[0];
    let scale = f32::from_bits((127 - d) << 23); // 2^-d, exact
    [
        range[0] + len * (i as f32 * scale),
        range[0] + len * ((i + 1) as f32 * scale),
    ]
}

/// Up to `steps` steps of the stackless depth-first search, from `st` (the kernel's
/// `line_search`): a step bounds one node and culls it, splits it or tests its end points; a
/// sign change is refined at once.
#[allow(clippy::too_many_arguments)]
pub fn line32_resume(
    f: &GpuField,
    o: [f32; 3],
    d: [f32; 3],
    range: Range32,
    min_cell: f32,
    any_solid: bool,
    mut st: Search32,
    steps: u32,
) -> Search32 {
    let at = |t: f32| -> [f32; 3] { std::array::from_fn(|k| o[k] + t * d[k]) };
    let pixel_cells = ((range[1] - range[0]) / min_cell).min(64.0);
    let mut bracket = None;
    for _ in 0..steps {
        let [s0, s1] = node_bounds(range, st.d, st.i);
        if st.candidate >= 0.0 && s0 >= st.limit {
            st.done = true;
            break;
        }
        let (t0, t1) = (exp32(s0), exp32(s1));
        let (tc, tr) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
        let mut v5 = [[0.0f32; 3]; 5];
        v5[0] = d.map(|x| tr * x);
        let cell = super::twin::Cell32::new(at(tc), v5);
        let (lo, hi) = field_range32(f, &cell);
        let mut next = true;
        if !(lo <= 0.0 && hi >= 0.0) {
            if any_solid && hi < 0.0 {
                return Search32 {
                    t: tc,
                    done: true,
                    ..st
                };
            }
        } else if s1 - s0 > min_cell && st.d < MAX_DEPTH {
            st.d += 1;
            st.i *= 2;
            next = false;
        } else {
            let (fa, fb) = (eval32(f, at(t0)).0, eval32(f, at(t1)).0);
            if (fa <= 0.0) != (fb <= 0.0) {
                bracket = Some((t0, t1, fa, fb));
                break;
            }
            if any_solid || fa <= 0.0 {
                let t = if fa <= 0.0 { t0 } else { tc };
                return Search32 {
                    t,
                    done: true,
                    ..st
                };
            }
            if st.candidate < 0.0 {
                st.candidate = tc;
                st.limit = s1 + pixel_cells * min_cell;
            }
        }
        if next {
            // Up past every level where this node is a right child, then its right sibling.
            let up = (!st.i).trailing_zeros();
            if up >= st.d {
                st.done = true;
                break;
            }
            st.d -= up;
            st.i = (st.i >> up) + 1;
        }
    }
    let Some((mut a, mut b, mut fa, mut fb)) = bracket else {
        if st.done {
            st.t = st.candidate;
        }
        return st;
    };
    // Illinois regula falsi, fixed count (the kernel's loop).
    let mut side = 0;
    for _ in 0..REFINE_STEPS {
        let mut c = (a * fb - b * fa) / (fb - fa);
        if !(c > a && c < b) {
            c = 0.5 * (a + b);
        }
        let fc = eval32(f, at(c)).0;
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
    Search32 {
        t: 0.5 * (a + b),
        done: true,
        ..st
    }
}

/// The tile passes as the GPU runs them: per level (coarse to fine) the depth range of every
/// tile, row-major. The last entry is what the pixel pass reads.
pub fn levels32(f: &GpuField, v: &View32, top_level: u32, prune: bool) -> Vec<Vec<Range32>> {
    let (w, h) = (v.width as usize, v.height as usize);
    let mut levels: Vec<Vec<Range32>> = Vec::new();
    let mut parent_cols = 1usize;
    for level in (1..=top_level).rev() {
        let size = 1usize << level;
        let (cols, rows) = (w.div_ceil(size), h.div_ceil(size));
        let ds = v.theta * size as f32;
        let ranges = levels.last();
        let next: Vec<Range32> = (0..cols * rows)
            .map(|i| {
                let (tx, ty) = (i % cols, i / cols);
                let parent = match ranges {
                    None => [v.near_ln, v.far_ln],
                    Some(r) => r[(ty / 2) * parent_cols + tx / 2],
                };
                let x = [
                    v.screen_x((tx * size) as f32),
                    v.screen_x(((tx + 1) * size).min(w) as f32),
                ];
                let y = [
                    v.screen_y(((ty + 1) * size).min(h) as f32),
                    v.screen_y((ty * size) as f32),
                ];
                tile32(f, v, x, y, parent, ds, prune)
            })
            .collect();
        levels.push(next);
        parent_cols = cols;
    }
    levels
}

/// The whole cast as the GPU runs it: per pixel (row-major) the distance along the unit ray and
/// the unit normal, or `None`.
pub fn cast32(
    f: &GpuField,
    v: &View32,
    top_level: u32,
    refine: u32,
    prune: bool,
) -> Vec<Option<(f32, [f32; 3])>> {
    let (w, h) = (v.width as usize, v.height as usize);
    let levels = levels32(f, v, top_level, prune);
    let parent_cols = if top_level == 0 { 1 } else { w.div_ceil(2) };
    let min_cell = v.theta / (1u32 << refine) as f32;
    (0..w * h)
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let r = match levels.last() {
                None => [v.near_ln, v.far_ln],
                Some(r) => r[(py / 2) * parent_cols + px / 2],
            };
            if r[0] > r[1] {
                return None;
            }
            let d = pixel_dir32(v, px as u32, py as u32);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            let z = line32(f, [0.0; 3], d, r, min_cell, false)?;
            // The normal pass starts again from the stored distance, as the kernel's does.
            let t = z * len;
            let p = d.map(|c| c * (t / len));
            let mut n = normal32(f, p);
            if n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0.0 {
                n = n.map(|c| -c);
            }
            Some((t, n))
        })
        .collect()
}

/// The kernel's `shadow` pass for one hit pixel: from the hit at distance `t` along the unit
/// ray (`d` the pixel's ray, not unit) with normal `n`, lifted off the surface by half a
/// pixel's footprint, is the sun toward `l` blocked? Pixels facing away from the sun are not
/// searched (false).
#[allow(clippy::too_many_arguments)]
pub fn shadow32(
    f: &GpuField,
    v: &View32,
    d: [f32; 3],
    t: f32,
    n: [f32; 3],
    l: [f32; 3],
    scale: f32,
    refine: u32,
) -> bool {
    if n[0] * l[0] + n[1] * l[1] + n[2] * l[2] <= 0.0 {
        return false;
    }
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let p = d.map(|c| c * (t / len));
    // Half a pixel's footprint (the kernel's bias; see there).
    let eps = (1e-5 * t.max(scale * 1e-3)).max(0.5 * v.theta * t);
    let o: [f32; 3] = std::array::from_fn(|k| p[k] + eps * n[k]);
    let far = exp32(v.far_ln).max(t) * 2.0;
    let min_cell = v.theta / (1u32 << refine) as f32;
    line32(f, o, l, [eps.ln(), far.ln()], min_cell, true).is_some()
}

/// The ray through pixel (px, py) as the kernel's `pixel_dir` builds it (not unit).
pub fn pixel_dir32(v: &View32, px: u32, py: u32) -> [f32; 3] {
    let (x, y) = (v.screen_x(px as f32 + 0.5), v.screen_y(py as f32 + 0.5));
    std::array::from_fn(|k| v.forward[k] + x * v.right[k] + y * v.up[k])
}
