//! Real roots of a polynomial of degree ≤ 6 on an interval, isolated by its derivatives
//! (Yuksel 2022, "High-Performance Polynomial Root Finding for Graphics", the exact variant):
//! the roots of `p′` split `[a, b]` into pieces on which `p` is monotone, so each piece holds
//! at most one root, and it holds one exactly when `p` changes sign over it — a bracket that
//! safeguarded Newton–bisection then narrows to full f64 precision. The derivative's roots come
//! from the same procedure one degree lower, down to the closed-form quadratic.
//!
//! Certification: a sign change is a certified root (the bracket is exact), a critical point
//! where `|p|` is within the rounding bound of Horner's rule (`4·n·ε·Σ|pₖ||x|ᵏ`) is reported as a
//! double root (a tangent touch): there `p` cannot be told from 0 in f64. Nothing else is a root.
//!
//! Coefficients are lowest degree first: `p(x) = Σ pₖ xᵏ`.

/// A polynomial of degree ≤ 6, lowest degree first.
pub type Poly = [f64; 7];

/// `p(x)` by Horner's rule.
#[inline]
pub fn eval(p: &[f64], x: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

/// A bound on the rounding error of [`eval`] at `x`.
#[inline]
fn eval_error(p: &[f64], x: f64) -> f64 {
    let ax = x.abs();
    let abs = p.iter().rev().fold(0.0, |acc: f64, &c| acc * ax + c.abs());
    4.0 * p.len() as f64 * f64::EPSILON * abs
}

/// `(α s² + β s + γ)³` added to `out` times `w`.
pub fn add_cube(out: &mut Poly, q: [f64; 3], w: f64) {
    let [a, b, c] = q;
    // (a s² + b s + c)² = a² s⁴ + 2ab s³ + (b² + 2ac) s² + 2bc s + c²
    let sq = [c * c, 2.0 * b * c, b * b + 2.0 * a * c, 2.0 * a * b, a * a];
    let quad = [c, b, a];
    for (i, &s) in sq.iter().enumerate() {
        for (j, &t) in quad.iter().enumerate() {
            out[i + j] += w * s * t;
        }
    }
}

/// All real roots of `p` in `[a, b]`, ascending, appended to `out` (double roots once).
pub fn roots_in(p: &[f64], a: f64, b: f64, out: &mut Vec<f64>) {
    let mut deg = p.len();
    while deg > 0 && p[deg - 1] == 0.0 {
        deg -= 1;
    }
    let p = &p[..deg];
    match deg {
        0 | 1 => {}
        2 => {
            let x = -p[0] / p[1];
            if (a..=b).contains(&x) {
                out.push(x);
            }
        }
        3 => quadratic(p[2], p[1], p[0], a, b, out),
        _ => {
            let mut dp = [0.0; 6];
            for k in 1..deg {
                dp[k - 1] = k as f64 * p[k];
            }
            let mut crit = Vec::with_capacity(deg);
            roots_in(&dp[..deg - 1], a, b, &mut crit);
            let mut x0 = a;
            let mut v0 = eval(p, a);
            if v0 == 0.0 {
                out.push(a);
            }
            for &x1 in crit.iter().chain(std::iter::once(&b)) {
                let v1 = eval(p, x1);
                let last = out.last().copied();
                if v1 == 0.0 {
                    if last != Some(x1) {
                        out.push(x1);
                    }
                } else if v0 != 0.0 && (v0 < 0.0) != (v1 < 0.0) {
                    out.push(bracketed(p, x0, x1, v0));
                } else if x1 < b && v1.abs() <= eval_error(p, x1) && last != Some(x1) {
                    // A critical point indistinguishable from zero: a tangent touch.
                    out.push(x1);
                }
                x0 = x1;
                v0 = v1;
            }
        }
    }
}

/// Roots of `a x² + b x + c` in `[lo, hi]`, the stable way (no cancellation).
fn quadratic(a: f64, b: f64, c: f64, lo: f64, hi: f64, out: &mut Vec<f64>) {
    let disc = b * b - 4.0 * a * c;
    let scale = (b * b).max((4.0 * a * c).abs());
    let mut push = |x: f64| {
        if (lo..=hi).contains(&x) {
            out.push(x);
        }
    };
    if disc < 0.0 {
        if -disc <= 4.0 * f64::EPSILON * scale {
            push(-b / (2.0 * a));
        }
        return;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    let (mut r0, mut r1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    if r0 > r1 {
        std::mem::swap(&mut r0, &mut r1);
    }
    push(r0);
    if r1 != r0 {
        push(r1);
    }
}

/// The root of `p` in `[x0, x1]` where `p(x0) = v0` and `p(x1)` have opposite signs.
fn bracketed(p: &[f64], mut x0: f64, mut x1: f64, v0: f64) -> f64 {
    let neg0 = v0 < 0.0;
    let mut x = 0.5 * (x0 + x1);
    for _ in 0..200 {
        let v = eval(p, x);
        if v == 0.0 {
            return x;
        }
        if (v < 0.0) == neg0 {
            x0 = x;
        } else {
            x1 = x;
        }
        // Newton from x, kept only if it stays strictly inside the bracket.
        let dv = p
            .iter()
            .enumerate()
            .skip(1)
            .rev()
            .fold(0.0, |acc, (k, &c)| acc * x + k as f64 * c);
        let nx = x - v / dv;
        x = if nx > x0 && nx < x1 {
            nx
        } else {
            0.5 * (x0 + x1)
        };
        if x1 - x0 <= 2.0 * f64::EPSILON * x0.abs().max(x1.abs()) {
            break;
        }
        if x == x0 || x == x1 {
            break;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_roots(rs: &[f64]) -> Vec<f64> {
        let mut p = vec![1.0];
        for &r in rs {
            let mut q = vec![0.0; p.len() + 1];
            for (i, &c) in p.iter().enumerate() {
                q[i + 1] += c;
                q[i] -= r * c;
            }
            p = q;
        }
        p
    }

    #[test]
    fn finds_distinct_roots_of_a_sextic() {
        let rs = [-2.5, -1.0, 0.1, 0.7, 1.9, 3.0];
        let mut out = Vec::new();
        roots_in(&from_roots(&rs), -10.0, 10.0, &mut out);
        assert_eq!(out.len(), 6, "{out:?}");
        for (a, b) in out.iter().zip(rs) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn reports_a_double_root_once() {
        let mut out = Vec::new();
        roots_in(&from_roots(&[0.5, 0.5, 2.0, 3.0]), -5.0, 5.0, &mut out);
        assert_eq!(out.len(), 3, "{out:?}");
        assert!((out[0] - 0.5).abs() < 1e-7);
    }

    #[test]
    fn cube_expansion_matches_direct_evaluation() {
        let mut p = [0.0; 7];
        add_cube(&mut p, [0.3, -1.2, 0.7], -2.0);
        for x in [-3.0, -0.2, 0.0, 1.1, 2.5] {
            let q: f64 = 0.3 * x * x - 1.2 * x + 0.7;
            assert!((eval(&p, x) + 2.0 * q.powi(3)).abs() < 1e-10);
        }
    }
}
