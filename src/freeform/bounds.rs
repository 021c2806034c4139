//! Bounds of the field over a cell of the view pyramid: the set
//! `{o + z·(f + X·r + Y·u) : z ∈ [z₀, z₁], X ∈ [X₀, X₁], Y ∈ [Y₀, Y₁]}` (camera forward f, right r,
//! up u; X, Y the tangent-scaled screen coordinates). Written about its centre it is exactly
//! `c + Σₖ εₖ·vₖ` with five noise symbols εₖ ∈ [−1, 1]: depth, the two screen axes, and the two
//! depth×screen products (treated as independent, which only widens the set).
//!
//! Two bounds of the field over such a cell:
//! - [`Bound::Interval`]: natural interval arithmetic over the cell's axis-aligned box — the
//!   baseline Vyatkin et al. (2018) imply;
//! - [`Bound::Affine`]: affine arithmetic over the five noise symbols (Knoll et al. 2009): a
//!   quadric is evaluated exactly up to its quadratic remainder, `max(q, 0)³` by its Chebyshev
//!   linear approximation, so the base surface and its perturbations keep their first-order
//!   correlation instead of adding up worst cases.
//!
//! Both return an interval that contains every value of the field on the cell (up to f64
//! rounding, far below the margins the casters use). A perturbation whose support box misses
//! the cell's box contributes exactly 0 and is skipped.

use super::field::{dot, Bump, Field, Op, Quad};
use serde::{Deserialize, Serialize};

/// Which bound culls cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum Bound {
    /// Interval arithmetic over the cell's bounding box.
    Interval,
    /// Affine arithmetic over the cell's five noise symbols.
    Affine,
}

/// Noise symbols of a cell.
pub const SYMBOLS: usize = 5;

/// A view-pyramid cell: centre and the five generating vectors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cell {
    pub c: [f64; 3],
    pub v: [[f64; 3]; SYMBOLS],
}

impl Cell {
    /// The cell's axis-aligned bounding box.
    pub fn bbox(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = self.c;
        let mut hi = self.c;
        for k in 0..3 {
            let r: f64 = self.v.iter().map(|v| v[k].abs()).sum();
            lo[k] -= r;
            hi[k] += r;
        }
        (lo, hi)
    }
}

/// A closed interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub lo: f64,
    pub hi: f64,
}

impl Range {
    /// True when the interval holds 0 (the cell may hold surface).
    pub fn straddles(&self) -> bool {
        self.lo <= 0.0 && self.hi >= 0.0
    }
}

fn imul(a: Range, b: Range) -> Range {
    let p = [a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi];
    Range {
        lo: p.iter().copied().fold(f64::INFINITY, f64::min),
        hi: p.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    }
}

fn isq(a: Range) -> Range {
    let (l, h) = (a.lo * a.lo, a.hi * a.hi);
    if a.lo <= 0.0 && a.hi >= 0.0 {
        Range {
            lo: 0.0,
            hi: l.max(h),
        }
    } else {
        Range {
            lo: l.min(h),
            hi: l.max(h),
        }
    }
}

fn iadd(a: Range, b: Range) -> Range {
    Range {
        lo: a.lo + b.lo,
        hi: a.hi + b.hi,
    }
}

fn iscale(a: Range, k: f64) -> Range {
    if k >= 0.0 {
        Range {
            lo: a.lo * k,
            hi: a.hi * k,
        }
    } else {
        Range {
            lo: a.hi * k,
            hi: a.lo * k,
        }
    }
}

/// Natural interval extension of a quadric over a box.
pub fn quad_interval(q: &Quad, lo: [f64; 3], hi: [f64; 3]) -> Range {
    let x: [Range; 3] = std::array::from_fn(|k| Range {
        lo: lo[k],
        hi: hi[k],
    });
    let mut r = Range { lo: q.c, hi: q.c };
    for i in 0..3 {
        r = iadd(r, iscale(isq(x[i]), q.a[i][i]));
        r = iadd(r, iscale(x[i], 2.0 * q.b[i]));
        for j in i + 1..3 {
            r = iadd(r, iscale(imul(x[i], x[j]), 2.0 * q.a[i][j]));
        }
    }
    r
}

/// An affine form `x₀ + Σ gₖ εₖ ± e`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Affine {
    pub x0: f64,
    pub g: [f64; SYMBOLS],
    pub e: f64,
}

impl Affine {
    fn constant(x: f64) -> Affine {
        Affine {
            x0: x,
            g: [0.0; SYMBOLS],
            e: 0.0,
        }
    }

    fn radius(&self) -> f64 {
        self.g.iter().map(|g| g.abs()).sum::<f64>() + self.e
    }

    /// The interval the form spans.
    pub fn range(&self) -> Range {
        let r = self.radius();
        Range {
            lo: self.x0 - r,
            hi: self.x0 + r,
        }
    }

    fn add_scaled(&mut self, b: &Affine, k: f64) {
        self.x0 += k * b.x0;
        for i in 0..SYMBOLS {
            self.g[i] += k * b.g[i];
        }
        self.e += k.abs() * b.e;
    }

    fn from_range(r: Range) -> Affine {
        Affine {
            x0: 0.5 * (r.lo + r.hi),
            g: [0.0; SYMBOLS],
            e: 0.5 * (r.hi - r.lo),
        }
    }
}

/// A quadric over a cell in affine form: exact linear part, the quadratic remainder
/// `εᵀ(VᵀAV)ε` bounded symbol by symbol.
pub fn quad_affine(q: &Quad, cell: &Cell) -> Affine {
    let g = q.grad(cell.c);
    let mut out = Affine {
        x0: q.eval(cell.c),
        g: std::array::from_fn(|k| dot(g, cell.v[k])),
        e: 0.0,
    };
    let av: [[f64; 3]; SYMBOLS] = std::array::from_fn(|k| {
        let v = cell.v[k];
        std::array::from_fn(|i| q.a[i][0] * v[0] + q.a[i][1] * v[1] + q.a[i][2] * v[2])
    });
    for j in 0..SYMBOLS {
        let mjj = dot(cell.v[j], av[j]);
        out.x0 += 0.5 * mjj;
        out.e += 0.5 * mjj.abs();
        for avk in &av[j + 1..] {
            out.e += 2.0 * dot(cell.v[j], *avk).abs();
        }
    }
    out
}

/// `max(x, 0)³` of an affine form: 0 when the form is ≤ 0, else the Chebyshev (min-max)
/// linear approximation of the convex function over the form's range.
pub fn relu_cube(x: &Affine) -> Affine {
    let Range { lo, hi } = x.range();
    if hi <= 0.0 {
        return Affine::constant(0.0);
    }
    let f = |t: f64| t.max(0.0).powi(3);
    if hi - lo <= 1e-300 {
        return Affine::constant(f(hi));
    }
    let alpha = (f(hi) - f(lo)) / (hi - lo);
    let u = (alpha / 3.0).sqrt().clamp(lo.max(0.0), hi);
    let secant = f(lo) + alpha * (u - lo);
    let delta = 0.5 * (secant - f(u));
    let zeta = 0.5 * (secant + f(u)) - alpha * u;
    Affine {
        x0: alpha * x.x0 + zeta,
        g: x.g.map(|g| alpha * g),
        e: alpha * x.e + delta.abs(),
    }
}

fn bump_skipped(b: &Bump, lo: [f64; 3], hi: [f64; 3]) -> bool {
    match b.support {
        Some((blo, bhi)) => (0..3).any(|k| bhi[k] < lo[k] || blo[k] > hi[k]),
        None => false,
    }
}

/// Work done by bound evaluations: quadric terms evaluated (bases and perturbations).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Work {
    pub terms: u64,
}

/// The field's range over `cell` by `bound`; `work.terms` counts the quadric terms evaluated.
pub fn field_range(field: &Field, cell: &Cell, bound: Bound, work: &mut Work) -> Range {
    let (lo, hi) = cell.bbox();
    match bound {
        Bound::Interval => {
            let leaf = |i: usize, work: &mut Work| {
                let l = &field.leaves[i];
                if let Some(t) = l.texture {
                    work.terms += 1;
                    let (lo, hi) = field.textures[t].range(lo, hi);
                    return Range { lo, hi };
                }
                let mut r = quad_interval(&l.base, lo, hi);
                work.terms += 1;
                for b in &field.bumps[l.bumps.clone()] {
                    if bump_skipped(b, lo, hi) {
                        continue;
                    }
                    work.terms += 1;
                    let q = quad_interval(&b.q, lo, hi);
                    if q.hi > 0.0 {
                        let c = Range {
                            lo: q.lo.max(0.0).powi(3),
                            hi: q.hi.powi(3),
                        };
                        r = iadd(r, iscale(c, b.weight));
                    }
                }
                r
            };
            run(field, |i| leaf(i, work), |r| r, |r| r)
        }
        Bound::Affine => {
            let leaf = |i: usize, work: &mut Work| {
                let l = &field.leaves[i];
                if let Some(t) = l.texture {
                    work.terms += 1;
                    let (lo, hi) = field.textures[t].range(lo, hi);
                    return Affine::from_range(Range { lo, hi });
                }
                let mut r = quad_affine(&l.base, cell);
                work.terms += 1;
                for b in &field.bumps[l.bumps.clone()] {
                    if bump_skipped(b, lo, hi) {
                        continue;
                    }
                    work.terms += 1;
                    let q = quad_affine(&b.q, cell);
                    if q.range().hi > 0.0 {
                        r.add_scaled(&relu_cube(&q), b.weight);
                    }
                }
                r
            };
            run(
                field,
                |i| leaf(i, work),
                |a: Affine| a.range(),
                Affine::from_range,
            )
            .range()
        }
    }
}

/// Run the CSG program over values of type T (ranges or affine forms): min/max fall back to
/// the interval hull unless one operand dominates.
fn run<T: Copy + Neg>(
    field: &Field,
    mut leaf: impl FnMut(usize) -> T,
    range: impl Fn(T) -> Range,
    from_range: impl Fn(Range) -> T,
) -> T {
    let mut stack: Vec<T> = Vec::with_capacity(8);
    for op in &field.ops {
        match *op {
            Op::Leaf(i) => stack.push(leaf(i as usize)),
            Op::Neg => {
                let t = stack.pop().expect("well-formed program");
                stack.push(t.neg());
            }
            Op::Min(n) | Op::Max(n) => {
                let from = stack.len() - n as usize;
                let is_min = matches!(op, Op::Min(_));
                let mut acc = stack[from];
                for &x in &stack[from + 1..] {
                    let (ra, rx) = (range(acc), range(x));
                    acc = if is_min {
                        if ra.hi <= rx.lo {
                            acc
                        } else if rx.hi <= ra.lo {
                            x
                        } else {
                            from_range(Range {
                                lo: ra.lo.min(rx.lo),
                                hi: ra.hi.min(rx.hi),
                            })
                        }
                    } else if ra.lo >= rx.hi {
                        acc
                    } else if rx.lo >= ra.hi {
                        x
                    } else {
                        from_range(Range {
                            lo: ra.lo.max(rx.lo),
                            hi: ra.hi.max(rx.hi),
                        })
                    };
                }
                stack.truncate(from);
                stack.push(acc);
            }
        }
    }
    stack.pop().expect("one value")
}

/// Negation of a bound value.
pub trait Neg {
    fn neg(self) -> Self;
}

impl Neg for Range {
    fn neg(self) -> Range {
        Range {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Neg for Affine {
    fn neg(self) -> Affine {
        Affine {
            x0: -self.x0,
            g: self.g.map(|g| -g),
            e: self.e,
        }
    }
}
