//! The compiled field of a freeform scene: world-space quadrics, the perturbations of each
//! surface, and the CSG tree as a postfix program. Every ray caster (the exact reference, the
//! multilevel caster, the GPU kernel) evaluates this one representation.
//!
//! A quadric is `Q(p) = pᵀ A p + 2 bᵀ p + c` (A symmetric). Along a line `p + s·d` it is the
//! quadratic `α s² + β s + γ` with `α = dᵀAd`, `β = 2(Ap + b)·d`, `γ = Q(p)`: evaluating the
//! coefficients about a point near the interval of interest (not about the ray origin) keeps
//! them accurate far from the origin.

use super::texture::Texture;
use crate::error::{Error, Result};
use crate::scene::freeform::{Quadric, Shape, Transform};
use glam::{DMat3, DMat4, DVec3, DVec4};

/// `pᵀ A p + 2 bᵀ p + c`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quad {
    pub a: [[f64; 3]; 3],
    pub b: [f64; 3],
    pub c: f64,
}

#[inline]
pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Quad {
    #[inline]
    fn ap_b(&self, p: [f64; 3]) -> [f64; 3] {
        let a = &self.a;
        [
            a[0][0] * p[0] + a[0][1] * p[1] + a[0][2] * p[2] + self.b[0],
            a[1][0] * p[0] + a[1][1] * p[1] + a[1][2] * p[2] + self.b[1],
            a[2][0] * p[0] + a[2][1] * p[1] + a[2][2] * p[2] + self.b[2],
        ]
    }

    /// `Q(p)`.
    #[inline]
    pub fn eval(&self, p: [f64; 3]) -> f64 {
        let g = self.ap_b(p);
        dot(g, p) + dot(self.b, p) + self.c
    }

    /// `Σ|aᵢⱼ||pᵢ||pⱼ| + 2Σ|bᵢ||pᵢ| + |c|`: the scale of the rounding error of [`Quad::eval`].
    pub fn magnitude(&self, p: [f64; 3]) -> f64 {
        let ap = p.map(f64::abs);
        let mut m = self.c.abs();
        for i in 0..3 {
            m += 2.0 * self.b[i].abs() * ap[i];
            for j in 0..3 {
                m += self.a[i][j].abs() * ap[i] * ap[j];
            }
        }
        m
    }

    /// `∇Q(p) = 2(Ap + b)`.
    #[inline]
    pub fn grad(&self, p: [f64; 3]) -> [f64; 3] {
        let g = self.ap_b(p);
        [2.0 * g[0], 2.0 * g[1], 2.0 * g[2]]
    }

    /// `(α, β, γ)` of `Q(p + s·d) = α s² + β s + γ`.
    #[inline]
    pub fn along(&self, p: [f64; 3], d: [f64; 3]) -> [f64; 3] {
        let g = self.ap_b(p);
        let ad = self.ap_b(d);
        let alpha = dot(ad, d) - dot(self.b, d);
        [alpha, 2.0 * dot(g, d), dot(g, p) + dot(self.b, p) + self.c]
    }

    /// `−Q`.
    pub fn negated(&self) -> Quad {
        let mut q = *self;
        q.a.iter_mut().flatten().for_each(|v| *v = -*v);
        q.b.iter_mut().for_each(|v| *v = -*v);
        q.c = -q.c;
        q
    }

    fn from_mat4(m: DMat4) -> Quad {
        let c = |i: usize, j: usize| m.col(j)[i];
        Quad {
            a: [
                [c(0, 0), c(0, 1), c(0, 2)],
                [c(1, 0), c(1, 1), c(1, 2)],
                [c(2, 0), c(2, 1), c(2, 2)],
            ],
            b: [c(0, 3), c(1, 3), c(2, 3)],
            c: c(3, 3),
        }
    }
}

/// One perturbation of a surface: `weight · max(q(p), 0)³`, with `q ≥ 0` only inside `support`
/// when the support is bounded (an ellipsoid or sphere shape).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bump {
    pub q: Quad,
    pub weight: f64,
    /// World box outside which `q < 0` (so the term is exactly 0); `None` when unbounded.
    pub support: Option<([f64; 3], [f64; 3])>,
}

/// One surface: base quadric, its bumps (a range of [`Field::bumps`]), its material.
#[derive(Clone, Debug, PartialEq)]
pub struct Leaf {
    pub base: Quad,
    pub bumps: std::ops::Range<usize>,
    pub color: [f64; 3],
    pub specular: f64,
    /// A shape texture (index into [`Field::textures`]): the leaf's field is the texture's,
    /// its base quadric zero and its bump range empty.
    pub texture: Option<usize>,
}

/// One instruction of the CSG program (postfix).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// Push the field of leaf i.
    Leaf(u32),
    /// Pop n values, push their minimum (union).
    Min(u32),
    /// Pop n values, push their maximum (intersection).
    Max(u32),
    /// Negate the top value (the second operand of a difference).
    Neg,
}

/// A compiled scene field.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    pub leaves: Vec<Leaf>,
    pub bumps: Vec<Bump>,
    pub ops: Vec<Op>,
    pub textures: Vec<Texture>,
}

/// The 4×4 object-frame matrix of a quadric (negative inside).
fn canonical(q: &Quadric) -> DMat4 {
    let diag = |a: f64, b: f64, c: f64, d: f64| DMat4::from_diagonal(DVec4::new(a, b, c, d));
    match *q {
        Quadric::Plane { normal, offset } => {
            let n = DVec3::from(normal).normalize();
            let mut m = DMat4::ZERO;
            for i in 0..3 {
                m.col_mut(3)[i] = 0.5 * n[i];
                m.col_mut(i)[3] = 0.5 * n[i];
            }
            m.col_mut(3)[3] = -offset;
            m
        }
        Quadric::Sphere { radius: r } => {
            let k = 1.0 / (r * r);
            diag(k, k, k, -1.0)
        }
        Quadric::Ellipsoid { radii: [a, b, c] } => {
            diag(1.0 / (a * a), 1.0 / (b * b), 1.0 / (c * c), -1.0)
        }
        Quadric::Cylinder { radius: r } => diag(1.0 / (r * r), 0.0, 1.0 / (r * r), -1.0),
        Quadric::Cone { half_angle } => {
            let t = half_angle.to_radians().tan();
            diag(1.0, -t * t, 1.0, 0.0)
        }
        Quadric::Paraboloid {
            radius: r,
            height: h,
        } => {
            let mut m = diag(1.0 / (r * r), 0.0, 1.0 / (r * r), 0.0);
            m.col_mut(3)[1] = -0.5 / h;
            m.col_mut(1)[3] = -0.5 / h;
            m
        }
        Quadric::Hyperboloid {
            radius: r,
            height: h,
            sheets,
        } => {
            let (k, l) = (1.0 / (r * r), 1.0 / (h * h));
            if sheets == 2 {
                diag(k, -l, k, 1.0)
            } else {
                diag(k, -l, k, -1.0)
            }
        }
        Quadric::General { matrix } => DMat4::from_cols_array_2d(&matrix).transpose(),
    }
}

/// Object → world matrix `T · Rz · Ry · Rx · S`.
pub fn placement(t: &Transform) -> DMat4 {
    let [rx, ry, rz] = t.rotate.map(f64::to_radians);
    DMat4::from_translation(DVec3::from(t.translate))
        * DMat4::from_rotation_z(rz)
        * DMat4::from_rotation_y(ry)
        * DMat4::from_rotation_x(rx)
        * DMat4::from_scale(DVec3::from(t.scale))
}

/// The world quadric of `q` placed by `t`: `Cᵀ Q C` with `C = M⁻¹`.
pub fn world_quad(q: &Quadric, t: &Transform) -> Quad {
    let c = placement(t).inverse();
    Quad::from_mat4(c.transpose() * canonical(q) * c)
}

/// The world box of a bounded shape's inside (sphere, ellipsoid), else `None`.
fn support_box(q: &Quadric, t: &Transform) -> Option<([f64; 3], [f64; 3])> {
    let radii = match *q {
        Quadric::Sphere { radius } => DVec3::splat(radius),
        Quadric::Ellipsoid { radii } => DVec3::from(radii),
        _ => return None,
    };
    let m = placement(t);
    let lin = DMat3::from_mat4(m) * DMat3::from_diagonal(radii);
    let centre = m.w_axis.truncate();
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for i in 0..3 {
        let row = lin.row(i);
        // A hair wider than the ellipsoid so that rounding never cuts off a live term.
        let h = row.length() * (1.0 + 1e-9) + 1e-12 * centre[i].abs();
        lo[i] = centre[i] - h;
        hi[i] = centre[i] + h;
    }
    Some((lo, hi))
}

impl Field {
    /// Compile a CSG tree.
    pub fn compile(shape: &Shape) -> Result<Field> {
        let mut f = Field {
            leaves: Vec::new(),
            bumps: Vec::new(),
            ops: Vec::new(),
            textures: Vec::new(),
        };
        f.emit(shape)?;
        if f.leaves.is_empty() {
            return Err(Error::knob("a freeform scene needs at least one surface"));
        }
        Ok(f)
    }

    fn emit(&mut self, shape: &Shape) -> Result<()> {
        match shape {
            Shape::Textured(t) => {
                self.ops.push(Op::Leaf(self.leaves.len() as u32));
                self.leaves.push(Leaf {
                    base: Quad {
                        a: [[0.0; 3]; 3],
                        b: [0.0; 3],
                        c: 0.0,
                    },
                    bumps: self.bumps.len()..self.bumps.len(),
                    color: t.color,
                    specular: t.specular,
                    texture: Some(self.textures.len()),
                });
                self.textures.push(Texture::compile(t)?);
            }
            Shape::Surface(s) => {
                let start = self.bumps.len();
                for p in &s.perturbations {
                    self.bumps.push(Bump {
                        q: world_quad(&p.shape, &p.transform).negated(),
                        weight: p.weight,
                        support: support_box(&p.shape, &p.transform),
                    });
                }
                self.ops.push(Op::Leaf(self.leaves.len() as u32));
                self.leaves.push(Leaf {
                    base: world_quad(&s.base, &s.transform),
                    bumps: start..self.bumps.len(),
                    color: s.color,
                    specular: s.specular,
                    texture: None,
                });
            }
            Shape::Union(c) | Shape::Intersection(c) => {
                for c in c {
                    self.emit(c)?;
                }
                if c.len() > 1 {
                    let n = c.len() as u32;
                    self.ops.push(match shape {
                        Shape::Union(_) => Op::Min(n),
                        _ => Op::Max(n),
                    });
                }
            }
            Shape::Difference(a, b) => {
                self.emit(a)?;
                self.emit(b)?;
                self.ops.push(Op::Neg);
                self.ops.push(Op::Max(2));
            }
        }
        Ok(())
    }

    /// Morph every shape texture to parameter `s` ∈ [0, 1] (those without a second grid stay).
    pub fn set_morph(&mut self, s: f64) {
        self.textures.iter_mut().for_each(|t| t.set_morph(s));
    }

    /// The field of leaf `i` at `p`.
    #[inline]
    pub fn leaf_value(&self, i: usize, p: [f64; 3]) -> f64 {
        let leaf = &self.leaves[i];
        if let Some(t) = leaf.texture {
            return self.textures[t].value(p);
        }
        let mut v = leaf.base.eval(p);
        for b in &self.bumps[leaf.bumps.clone()] {
            if let Some((lo, hi)) = b.support {
                if (0..3).any(|k| p[k] < lo[k] || p[k] > hi[k]) {
                    continue;
                }
            }
            let q = b.q.eval(p);
            if q > 0.0 {
                v += b.weight * q * q * q;
            }
        }
        v
    }

    /// The gradient of leaf `i` at `p`.
    pub fn leaf_gradient(&self, i: usize, p: [f64; 3]) -> [f64; 3] {
        let leaf = &self.leaves[i];
        if let Some(t) = leaf.texture {
            return self.textures[t].gradient(p);
        }
        let mut g = leaf.base.grad(p);
        for b in &self.bumps[leaf.bumps.clone()] {
            let q = b.q.eval(p);
            if q > 0.0 {
                let k = 3.0 * b.weight * q * q;
                let gq = b.q.grad(p);
                (0..3).for_each(|i| g[i] += k * gq[i]);
            }
        }
        g
    }

    /// The field at `p` and the leaf it comes from, with the sign the CSG gives that leaf
    /// (−1 under a difference's second operand).
    pub fn eval_with_leaf(&self, p: [f64; 3]) -> (f64, usize, f64) {
        let mut stack: Vec<(f64, usize, f64)> = Vec::with_capacity(8);
        for op in &self.ops {
            match *op {
                Op::Leaf(i) => stack.push((self.leaf_value(i as usize, p), i as usize, 1.0)),
                Op::Neg => {
                    let top = stack.last_mut().expect("postfix program is well formed");
                    top.0 = -top.0;
                    top.2 = -top.2;
                }
                Op::Min(n) | Op::Max(n) => {
                    let from = stack.len() - n as usize;
                    let is_min = matches!(op, Op::Min(_));
                    let best = stack[from..]
                        .iter()
                        .copied()
                        .reduce(|a, b| {
                            if (is_min && b.0 < a.0) || (!is_min && b.0 > a.0) {
                                b
                            } else {
                                a
                            }
                        })
                        .expect("n >= 1");
                    stack.truncate(from);
                    stack.push(best);
                }
            }
        }
        stack[0]
    }

    /// The field at `p`.
    pub fn eval(&self, p: [f64; 3]) -> f64 {
        self.eval_with_leaf(p).0
    }

    /// The outward unit normal at a surface point `p` (the gradient of the active leaf, with
    /// its CSG sign).
    pub fn normal(&self, p: [f64; 3]) -> [f64; 3] {
        let (_, leaf, sign) = self.eval_with_leaf(p);
        let g = self.leaf_gradient(leaf, p);
        let len = dot(g, g).sqrt();
        if len > 0.0 && len.is_finite() {
            g.map(|v| sign * v / len)
        } else {
            [0.0, 1.0, 0.0]
        }
    }
}
