//! The bounds of a shape texture's field over a box (`texture.rs`, module header: the mipmap
//! bound and the Lipschitz bound, intersected), from each carrier's coordinate ranges.

use super::texture::{dot, norm, sub, CarrierGeom, Texture};
use crate::heightmap::minmax_mipmap::MinMaxMipmap;
use std::f64::consts::PI;

impl Texture {
    /// (low, high) containing F over the box [lo, hi] (both bounds of the module header).
    pub fn range(&self, lo: [f64; 3], hi: [f64; 3]) -> (f64, f64) {
        let c: [f64; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
        let e: [f64; 3] = std::array::from_fn(|k| 0.5 * (hi[k] - lo[k]));
        let (dl, dh, (xl, xh), (yl, yh), grad) = self.box_coords(c, e);
        let (hmax, hmin) = self.sample_range(xl, xh, yl, yh);
        // Rounding: a hair of slack relative to the magnitudes involved.
        let slack = 1e-12 * (norm(c) + norm(e) + hmax.abs().max(hmin.abs()) as f64 + 1.0);
        let mip = (dl - hmax as f64 - slack, dh - hmin as f64 + slack);
        let r = norm(e);
        let l = 1.0 + grad;
        let f = self.value(c);
        (mip.0.max(f - l * r - slack), mip.1.min(f + l * r + slack))
    }

    /// The largest and smallest sample over continuous sample coordinates [xl, xh] × [yl, yh]
    /// (the samples a bilinear value there interpolates).
    fn sample_range(&self, xl: f64, xh: f64, yl: f64, yh: f64) -> (f32, f32) {
        self.ranged(&self.mip, xl, xh, yl, yh)
    }

    /// (max, min) of `mip`'s samples over continuous sample coordinates (clamped, or wrapped
    /// along x on a sphere).
    fn ranged(&self, mip: &MinMaxMipmap, xl: f64, xh: f64, yl: f64, yh: f64) -> (f32, f32) {
        let (w, h) = (self.width, self.height);
        let clampi = |v: f64, n: usize| v.clamp(0.0, (n - 1) as f64) as usize;
        let ys = (clampi(yl.floor(), h), clampi(yh.ceil(), h));
        if !self.wraps() {
            let xs = (clampi(xl.floor(), w), clampi(xh.ceil(), w));
            return mip.sample_range(xs, ys);
        }
        let (x0, x1) = (xl.floor(), xh.ceil());
        if x1 - x0 >= (w - 1) as f64 || x1.is_nan() || x0.is_nan() {
            return mip.sample_range((0, w - 1), ys);
        }
        let a = x0.rem_euclid(w as f64) as usize;
        let b = a + (x1 - x0) as usize;
        if b < w {
            mip.sample_range((a, b), ys)
        } else {
            let (h1, l1) = mip.sample_range((a, w - 1), ys);
            let (h2, l2) = mip.sample_range((0, b - w), ys);
            (h1.max(h2), l1.min(l2))
        }
    }

    /// The largest sample differences along x and y over the patches that continuous sample
    /// coordinates [xs] × [ys] touch.
    fn slopes(&self, xs: (f64, f64), ys: (f64, f64)) -> [f64; 2] {
        // A patch's slope involves its sample and the next: widen the ranges by one sample.
        let pad = |r: (f64, f64)| (r.0 - 1.0, r.1 + 1.0);
        let (xs, ys) = (pad(xs), pad(ys));
        [0, 1].map(|k| self.ranged(&self.slope_mip[k], xs.0, xs.1, ys.0, ys.1).0 as f64)
    }

    /// The continuous sample x range of the angle atan2(z, x) over the xz-rectangle of [lo, hi]
    /// (relative to the axis, which the rectangle must not contain): the extremes are at its
    /// corners.
    fn angle_range(&self, lo: [f64; 3], hi: [f64; 3]) -> (f64, f64) {
        let mid = (0.5 * (lo[2] + hi[2])).atan2(0.5 * (lo[0] + hi[0]));
        let (mut a, mut b) = (f64::INFINITY, f64::NEG_INFINITY);
        for (x, z) in [
            (lo[0], lo[2]),
            (lo[0], hi[2]),
            (hi[0], lo[2]),
            (hi[0], hi[2]),
        ] {
            let d = (z.atan2(x) - mid + PI).rem_euclid(2.0 * PI) - PI;
            a = a.min(d);
            b = b.max(d);
        }
        let k = self.width as f64 / (2.0 * PI);
        ((mid + a + PI) * k - 0.5, (mid + b + PI) * k - 0.5)
    }

    /// Over the box c ± e: D's range, X's and Y's ranges, and a bound of |∇h|.
    #[allow(clippy::type_complexity)]
    fn box_coords(&self, c: [f64; 3], e: [f64; 3]) -> (f64, f64, (f64, f64), (f64, f64), f64) {
        match self.carrier {
            CarrierGeom::Plane {
                origin,
                u,
                v,
                n,
                scale,
            } => {
                let q = sub(c, origin);
                let span = |a: [f64; 3]| (0..3).map(|k| a[k].abs() * e[k]).sum::<f64>();
                let (dc, dr) = (dot(n, q), span(n));
                let (xc, xr) = (dot(u, q) * scale[0], span(u) * scale[0]);
                let (yc, yr) = (dot(v, q) * scale[1], span(v) * scale[1]);
                let (xs, ys) = ((xc - xr, xc + xr), (yc - yr, yc + yr));
                let [sx, sy] = self.slopes(xs, ys);
                (dc - dr, dc + dr, xs, ys, sx * scale[0] + sy * scale[1])
            }
            CarrierGeom::Sphere { centre, radius } => {
                let lo = sub(sub(c, e), centre);
                let hi = sub([c[0] + e[0], c[1] + e[1], c[2] + e[2]], centre);
                let near: [f64; 3] = std::array::from_fn(|k| 0.0f64.clamp(lo[k], hi[k]));
                let far: [f64; 3] = std::array::from_fn(|k| lo[k].abs().max(hi[k].abs()));
                let (dmin, dmax) = (norm(near), norm(far));
                let all_x = (-1.0, self.width as f64);
                let all_y = (-1.0, self.height as f64);
                // Distance to the polar axis over the box (xz-rectangle).
                let axis = (near[0] * near[0] + near[2] * near[2]).sqrt();
                let (xs, ys, grad) = if dmin <= 0.0 {
                    (all_x, all_y, f64::INFINITY)
                } else {
                    let xs = if axis <= 0.0 {
                        all_x
                    } else {
                        self.angle_range(lo, hi)
                    };
                    let smax = if hi[1] > 0.0 {
                        hi[1] / dmin
                    } else {
                        hi[1] / dmax
                    };
                    let smin = if lo[1] < 0.0 {
                        lo[1] / dmin
                    } else {
                        lo[1] / dmax
                    };
                    let (lat_hi, lat_lo) =
                        (smax.clamp(-1.0, 1.0).asin(), smin.clamp(-1.0, 1.0).asin());
                    let k = self.height as f64 / PI;
                    let ys = ((0.5 * PI - lat_hi) * k - 0.5, (0.5 * PI - lat_lo) * k - 0.5);
                    let grad = if axis > 0.0 {
                        let [sx, sy] = self.slopes(xs, ys);
                        sx * self.width as f64 / (2.0 * PI * axis)
                            + sy * self.height as f64 / (PI * dmin)
                    } else {
                        f64::INFINITY
                    };
                    (xs, ys, grad)
                };
                curved(dmin - radius, dmax - radius, xs, ys, grad)
            }
            CarrierGeom::Cylinder {
                base,
                radius,
                scale_y,
            } => {
                let lo = sub(sub(c, e), base);
                let hi = sub([c[0] + e[0], c[1] + e[1], c[2] + e[2]], base);
                // Distances to the axis over the box's xz-rectangle.
                let near = [0.0f64.clamp(lo[0], hi[0]), 0.0f64.clamp(lo[2], hi[2])];
                let far = [lo[0].abs().max(hi[0].abs()), lo[2].abs().max(hi[2].abs())];
                let dmin = (near[0] * near[0] + near[1] * near[1]).sqrt();
                let dmax = (far[0] * far[0] + far[1] * far[1]).sqrt();
                let ys = (lo[1] * scale_y, hi[1] * scale_y);
                let (xs, grad) = if dmin <= 0.0 {
                    ((-1.0, self.width as f64), f64::INFINITY)
                } else {
                    let xs = self.angle_range(lo, hi);
                    let [sx, sy] = self.slopes(xs, ys);
                    (
                        xs,
                        sx * self.width as f64 / (2.0 * PI * dmin) + sy * scale_y,
                    )
                };
                curved(dmin - radius, dmax - radius, xs, ys, grad)
            }
        }
    }
}

/// A curved carrier's box coordinates, the sample ranges padded by a hundredth of a sample
/// (slack for the angle arithmetic).
fn curved(
    dl: f64,
    dh: f64,
    xs: (f64, f64),
    ys: (f64, f64),
    grad: f64,
) -> (f64, f64, (f64, f64), (f64, f64), f64) {
    let pad = 0.01;
    (
        dl,
        dh,
        (xs.0 - pad, xs.1 + pad),
        (ys.0 - pad, ys.1 + pad),
        grad,
    )
}
