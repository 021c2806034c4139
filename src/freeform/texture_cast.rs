//! The certified cast of a shape texture along a ray (the exact reference's texture leaves,
//! `reference.rs`): bisection on the texture's bounds (`texture.rs`, module header).

use super::texture::{Texture, MAX_SEGMENTS};

impl Texture {
    /// The solid set along `o + t·d` within [t0, t1]: bisection on the bounds of segments,
    /// down to `1e-10·(1 + |t|)`, where the end points' signs decide and a sign change is
    /// refined by bisection on F to the last bit. Certified except for a tangent touch (F
    /// reaching 0 without changing sign) inside one tolerance interval, and beyond
    /// [`MAX_SEGMENTS`] segments on one ray, where the segments left are decided by their end
    /// points (a guard against pathological inputs; the bundled scenes stay far below it).
    pub fn solid_along(&self, o: [f64; 3], d: [f64; 3], t0: f64, t1: f64) -> Vec<(f64, f64)> {
        let mut out: Vec<(f64, f64)> = Vec::new();
        let at = |t: f64| -> [f64; 3] { std::array::from_fn(|k| o[k] + t * d[k]) };
        let push = |a: f64, b: f64, out: &mut Vec<(f64, f64)>| match out.last_mut() {
            Some(last) if last.1 >= a => last.1 = last.1.max(b),
            _ => out.push((a, b)),
        };
        let mut stack = vec![(t0, t1)];
        let mut budget = MAX_SEGMENTS;
        while let Some((a, b)) = stack.pop() {
            budget = budget.saturating_sub(1);
            let (pa, pb) = (at(a), at(b));
            let lo: [f64; 3] = std::array::from_fn(|k| pa[k].min(pb[k]));
            let hi: [f64; 3] = std::array::from_fn(|k| pa[k].max(pb[k]));
            let (rlo, rhi) = self.range(lo, hi);
            if rlo > 0.0 {
                continue;
            }
            if rhi < 0.0 {
                push(a, b, &mut out);
                continue;
            }
            if b - a > 1e-10 * (1.0 + a.abs().max(b.abs())) && budget > 0 {
                let m = 0.5 * (a + b);
                stack.push((m, b));
                stack.push((a, m));
                continue;
            }
            let (fa, fb) = (self.value(pa), self.value(pb));
            match (fa <= 0.0, fb <= 0.0) {
                (true, true) => push(a, b, &mut out),
                (false, false) => {}
                (inside_a, _) => {
                    let (mut x, mut y) = (a, b);
                    for _ in 0..80 {
                        let m = 0.5 * (x + y);
                        if m <= x || m >= y {
                            break;
                        }
                        if (self.value(at(m)) <= 0.0) == inside_a {
                            x = m;
                        } else {
                            y = m;
                        }
                    }
                    if inside_a {
                        push(a, x, &mut out);
                    } else {
                        push(y, b, &mut out);
                    }
                }
            }
        }
        out
    }
}
