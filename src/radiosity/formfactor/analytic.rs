//! Closed-form configuration factors (J. R. Howell, *A Catalog of Radiation Heat Transfer
//! Configuration Factors*), the references the estimators are tested and measured against.

use std::f64::consts::PI;

/// C-11: between identical, parallel, directly opposed rectangles `a × b` at distance `c`.
pub fn parallel_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    2.0 / (PI * x * y)
        * ((((1.0 + x2) * (1.0 + y2)) / (1.0 + x2 + y2)).sqrt().ln()
            + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
            + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
            - x * x.atan()
            - y * y.atan())
}

/// C-14: from a rectangle of width `w` to a perpendicular rectangle of height `h`, sharing an
/// edge of length `l`.
pub fn perpendicular_rectangles(w: f64, h: f64, l: f64) -> f64 {
    let (hh, ww) = (h / l, w / l);
    let (h2, w2) = (hh * hh, ww * ww);
    let s = (h2 + w2).sqrt();
    let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
    let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
    let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
    1.0 / (PI * ww)
        * (ww * (1.0 / ww).atan() + hh * (1.0 / hh).atan() - s * (1.0 / s).atan()
            + 0.25 * (a * b * c).ln())
}

/// From a disc of radius `r1` to a coaxial parallel disc of radius `r2` at distance `h`.
pub fn coaxial_discs(r1: f64, r2: f64, h: f64) -> f64 {
    let (a, b) = (r1 / h, r2 / h);
    let x = 1.0 + (1.0 + b * b) / (a * a);
    0.5 * (x - (x * x - 4.0 * (b / a) * (b / a)).sqrt())
}

/// B-3: from a differential planar element to a parallel rectangle `a × b` at distance `c`, the
/// element's normal passing through a corner of the rectangle.
pub fn element_to_corner_rectangle(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    1.0 / (2.0 * PI) * (x / sx * (y / sx).atan() + y / sy * (x / sy).atan())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        // Adjacent faces of a cube: 0.20004; opposite faces: 0.19982.
        assert!((perpendicular_rectangles(1.0, 1.0, 1.0) - 0.20004).abs() < 1e-5);
        assert!((parallel_rectangles(1.0, 1.0, 1.0) - 0.19982).abs() < 1e-5);
        // Unit discs one radius apart: 0.38197 (= (3 − √5) / 2).
        assert!((coaxial_discs(1.0, 1.0, 1.0) - 0.381966).abs() < 1e-6);
        // A corner element under an infinite quadrant sees a quarter of the hemisphere's cosine.
        assert!((element_to_corner_rectangle(1e6, 1e6, 1.0) - 0.25).abs() < 1e-5);
        // Row sum of a cube face: 4 × adjacent + opposite = 1.
        let sum =
            4.0 * perpendicular_rectangles(1.0, 1.0, 1.0) + parallel_rectangles(1.0, 1.0, 1.0);
        assert!((sum - 1.0).abs() < 1e-9, "{sum}");
    }
}
