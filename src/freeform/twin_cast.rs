//! The f32 twin of the kernel's passes (`shaders/freeform.wgsl`): one tile pass per level,
//! then the pixel pass — the algorithm of [`super::rmlrc`] in f32 with the widened bound of
//! [`super::twin`], and the eye at the origin.

use super::twin::{exp32, field_range32, GpuField, GpuQuad, View32, MAX_DFS};

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
    let mut stack = [[0.0f32; 2]; MAX_DFS];
    let mut sp = 1;
    stack[0] = range;
    let at = |t: f32| -> [f32; 3] { std::array::from_fn(|k| o[k] + t * d[k]) };
    let pixel_cells = ((range[1] - range[0]) / min_cell).min(64.0);
    let mut candidate = -1.0f32;
    let mut limit = f32::INFINITY;
    while sp > 0 {
        sp -= 1;
        let [s0, s1] = stack[sp];
        if candidate >= 0.0 && s0 >= limit {
            break;
        }
        let (t0, t1) = (exp32(s0), exp32(s1));
        let (tc, tr) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
        let mut v5 = [[0.0f32; 3]; 5];
        v5[0] = d.map(|x| tr * x);
        let cell = super::twin::Cell32::new(at(tc), v5);
        let (lo, hi) = field_range32(f, &cell);
        if !(lo <= 0.0 && hi >= 0.0) {
            if any_solid && hi < 0.0 {
                return Some(tc);
            }
            continue;
        }
        if s1 - s0 > min_cell && sp + 2 <= MAX_DFS {
            let m = 0.5 * (s0 + s1);
            stack[sp] = [m, s1];
            stack[sp + 1] = [s0, m];
            sp += 2;
            continue;
        }
        let (mut a, mut b) = (t0, t1);
        let (mut fa, mut fb) = (eval32(f, at(a)).0, eval32(f, at(b)).0);
        if (fa <= 0.0) != (fb <= 0.0) {
            // Illinois regula falsi, fixed count (the kernel's loop).
            let mut side = 0;
            for _ in 0..24 {
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
            return Some(0.5 * (a + b));
        }
        if any_solid || fa <= 0.0 {
            return Some(if fa <= 0.0 { a } else { tc });
        }
        if candidate < 0.0 {
            candidate = tc;
            limit = s1 + pixel_cells * min_cell;
        }
    }
    (candidate >= 0.0).then_some(candidate)
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
    let mut ranges: Vec<Range32> = vec![[v.near_ln, v.far_ln]];
    let mut parent_cols = 1usize;
    for level in (1..=top_level).rev() {
        let size = 1usize << level;
        let (cols, rows) = (w.div_ceil(size), h.div_ceil(size));
        let ds = v.theta * size as f32;
        let next: Vec<Range32> = (0..cols * rows)
            .map(|i| {
                let (tx, ty) = (i % cols, i / cols);
                let parent = if level == top_level {
                    ranges[0]
                } else {
                    ranges[(ty / 2) * parent_cols + tx / 2]
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
        ranges = next;
        parent_cols = cols;
    }
    let min_cell = v.theta / (1u32 << refine) as f32;
    (0..w * h)
        .map(|i| {
            let (px, py) = (i % w, i / w);
            let r = if top_level == 0 {
                ranges[0]
            } else {
                ranges[(py / 2) * parent_cols + px / 2]
            };
            if r[0] > r[1] {
                return None;
            }
            let (x, y) = (v.screen_x(px as f32 + 0.5), v.screen_y(py as f32 + 0.5));
            let d: [f32; 3] = std::array::from_fn(|k| v.forward[k] + x * v.right[k] + y * v.up[k]);
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
