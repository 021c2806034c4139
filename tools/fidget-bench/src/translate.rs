//! relume's compiled freeform [`Field`] as a fidget expression: each quadric in a centred
//! form (better conditioned in f32 than the expanded `pᵀAp + 2bᵀp + c`), each perturbation as
//! `g · max(q, 0)³`, the CSG program as min/max/neg.

use fidget::context::{Context, Node};
use relume::freeform::field::{Field, Op, Quad};

/// An error of the translation (a shape texture, or an ill-formed program).
pub type Error = Box<dyn std::error::Error>;

/// The expression of `field` in `ctx`.
pub fn field_node(ctx: &mut Context, field: &Field) -> Result<Node, Error> {
    let axes = ctx.axes();
    let mut stack: Vec<Node> = Vec::new();
    for op in &field.ops {
        match *op {
            Op::Leaf(i) => {
                let leaf = &field.leaves[i as usize];
                if leaf.texture.is_some() {
                    return Err("shape textures have no fidget translation".into());
                }
                let mut v = quad_node(ctx, &leaf.base, axes)?;
                for bump in &field.bumps[leaf.bumps.clone()] {
                    let q = quad_node(ctx, &bump.q, axes)?;
                    let m = ctx.max(q, 0.0)?;
                    let m2 = ctx.square(m)?;
                    let m3 = ctx.mul(m2, m)?;
                    let term = ctx.mul(m3, bump.weight as f32)?;
                    v = ctx.add(v, term)?;
                }
                stack.push(v);
            }
            Op::Neg => {
                let top = stack.pop().ok_or("Neg on an empty stack")?;
                stack.push(ctx.neg(top)?);
            }
            Op::Min(n) | Op::Max(n) => {
                let from = stack
                    .len()
                    .checked_sub(n as usize)
                    .ok_or("CSG operator with too few operands")?;
                let operands = stack.split_off(from);
                let mut acc = operands[0];
                for &b in &operands[1..] {
                    acc = match op {
                        Op::Min(_) => ctx.min(acc, b)?,
                        _ => ctx.max(acc, b)?,
                    };
                }
                stack.push(acc);
            }
        }
    }
    match stack.as_slice() {
        [root] => Ok(*root),
        _ => Err("the CSG program does not reduce to one value".into()),
    }
}

/// `Q(p)` written about a centre `p₀` (the stationary point `−A⁻¹b` when A is invertible,
/// else the origin): `Q(p₀ + d) = dᵀAd + 2gᵀd + Q(p₀)`, `g = Ap₀ + b`, `d = p − p₀`.
fn quad_node(ctx: &mut Context, q: &Quad, axes: [Node; 3]) -> Result<Node, Error> {
    let p0 = stationary_point(q).unwrap_or([0.0; 3]);
    let a = &q.a;
    let mut g = [0.0; 3];
    for i in 0..3 {
        g[i] = a[i][0] * p0[0] + a[i][1] * p0[1] + a[i][2] * p0[2] + q.b[i];
        // At the stationary point g is rounding noise: drop it.
        let scale = q.b[i].abs() + (0..3).map(|j| (a[i][j] * p0[j]).abs()).sum::<f64>();
        if g[i].abs() <= 1e-12 * scale {
            g[i] = 0.0;
        }
    }
    let c = q.eval(p0);
    let mut d = [axes[0]; 3];
    for k in 0..3 {
        d[k] = if p0[k] == 0.0 {
            axes[k]
        } else {
            ctx.sub(axes[k], p0[k] as f32)?
        };
    }
    let mut terms: Vec<Node> = Vec::new();
    for i in 0..3 {
        if a[i][i] != 0.0 {
            let s = ctx.square(d[i])?;
            terms.push(ctx.mul(s, a[i][i] as f32)?);
        }
        for j in i + 1..3 {
            let k = a[i][j] + a[j][i];
            if k != 0.0 {
                let p = ctx.mul(d[i], d[j])?;
                terms.push(ctx.mul(p, k as f32)?);
            }
        }
        if g[i] != 0.0 {
            terms.push(ctx.mul(d[i], (2.0 * g[i]) as f32)?);
        }
    }
    let mut acc = ctx.constant(c as f32);
    for t in terms {
        acc = ctx.add(acc, t)?;
    }
    Ok(acc)
}

/// `−A⁻¹b`, or `None` when A is (nearly) singular.
fn stationary_point(q: &Quad) -> Option<[f64; 3]> {
    let a = &q.a;
    let cof =
        |r0: usize, r1: usize, c0: usize, c1: usize| a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
    let adj = [
        [cof(1, 2, 1, 2), -cof(0, 2, 1, 2), cof(0, 1, 1, 2)],
        [-cof(1, 2, 0, 2), cof(0, 2, 0, 2), -cof(0, 1, 0, 2)],
        [cof(1, 2, 0, 1), -cof(0, 2, 0, 1), cof(0, 1, 0, 1)],
    ];
    let det = a[0][0] * adj[0][0] + a[0][1] * adj[1][0] + a[0][2] * adj[2][0];
    let norm = a.iter().flatten().map(|v| v.abs()).fold(0.0, f64::max);
    if norm == 0.0 || det.abs() <= 1e-9 * norm.powi(3) {
        return None;
    }
    Some(std::array::from_fn(|i| {
        -(adj[i][0] * q.b[0] + adj[i][1] * q.b[1] + adj[i][2] * q.b[2]) / det
    }))
}
