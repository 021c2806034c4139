//! The exact ray cast every other method is tested against (f64).
//!
//! Along a ray `o + t·d` a surface's field is piecewise polynomial: the base quadric is a
//! quadratic in t, each perturbation `g·max(q, 0)³` a sextic where `q(t) > 0` and 0 elsewhere, so
//! the pieces break at the (closed-form) roots of the `q`'s. On each piece the sextic is built
//! about the piece's midpoint and its roots isolated by [`poly::roots_in`] (certified brackets).
//! That gives each surface's solid set along the ray as closed intervals; the CSG tree combines
//! them exactly as sets (union, intersection, closure of the complement), so min/max switches
//! need no root finding of their own. The hit is the first boundary point of the final set
//! after `t_min`: an entry, or the exit when the ray starts inside.

use super::field::{Field, Op};
use super::poly::{self, Poly};

/// Closed intervals, sorted and disjoint.
type Set = Vec<(f64, f64)>;

/// A ray hit: distance along the (unit) direction, and the leaf hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f64,
    pub leaf: usize,
}

fn ray_box(
    o: [f64; 3],
    d: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
    t0: f64,
    t1: f64,
) -> Option<(f64, f64)> {
    let (mut a, mut b) = (t0, t1);
    for k in 0..3 {
        if d[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
            continue;
        }
        let (mut u, mut v) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
        if u > v {
            std::mem::swap(&mut u, &mut v);
        }
        a = a.max(u);
        b = b.min(v);
        if a > b {
            return None;
        }
    }
    Some((a, b))
}

fn at(o: [f64; 3], d: [f64; 3], t: f64) -> [f64; 3] {
    [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]]
}

/// The solid set of leaf `i` along the ray within `[t0, t1]`.
pub fn leaf_solid(
    field: &Field,
    i: usize,
    o: [f64; 3],
    d: [f64; 3],
    t0: f64,
    t1: f64,
) -> Vec<(f64, f64)> {
    let leaf = &field.leaves[i];
    if let Some(t) = leaf.texture {
        return field.textures[t].solid_along(o, d, t0, t1);
    }
    let mut set: Set = Vec::new();
    let add = |a: f64, b: f64, set: &mut Set| match set.last_mut() {
        Some(last) if last.1 >= a => last.1 = last.1.max(b),
        _ => set.push((a, b)),
    };
    // The base quadric's own roots and tangent touch, in closed form about its vertex.
    let (mut breaks, touch) = quad_roots(&leaf.base, o, d, t0, t1);
    breaks.extend([t0, t1]);
    // Perturbations whose support the ray crosses, and where their q changes sign.
    let mut live = Vec::new();
    for (k, b) in field.bumps[leaf.bumps.clone()].iter().enumerate() {
        let (a, e) = match b.support {
            Some((lo, hi)) => match ray_box(o, d, lo, hi, t0, t1) {
                Some(r) => r,
                None => continue,
            },
            None => (t0, t1),
        };
        breaks.extend(quad_roots(&b.q, o, d, a, e).0);
        live.push(leaf.bumps.start + k);
    }
    breaks.retain(|t| *t >= t0 && *t <= t1);
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let touch = touch.filter(|t| *t > t0 && *t < t1);
    for w in breaks.windows(2) {
        let (a, b) = (w[0], w[1]);
        let m = 0.5 * (a + b);
        let pm = at(o, d, m);
        let active: Vec<usize> = live
            .iter()
            .copied()
            .filter(|&k| field.bumps[k].q.eval(pm) > 0.0)
            .collect();
        if active.is_empty() {
            // Only the base quadric: its roots are breakpoints, so the sign is constant.
            if let Some(t) = touch.filter(|t| *t >= a && *t <= b) {
                add(t, t, &mut set);
            }
            if leaf.base.eval(pm) <= 0.0 {
                add(a, b, &mut set);
            }
            continue;
        }
        let mut p: Poly = [0.0; 7];
        let [fa, fb, fc] = leaf.base.along(pm, d);
        p[0] = fc;
        p[1] = fb;
        p[2] = fa;
        for &k in &active {
            let bump = &field.bumps[k];
            poly::add_cube(&mut p, bump.q.along(pm, d), bump.weight);
        }
        let (sa, sb) = (a - m, b - m);
        let mut roots = Vec::new();
        poly::roots_in(&p, sa, sb, &mut roots);
        // Piece ends stay exact (a, b), so that neighbouring pieces and sets meet exactly; roots
        // are polished against the field evaluated at the point itself.
        let mut pts = vec![a];
        pts.extend(
            roots
                .iter()
                .filter(|r| **r > sa && **r < sb)
                .map(|r| polish(field, &live, i, o, d, r + m, a, b)),
        );
        pts.push(b);
        let inside: Vec<bool> = pts
            .windows(2)
            .map(|seg| poly::eval(&p, 0.5 * (seg[0] + seg[1]) - m) <= 0.0)
            .collect();
        for (j, seg) in pts.windows(2).enumerate() {
            if inside[j] {
                add(seg[0], seg[1], &mut set);
            } else if j > 0 && !inside[j - 1] {
                // A root between two outside segments: a tangent touch.
                add(seg[0], seg[0], &mut set);
            }
        }
    }
    set
}

/// The roots of quadric `q` along `o + t·d` in `[t0, t1]`, and its tangent point when the line
/// only touches it. Coefficients are taken about the line's point nearest the vertex of the
/// quadratic (the minimum or maximum of q along the line), where they are accurate: the
/// discriminant there is `−γ/α` up to rounding, and a touch is a `γ` within the rounding bound
/// of evaluating q at that point.
pub fn quad_roots(
    q: &super::field::Quad,
    o: [f64; 3],
    d: [f64; 3],
    t0: f64,
    t1: f64,
) -> (Vec<f64>, Option<f64>) {
    let [a0, b0, c0] = q.along(o, d);
    let mut out = Vec::new();
    let scale = a0.abs() + b0.abs();
    if a0.abs() <= 1e-14 * scale || a0 == 0.0 {
        if b0 != 0.0 {
            // Linear: one Newton step about the first estimate.
            let t = -c0 / b0;
            let [_, b1, c1] = q.along(at(o, d, t), d);
            let t = if b1 != 0.0 { t - c1 / b1 } else { t };
            if t >= t0 && t <= t1 {
                out.push(t);
            }
        }
        return (out, None);
    }
    let mut tv = -b0 / (2.0 * a0);
    let [_, bv, _] = q.along(at(o, d, tv), d);
    tv -= bv / (2.0 * a0);
    let pv = at(o, d, tv);
    let [a, b, c] = q.along(pv, d);
    let disc = b * b - 4.0 * a * c;
    let tol = 8.0 * f64::EPSILON * q.magnitude(pv);
    if c.abs() <= tol {
        return (
            (tv >= t0 && tv <= t1).then_some(tv).into_iter().collect(),
            Some(tv),
        );
    }
    if disc < 0.0 {
        return (out, None);
    }
    let h = -0.5 * (b + b.signum() * disc.sqrt());
    let mut r = [h / a, c / h];
    r.sort_by(f64::total_cmp);
    for s in r {
        let t = tv + s;
        if t >= t0 && t <= t1 {
            out.push(t);
        }
    }
    (out, None)
}

/// Leaf `i`'s field and its t-derivative at `o + t·d`, from coefficients about that point.
fn value_and_slope(
    field: &Field,
    live: &[usize],
    i: usize,
    o: [f64; 3],
    d: [f64; 3],
    t: f64,
) -> (f64, f64) {
    let p = at(o, d, t);
    let [_, mut slope, mut value] = field.leaves[i].base.along(p, d);
    for &k in live {
        let b = &field.bumps[k];
        let [_, qb, q] = b.q.along(p, d);
        if q > 0.0 {
            value += b.weight * q * q * q;
            slope += 3.0 * b.weight * q * q * qb;
        }
    }
    (value, slope)
}

/// Newton steps from `t` on the field evaluated about the point itself (not about the piece's
/// midpoint, whose coefficients lose digits when the piece is long), kept only while they stay
/// in `[lo, hi]` and shrink the residual.
#[allow(clippy::too_many_arguments)]
fn polish(
    field: &Field,
    live: &[usize],
    i: usize,
    o: [f64; 3],
    d: [f64; 3],
    mut t: f64,
    lo: f64,
    hi: f64,
) -> f64 {
    let (mut v, mut s) = value_and_slope(field, live, i, o, d, t);
    for _ in 0..4 {
        if v == 0.0 || s == 0.0 {
            break;
        }
        let nt = t - v / s;
        if !(nt >= lo && nt <= hi) {
            break;
        }
        let (nv, ns) = value_and_slope(field, live, i, o, d, nt);
        if nv.abs() >= v.abs() {
            break;
        }
        (t, v, s) = (nt, nv, ns);
    }
    t
}

fn union(a: &Set, b: &Set) -> Set {
    let mut all: Set = a.iter().chain(b).copied().collect();
    all.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut out: Set = Vec::with_capacity(all.len());
    for (s, e) in all {
        match out.last_mut() {
            Some(last) if last.1 >= s => last.1 = last.1.max(e),
            _ => out.push((s, e)),
        }
    }
    out
}

fn intersection(a: &Set, b: &Set) -> Set {
    let (mut i, mut j) = (0, 0);
    let mut out = Vec::new();
    while i < a.len() && j < b.len() {
        let s = a[i].0.max(b[j].0);
        let e = a[i].1.min(b[j].1);
        if s <= e {
            out.push((s, e));
        }
        if a[i].1 < b[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    out
}

/// The closure of the complement of `a` within `[t0, t1]`.
fn complement(a: &Set, t0: f64, t1: f64) -> Set {
    let mut out = Vec::new();
    let mut from = t0;
    for &(s, e) in a {
        if s > from || (s == from && s == e) {
            out.push((from, s));
        }
        from = e;
    }
    if from < t1 || a.is_empty() {
        out.push((from, t1));
    }
    // A point interval in `a` leaves the complement whole: merge touching pieces.
    union(&out, &Vec::new())
}

/// The solid set of the whole scene along the ray within `[t0, t1]`.
pub fn solid(field: &Field, o: [f64; 3], d: [f64; 3], t0: f64, t1: f64) -> Vec<(f64, f64)> {
    let mut stack: Vec<Set> = Vec::new();
    for op in &field.ops {
        match *op {
            Op::Leaf(i) => stack.push(leaf_solid(field, i as usize, o, d, t0, t1)),
            Op::Neg => {
                let top = stack.pop().expect("well-formed program");
                stack.push(complement(&top, t0, t1));
            }
            Op::Min(n) | Op::Max(n) => {
                let from = stack.len() - n as usize;
                let parts: Vec<Set> = stack.drain(from..).collect();
                let is_min = matches!(op, Op::Min(_));
                let merged = parts
                    .into_iter()
                    .reduce(|a, b| {
                        if is_min {
                            union(&a, &b)
                        } else {
                            intersection(&a, &b)
                        }
                    })
                    .expect("n >= 1");
                stack.push(merged);
            }
        }
    }
    stack.pop().expect("one value")
}

/// The first surface point along `o + t·d`, `t ∈ (t_min, t_max]` (d need not be unit; t is in
/// units of |d|).
pub fn first_hit(field: &Field, o: [f64; 3], d: [f64; 3], t_min: f64, t_max: f64) -> Option<Hit> {
    let set = solid(field, o, d, t_min, t_max);
    let t = set.iter().find_map(|&(s, e)| {
        if s > t_min {
            Some(s)
        } else if e < t_max {
            Some(e)
        } else {
            None
        }
    })?;
    let (_, leaf, _) = field.eval_with_leaf(at(o, d, t));
    Some(Hit { t, leaf })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_operations_are_those_of_closed_intervals() {
        let a = vec![(0.0, 2.0), (5.0, 6.0)];
        let b = vec![(1.0, 5.5)];
        assert_eq!(union(&a, &b), vec![(0.0, 6.0)]);
        assert_eq!(intersection(&a, &b), vec![(1.0, 2.0), (5.0, 5.5)]);
        assert_eq!(
            complement(&a, -1.0, 10.0),
            vec![(-1.0, 0.0), (2.0, 5.0), (6.0, 10.0)]
        );
        assert_eq!(complement(&vec![(3.0, 3.0)], 0.0, 10.0), vec![(0.0, 10.0)]);
    }
}
