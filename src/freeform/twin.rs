//! The f32 twin of `shaders/freeform.wgsl`: the same multilevel cast, operation for operation,
//! with the affine bound evaluated in f32 and **widened** so that it contains the f64 bound of
//! [`super::bounds`] (WGSL has no directed rounding).
//!
//! Widening, and why it is enough (u = 2⁻²⁴, the f32 unit roundoff):
//! - the scene is uploaded relative to the eye (quadrics re-centred in f64, then rounded), so
//!   cell coordinates are distances from the eye and never cancel catastrophically;
//! - a cell is `c + Σ vₖεₖ` plus three axis-aligned rounding symbols of radius
//!   `KC·(|c| + Σ|vₖ|)` per axis (KC = 2⁻²⁰ ≫ the few roundings of building c and vₖ), so the
//!   f32 cell contains the cell the f64 caster would build from the same camera;
//! - a quadric over the cell: every computed coefficient is a sum of at most ~40 products of
//!   coefficients and coordinates, each bounded by the quadric's magnitude
//!   `m = Σ|aᵢⱼ|XᵢXⱼ + 2Σ|bᵢ|Xᵢ + |c|` (X = |c| + Σ|vₖ| per axis), so rounding (and the f64→f32
//!   rounding of the coefficients, ≤ u relative each) is below `KQ·m` with KQ = 2⁻¹⁶ ≥ 40·8·u;
//! - every other operation (the cube's Chebyshev line, the weighted sums, min/max hulls, the
//!   final range) adds `KR·(|x₀| + Σ|gₖ| + e)` with KR = 2⁻²⁰ ≥ 8·u per operation group, and the
//!   Chebyshev error δ is recomputed from the f32 line itself at the three points where a
//!   convex function's deviation from a line can peak.
//!
//! `tests/gpu/freeform_twin.rs` checks containment on random cells (proptest) and that the GPU
//! (lavapipe) returns the twin's hit mask, depths and normals.

use super::field::{Field, Op, Quad};
use super::twin_texture;
use super::view::View;
use crate::error::{Error, Result};

/// Noise symbols of an f32 cell: the five of the view pyramid and three rounding symbols.
pub const SYMBOLS32: usize = 8;
/// The CSG stack depth the kernel supports.
pub const MAX_STACK: usize = 8;

const KC: f32 = 9.536_743e-7; // 2^-20
const KQ: f32 = 1.525_878_9e-5; // 2^-16
const KR: f32 = 9.536_743e-7; // 2^-20
const TINY: f32 = 1e-30;
/// The most shape-texture words uploaded with the program (120 MiB: wgpu's default storage
/// binding size is 128 MiB).
const MAX_TEXTURE_WORDS: usize = 30 << 20;

/// A quadric for the GPU: `a00 a01 a02 a11 | a12 a22 b0 b1 | b2 c 0 0`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuQuad {
    pub v: [[f32; 4]; 3],
}

/// A perturbation: its quadric, support box (lo, weight), (hi, has_box).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuBump {
    pub q: GpuQuad,
    pub lo_weight: [f32; 4],
    pub hi_flag: [f32; 4],
}

/// A surface: base quadric, bump range (start, count), material (rgb, specular).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuLeaf {
    pub base: GpuQuad,
    pub range: [u32; 4],
    pub material: [f32; 4],
}

/// The field as the kernel reads it, relative to the eye.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuField {
    pub leaves: Vec<GpuLeaf>,
    pub bumps: Vec<GpuBump>,
    /// `kind << 24 | slot << 16 | leaf`: kind 0 leaf into slot, 1 min / 2 max of slots
    /// (slot, slot + 1) into slot, 3 negate slot.
    pub ops: Vec<u32>,
    /// Shape-texture records (`twin_texture`), uploaded after `ops` in the kernel's `ops`
    /// buffer; a textured leaf has `range = [0, 0, 1, record offset]`.
    pub textures: Vec<u32>,
}

fn recentre(q: &Quad, eye: [f64; 3]) -> GpuQuad {
    // Q(p + e) = pᵀAp + 2(Ae + b)ᵀp + Q(e).
    let a = &q.a;
    let b: [f64; 3] =
        std::array::from_fn(|i| a[i][0] * eye[0] + a[i][1] * eye[1] + a[i][2] * eye[2] + q.b[i]);
    let c = q.eval(eye);
    let f = |x: f64| x as f32;
    GpuQuad {
        v: [
            [f(a[0][0]), f(a[0][1]), f(a[0][2]), f(a[1][1])],
            [f(a[1][2]), f(a[2][2]), f(b[0]), f(b[1])],
            [f(b[2]), f(c), 0.0, 0.0],
        ],
    }
}

impl GpuField {
    /// Loop iterations of one evaluation of the field by the kernel: one per operation and one
    /// per perturbation of every surface it evaluates (nothing else in `field_range` or
    /// `eval_point` loops). Lavapipe bounds the iterations of an invocation; the caster plans its
    /// passes by this.
    pub fn evaluation_loops(&self) -> u32 {
        let bumps: u32 = self
            .ops
            .iter()
            .filter(|op| *op >> 24 == 0)
            .map(|op| self.leaves[(op & 0xffff) as usize].range[1])
            .sum();
        self.ops.len() as u32 + bumps
    }

    /// The field relative to `eye`, refused when its CSG stack is deeper than the kernel's.
    pub fn upload(field: &Field, eye: [f64; 3]) -> Result<GpuField> {
        let mut depth = 0usize;
        let mut deepest = 0usize;
        // Min(n)/Max(n) become n − 1 binary ops, and every op names its stack slot (computed
        // here, once): the kernel keeps no stack pointer (a loop-carried stack pointer came out
        // wrong on lavapipe). Word: kind << 24 | slot << 16 | leaf index.
        let mut ops = Vec::with_capacity(field.ops.len() * 2);
        for op in &field.ops {
            match *op {
                Op::Leaf(i) => {
                    if i > 0xffff {
                        return Err(Error::knob("the GPU caster takes at most 65,536 surfaces"));
                    }
                    ops.push((depth as u32) << 16 | i);
                    depth += 1;
                    deepest = deepest.max(depth);
                }
                Op::Min(n) | Op::Max(n) => {
                    let kind = if matches!(op, Op::Min(_)) { 1 } else { 2 };
                    for _ in 1..n {
                        depth -= 1;
                        ops.push(kind << 24 | ((depth as u32 - 1) << 16));
                    }
                }
                Op::Neg => ops.push(3 << 24 | ((depth as u32 - 1) << 16)),
            }
        }
        if deepest > MAX_STACK {
            return Err(Error::knob(format!(
                "the GPU caster evaluates CSG trees with at most {MAX_STACK} pending operands; this scene needs {deepest} (nest fewer unions side by side)"
            )));
        }
        let rel = |p: [f64; 3]| -> [f32; 3] { std::array::from_fn(|k| (p[k] - eye[k]) as f32) };
        let mut textures = Vec::new();
        let records: Vec<u32> = field
            .textures
            .iter()
            .map(|t| twin_texture::append(t, eye, &mut textures))
            .collect();
        if textures.len() > MAX_TEXTURE_WORDS {
            return Err(Error::knob(format!(
                "the shape textures take {} MiB on the GPU, more than its {} MiB: raise their lod",
                (textures.len() * 4) >> 20,
                (MAX_TEXTURE_WORDS * 4) >> 20
            )));
        }
        Ok(GpuField {
            leaves: field
                .leaves
                .iter()
                .map(|l| GpuLeaf {
                    base: recentre(&l.base, eye),
                    range: match l.texture {
                        Some(t) => [0, 0, 1, records[t]],
                        None => [l.bumps.start as u32, l.bumps.len() as u32, 0, 0],
                    },
                    material: [
                        l.color[0] as f32,
                        l.color[1] as f32,
                        l.color[2] as f32,
                        l.specular as f32,
                    ],
                })
                .collect(),
            bumps: field
                .bumps
                .iter()
                .map(|b| {
                    let (lo, hi, flag) = match b.support {
                        // Rounded outward by a relative hair: the box only ever grows.
                        Some((lo, hi)) => {
                            let (l, h) = (rel(lo), rel(hi));
                            (
                                l.map(|v| v - v.abs() * KC - TINY),
                                h.map(|v| v + v.abs() * KC + TINY),
                                1.0,
                            )
                        }
                        None => ([0.0; 3], [0.0; 3], 0.0),
                    };
                    GpuBump {
                        q: recentre(&b.q, eye),
                        lo_weight: [lo[0], lo[1], lo[2], b.weight as f32],
                        hi_flag: [hi[0], hi[1], hi[2], flag],
                    }
                })
                .collect(),
            ops,
            textures,
        })
    }
}

/// An f32 cell: centre, eight generators (five of the pyramid, three rounding symbols).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell32 {
    pub c: [f32; 3],
    pub v: [[f32; 3]; SYMBOLS32],
}

impl Cell32 {
    /// A cell from its centre and five pyramid generators, with its rounding symbols.
    pub fn new(c: [f32; 3], v5: [[f32; 3]; 5]) -> Cell32 {
        let mut v = [[0.0; 3]; SYMBOLS32];
        v[..5].copy_from_slice(&v5);
        for k in 0..3 {
            let r = v5.iter().fold(c[k].abs(), |s, g| s + g[k].abs());
            v[5 + k][k] = KC * r + TINY;
        }
        Cell32 { c, v }
    }

    fn extent(&self) -> [f32; 3] {
        std::array::from_fn(|k| sum8_abs(self.component(k)))
    }

    /// Component `k` of the eight generators.
    fn component(&self, k: usize) -> [f32; SYMBOLS32] {
        self.v.map(|g| g[k])
    }
}

/// `Σ|vₖ|` in the kernel's order: `sum4(abs(v0..3)) + sum4(abs(v4..7))`, pairwise in each.
fn sum8_abs(v: [f32; SYMBOLS32]) -> f32 {
    sum8(v.map(f32::abs))
}

/// `Σvₖ` in the kernel's order.
fn sum8(v: [f32; SYMBOLS32]) -> f32 {
    ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]))
}

/// An f32 affine form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aff32 {
    pub x0: f32,
    pub g: [f32; SYMBOLS32],
    pub e: f32,
}

impl Aff32 {
    fn magnitude(&self) -> f32 {
        (self.x0.abs() + self.e) + sum8_abs(self.g)
    }
    fn widen(&mut self) {
        self.e += KR * self.magnitude() + TINY;
    }
    /// The widened interval of the form.
    pub fn range(&self) -> (f32, f32) {
        let r = self.e + sum8_abs(self.g);
        let r = r + KR * (r + self.x0.abs()) + TINY;
        (self.x0 - r, self.x0 + r)
    }
    fn constant(x: f32) -> Aff32 {
        Aff32 {
            x0: x,
            g: [0.0; SYMBOLS32],
            e: 0.0,
        }
    }
    fn hull(lo: f32, hi: f32) -> Aff32 {
        let mut a = Aff32 {
            x0: 0.5 * (lo + hi),
            g: [0.0; SYMBOLS32],
            e: 0.5 * (hi - lo),
        };
        a.widen();
        a
    }
}

fn unpack(q: &GpuQuad) -> ([[f32; 3]; 3], [f32; 3], f32) {
    let [r0, r1, r2] = q.v;
    (
        [
            [r0[0], r0[1], r0[2]],
            [r0[1], r0[3], r1[0]],
            [r0[2], r1[0], r1[1]],
        ],
        [r1[2], r1[3], r2[0]],
        r2[1],
    )
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mat_vec(a: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [dot3(a[0], v), dot3(a[1], v), dot3(a[2], v)]
}

/// A quadric over an f32 cell, widened, in the kernel's order of operations.
pub fn quad_aff32(q: &GpuQuad, cell: &Cell32) -> Aff32 {
    let (a, b, c0) = unpack(q);
    let ac = mat_vec(&a, cell.c);
    let gc: [f32; 3] = std::array::from_fn(|i| ac[i] + b[i]);
    let (vx, vy, vz) = (cell.component(0), cell.component(1), cell.component(2));
    let g = std::array::from_fn(|k| 2.0 * (gc[0] * vx[k] + gc[1] * vy[k] + gc[2] * vz[k]));
    // A·v_k for the eight generators, by component.
    let av = |i: usize| -> [f32; SYMBOLS32] {
        std::array::from_fn(|k| a[i][0] * vx[k] + a[i][1] * vy[k] + a[i][2] * vz[k])
    };
    let (ax, ay, az) = (av(0), av(1), av(2));
    let d: [f32; SYMBOLS32] =
        std::array::from_fn(|k| vx[k] * ax[k] + vy[k] * ay[k] + vz[k] * az[k]);
    let x0 = (dot3(ac, cell.c) + 2.0 * dot3(b, cell.c) + c0) + 0.5 * sum8(d);
    let mut total = 0.0f32;
    for j in 0..SYMBOLS32 {
        let row = std::array::from_fn(|k| vx[j] * ax[k] + vy[j] * ay[k] + vz[j] * az[k]);
        total += sum8_abs(row);
    }
    // ½Σ|M_jj| + 2Σ_{j<k}|M_jk| = Σ_jk|M_jk| − ½Σ|M_jj|.
    let mut e = total - 0.5 * sum8_abs(d);
    let ext = cell.extent();
    let x: [f32; 3] = std::array::from_fn(|k| cell.c[k].abs() + ext[k]);
    let ax3: [f32; 3] =
        std::array::from_fn(|i| a[i][0].abs() * x[0] + a[i][1].abs() * x[1] + a[i][2].abs() * x[2]);
    let m = c0.abs()
        + 2.0 * (b[0].abs() * x[0] + b[1].abs() * x[1] + b[2].abs() * x[2])
        + (x[0] * ax3[0] + x[1] * ax3[1] + x[2] * ax3[2]);
    e += KQ * m + TINY;
    Aff32 { x0, g, e }
}

fn cube0(t: f32) -> f32 {
    let t = t.max(0.0);
    t * t * t
}

/// `max(x, 0)³` by its Chebyshev line, with the deviation measured from the f32 line itself.
pub fn relu_cube32(x: &Aff32) -> Aff32 {
    let (lo, hi) = x.range();
    if hi <= 0.0 {
        return Aff32::constant(0.0);
    }
    let (flo, fhi) = (cube0(lo), cube0(hi));
    let alpha = if hi > lo {
        (fhi - flo) / (hi - lo)
    } else {
        0.0
    };
    let u = (alpha / 3.0).sqrt().clamp(lo.max(0.0), hi);
    let zeta = 0.5 * ((flo + alpha * (u - lo)) + cube0(u)) - alpha * u;
    let dev = |t: f32| (cube0(t) - (alpha * t + zeta)).abs();
    let delta = dev(lo).max(dev(hi)).max(dev(u));
    let mut out = Aff32 {
        x0: alpha * x.x0 + zeta,
        g: x.g.map(|g| alpha * g),
        e: alpha * x.e + delta + KR * (fhi + alpha * (lo.abs().max(hi.abs())) + zeta.abs()),
    };
    out.widen();
    out
}

fn skipped(b: &GpuBump, lo: [f32; 3], hi: [f32; 3]) -> bool {
    b.hi_flag[3] != 0.0 && (0..3).any(|k| b.hi_flag[k] < lo[k] || b.lo_weight[k] > hi[k])
}

/// The widened range of the field over an f32 cell (the kernel's `field_range`).
pub fn field_range32(f: &GpuField, cell: &Cell32) -> (f32, f32) {
    let ext = cell.extent();
    let lo: [f32; 3] = std::array::from_fn(|k| cell.c[k] - ext[k]);
    let hi: [f32; 3] = std::array::from_fn(|k| cell.c[k] + ext[k]);
    let mut stack = [Aff32::constant(0.0); MAX_STACK];
    for &op in &f.ops {
        let (kind, slot, arg) = (op >> 24, ((op >> 16) & 0xff) as usize, op & 0xffff);
        match kind {
            0 => {
                let leaf = &f.leaves[arg as usize];
                if leaf.range[2] != 0 {
                    let (l, h) = twin_texture::range32(&f.textures, leaf.range[3] as usize, lo, hi);
                    stack[slot] = Aff32::hull(l, h);
                    continue;
                }
                let mut r = quad_aff32(&leaf.base, cell);
                let (start, count) = (leaf.range[0] as usize, leaf.range[1] as usize);
                for b in &f.bumps[start..start + count] {
                    if skipped(b, lo, hi) {
                        continue;
                    }
                    let q = quad_aff32(&b.q, cell);
                    if q.range().1 > 0.0 {
                        let c = relu_cube32(&q);
                        let w = b.lo_weight[3];
                        r.x0 += w * c.x0;
                        for k in 0..SYMBOLS32 {
                            r.g[k] += w * c.g[k];
                        }
                        r.e += w.abs() * c.e;
                        r.widen();
                    }
                }
                stack[slot] = r;
            }
            3 => {
                let t = &mut stack[slot];
                t.x0 = -t.x0;
                t.g = t.g.map(|g| -g);
            }
            _ => {
                // A binary min or max of the two top values.
                let (x, y) = (stack[slot], stack[slot + 1]);
                let (xl, xh) = x.range();
                let (yl, yh) = y.range();
                stack[slot] = if kind == 1 {
                    if xh <= yl {
                        x
                    } else if yh <= xl {
                        y
                    } else {
                        Aff32::hull(xl.min(yl), xh.min(yh))
                    }
                } else if xl >= yh {
                    x
                } else if yl >= xh {
                    y
                } else {
                    Aff32::hull(xl.max(yl), xh.max(yh))
                };
            }
        }
    }
    stack[0].range()
}

/// `e^x` from additions and multiplications only (as the kernel computes it, so that the twin
/// and the GPU split depth at the same points): 2^(x·log₂e) = 2ⁿ·2^f, 2^f by a degree-7 Taylor
/// polynomial on f ∈ [−0.5, 0.5] (relative error < 2e-8).
pub fn exp32(x: f32) -> f32 {
    let y = x * std::f32::consts::LOG2_E;
    let n = (y + 0.5).floor();
    let f = (y - n) * std::f32::consts::LN_2;
    let p = 1.0
        + f * (1.0
            + f * (0.5
                + f * (1.0 / 6.0
                    + f * (1.0 / 24.0
                        + f * (1.0 / 120.0 + f * (1.0 / 720.0 + f * (1.0 / 5040.0)))))));
    p * 2f32.powi(n as i32)
}

/// The f32 view the kernel receives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View32 {
    pub forward: [f32; 3],
    pub right: [f32; 3],
    pub up: [f32; 3],
    pub tan_x: f32,
    pub tan_y: f32,
    pub width: u32,
    pub height: u32,
    pub near_ln: f32,
    pub far_ln: f32,
    pub theta: f32,
}

impl View32 {
    pub fn of(v: &View) -> View32 {
        let f = |a: [f64; 3]| a.map(|x| x as f32);
        View32 {
            forward: f(v.forward),
            right: f(v.right),
            up: f(v.up),
            tan_x: v.tan_x as f32,
            tan_y: v.tan_y as f32,
            width: v.width,
            height: v.height,
            near_ln: v.near.ln() as f32,
            far_ln: v.far.ln() as f32,
            theta: v.pixel_angle() as f32,
        }
    }

    pub fn screen_x(&self, ex: f32) -> f32 {
        (ex / self.width as f32 * 2.0 - 1.0) * self.tan_x
    }

    pub fn screen_y(&self, ey: f32) -> f32 {
        (1.0 - ey / self.height as f32 * 2.0) * self.tan_y
    }

    /// The cell over screen `x`, `y` and log depth `s` (eye at the origin).
    pub fn cell(&self, x: [f32; 2], y: [f32; 2], s: [f32; 2]) -> Cell32 {
        let (z0, z1) = (exp32(s[0]), exp32(s[1]));
        let (zc, zr) = (0.5 * (z0 + z1), 0.5 * (z1 - z0));
        let (xc, xr) = (0.5 * (x[0] + x[1]), 0.5 * (x[1] - x[0]));
        let (yc, yr) = (0.5 * (y[0] + y[1]), 0.5 * (y[1] - y[0]));
        let dc: [f32; 3] =
            std::array::from_fn(|k| self.forward[k] + xc * self.right[k] + yc * self.up[k]);
        Cell32::new(
            dc.map(|v| zc * v),
            [
                dc.map(|v| zr * v),
                self.right.map(|v| zc * xr * v),
                self.up.map(|v| zc * yr * v),
                self.right.map(|v| zr * xr * v),
                self.up.map(|v| zr * yr * v),
            ],
        )
    }
}
