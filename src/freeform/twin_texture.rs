//! The f32 twin of `shaders/freeform_texture.wgsl`: shape textures ([`super::texture`]) as the
//! kernel reads, evaluates and bounds them, operation for operation.
//!
//! **Record.** A texture is a run of 32-bit words after the CSG program in the kernel's `ops`
//! buffer (floats by bit pattern), at the word offset its leaf names (`range[3]`, relative to
//! the end of the program; `range[2] = 1` marks a textured leaf):
//!
//! | words | content |
//! |---|---|
//! | 0–3 | kind (0 plane, 1 sphere, 2 cylinder), width, height, mip levels L |
//! | 4–7 | offsets (from the record's start) of the heights, the height mip, the x- and y-slope mips |
//! | 8–11 | plane origin, sphere centre or cylinder base (eye-relative); radius |
//! | 12–15, 16–19, 20–23 | plane u, v, n (unit) with samples per world unit along u and v (19: a cylinder's rows per unit) |
//! | 24–27 | the largest and smallest height, the largest x and y sample differences |
//! | 28… | per mip level: texel offset, width, height |
//!
//! **Bound** over an f32 box: the two bounds of [`super::texture::Texture::range`] (the min/max
//! mipmap, Lipschitz about the centre), intersected, each **widened** so that it contains the
//! exact range over the box:
//! - the mipmap is read at the level whose blocks cover the box's samples in two per axis
//!   (`firstLeadingBit`, no loop — lavapipe bounds a shader's loop iterations), a level no finer
//!   than the CPU's, so the range is never tighter; heights are f32 already, exact;
//! - distances and coordinates carry `KR = 2⁻²⁰` relative slack per operation group (f32
//!   rounding is 2⁻²⁴ per operation; `sqrt` is within 3 ulps in Vulkan);
//! - sample coordinates are padded by 0.02 samples plus, on a sphere, four times WGSL's
//!   accuracy of `atan2`/`asin` (4096 ulps of an angle below 4: 2⁻¹⁰ rad) in samples, and the
//!   Lipschitz centre value by the largest sample difference times that pad.
//!
//! The kernel's `atan2`/`asin` are not libm's, so on a sphere the GPU and this twin agree to
//! the pad, not bit for bit; on a plane they run the same operations.

use super::texture::{CarrierGeom, Texture};
use std::f32::consts::PI;

const KR: f32 = 9.536_743e-7; // 2^-20
const TINY: f32 = 1e-30;
const INF: f32 = 3.0e38;
/// WGSL's `atan2`/`asin` accuracy for angles below 4 (4096 ulps of 2⁻²²), in radians.
const APAD: f32 = 9.765_625e-4; // 2^-10
/// Words before the level table.
const HEAD: usize = 28;

fn f(x: f64) -> u32 {
    (x as f32).to_bits()
}

/// Append `t`'s record (eye-relative) to `words`; returns its offset.
pub fn append(t: &Texture, eye: [f64; 3], words: &mut Vec<u32>) -> u32 {
    let slopes = t.slope_mips();
    let start = words.len();
    let levels = &t.mip.levels;
    let mut rec = vec![0u32; HEAD + 3 * levels.len()];
    rec[1] = t.width as u32;
    rec[2] = t.height as u32;
    rec[3] = levels.len() as u32;
    match t.carrier {
        CarrierGeom::Plane {
            origin,
            u,
            v,
            n,
            scale,
        } => {
            for k in 0..3 {
                rec[8 + k] = f(origin[k] - eye[k]);
                rec[12 + k] = f(u[k]);
                rec[16 + k] = f(v[k]);
                rec[20 + k] = f(n[k]);
            }
            rec[15] = f(scale[0]);
            rec[19] = f(scale[1]);
        }
        CarrierGeom::Sphere { centre, radius } => {
            rec[0] = 1;
            for k in 0..3 {
                rec[8 + k] = f(centre[k] - eye[k]);
            }
            rec[11] = f(radius);
        }
        CarrierGeom::Cylinder {
            base,
            radius,
            scale_y,
        } => {
            rec[0] = 2;
            for k in 0..3 {
                rec[8 + k] = f(base[k] - eye[k]);
            }
            rec[11] = f(radius);
            rec[19] = f(scale_y);
        }
    }
    rec[24] = t.mip.max_height.to_bits();
    rec[25] = t.mip.min_height.to_bits();
    rec[26] = slopes[0].max_height.to_bits();
    rec[27] = slopes[1].max_height.to_bits();
    for (i, l) in levels.iter().enumerate() {
        rec[HEAD + 3 * i] = l.offset as u32;
        rec[HEAD + 3 * i + 1] = l.width as u32;
        rec[HEAD + 3 * i + 2] = l.height as u32;
    }
    let data = |v: &[f32], slot: usize, rec: &mut Vec<u32>| {
        rec[slot] = rec.len() as u32;
        rec.extend(v.iter().map(|x| x.to_bits()));
    };
    data(&t.heights, 4, &mut rec);
    data(&t.mip.data, 5, &mut rec);
    data(&slopes[0].data, 6, &mut rec);
    data(&slopes[1].data, 7, &mut rec);
    words.extend(rec);
    start as u32
}

/// A record, read as the kernel reads it.
struct Rec<'a> {
    w: &'a [u32],
}

impl Rec<'_> {
    fn u(&self, i: usize) -> u32 {
        self.w[i]
    }
    fn f(&self, i: usize) -> f32 {
        f32::from_bits(self.w[i])
    }
    fn v3(&self, i: usize) -> [f32; 3] {
        [self.f(i), self.f(i + 1), self.f(i + 2)]
    }
    /// 0 plane, 1 sphere, 2 cylinder (the last two wrap along x).
    fn kind(&self) -> u32 {
        self.u(0)
    }
    fn dims(&self) -> (u32, u32) {
        (self.u(1), self.u(2))
    }
    fn height(&self, i: u32, j: u32) -> f32 {
        let (w, _) = self.dims();
        self.f(self.u(4) as usize + (j * w + i) as usize)
    }

    /// (max, min) of mip `m` (5 heights, 6 and 7 slopes) over samples [x0, x1] × [y0, y1]
    /// (clamped already, x0 ≤ x1, y0 ≤ y1).
    fn mip_range(&self, m: usize, x: (u32, u32), y: (u32, u32)) -> (f32, f32) {
        let span = (x.1 - x.0).max(y.1 - y.0);
        let l = if span <= 1 {
            0
        } else {
            31 - (span - 1).leading_zeros()
        };
        if l >= self.u(3) {
            return match m {
                5 => (self.f(24), self.f(25)),
                _ => (self.f(20 + m), 0.0),
            };
        }
        let lt = HEAD + 3 * l as usize;
        let (off, lw, lh) = (self.u(lt), self.u(lt + 1), self.u(lt + 2));
        let b = 2u32 << l;
        let (bx0, bx1) = (x.0 / b, (x.1 / b).min(lw - 1));
        let (by0, by1) = (y.0 / b, (y.1 / b).min(lh - 1));
        let base = self.u(m) as usize;
        let texel = |bx: u32, by: u32| -> (f32, f32) {
            let i = base + 2 * (off + by * lw + bx) as usize;
            (self.f(i), self.f(i + 1))
        };
        let (a, b2, c, d) = (
            texel(bx0, by0),
            texel(bx1, by0),
            texel(bx0, by1),
            texel(bx1, by1),
        );
        (
            a.0.max(b2.0).max(c.0.max(d.0)),
            a.1.min(b2.1).min(c.1.min(d.1)),
        )
    }

    /// (max, min) of mip `m` over continuous sample coordinates (clamped, or wrapped along x
    /// on a sphere); the whole map for NaN coordinates.
    fn ranged(&self, m: usize, xl: f32, xh: f32, yl: f32, yh: f32) -> (f32, f32) {
        let (w, h) = self.dims();
        let clampi = |v: f32, n: u32| v.clamp(0.0, (n - 1) as f32) as u32;
        if xl.is_nan() || xh.is_nan() || yl.is_nan() || yh.is_nan() {
            return self.mip_range(m, (0, w - 1), (0, h - 1));
        }
        let ys = (
            clampi(yl.floor(), h),
            clampi(yh.ceil(), h).max(clampi(yl.floor(), h)),
        );
        if self.kind() == 0 {
            let x0 = clampi(xl.floor(), w);
            return self.mip_range(m, (x0, clampi(xh.ceil(), w).max(x0)), ys);
        }
        let (x0, x1) = (xl.floor(), xh.ceil());
        if x1 - x0 >= (w - 1) as f32 {
            return self.mip_range(m, (0, w - 1), ys);
        }
        let a = wrap(x0, w as f32).clamp(0.0, (w - 1) as f32) as u32;
        let b = a + (x1 - x0) as u32;
        if b < w {
            return self.mip_range(m, (a, b), ys);
        }
        let (h1, l1) = self.mip_range(m, (a, w - 1), ys);
        let (h2, l2) = self.mip_range(m, (0, b - w), ys);
        (h1.max(h2), l1.min(l2))
    }

    /// The bilinear height at continuous sample coordinates.
    fn height_at(&self, x: f32, y: f32) -> f32 {
        let (w, h) = self.dims();
        let y = y.clamp(0.0, (h - 1) as f32);
        let j = (y.floor() as u32).min(h - 2);
        let fy = y - j as f32;
        let (i0, i1, fx) = if self.kind() != 0 {
            let x = wrap(x, w as f32);
            let i = (x.floor() as u32).min(w - 1);
            (i, (i + 1) % w, x - i as f32)
        } else {
            let x = x.clamp(0.0, (w - 1) as f32);
            let i = (x.floor() as u32).min(w - 2);
            (i, i + 1, x - i as f32)
        };
        let top = self.height(i0, j) + fx * (self.height(i1, j) - self.height(i0, j));
        let bottom =
            self.height(i0, j + 1) + fx * (self.height(i1, j + 1) - self.height(i0, j + 1));
        top + fy * (bottom - top)
    }

    /// (D, X, Y) at p.
    fn coords(&self, p: [f32; 3]) -> (f32, f32, f32) {
        let o = self.v3(8);
        let q = sub(p, o);
        if self.kind() == 0 {
            return (
                dot(self.v3(20), q),
                dot(self.v3(12), q) * self.f(15),
                dot(self.v3(16), q) * self.f(19),
            );
        }
        let (w, h) = self.dims();
        if self.kind() == 2 {
            return (
                (q[0] * q[0] + q[2] * q[2]).sqrt() - self.f(11),
                (q[2].atan2(q[0]) + PI) / (2.0 * PI) * w as f32 - 0.5,
                q[1] * self.f(19),
            );
        }
        let rho = norm(q);
        let lon = q[2].atan2(q[0]);
        let lat = if rho > 0.0 {
            (q[1] / rho).clamp(-1.0, 1.0).asin()
        } else {
            0.0
        };
        (
            rho - self.f(11),
            (lon + PI) / (2.0 * PI) * w as f32 - 0.5,
            (0.5 * PI - lat) / PI * h as f32 - 0.5,
        )
    }
}

/// `x mod m` in [0, m) as the kernel computes it (`x − m·floor(x / m)`).
fn wrap(x: f32, m: f32) -> f32 {
    x - m * (x / m).floor()
}

fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: [f32; 3]) -> f32 {
    dot(a, a).sqrt()
}
fn norm1(a: [f32; 3]) -> f32 {
    a[0].abs() + a[1].abs() + a[2].abs()
}

/// `F(p)` of the record at `words[at..]` (p eye-relative).
pub fn value32(words: &[u32], at: usize, p: [f32; 3]) -> f32 {
    let r = Rec { w: &words[at..] };
    let (d, x, y) = r.coords(p);
    d - r.height_at(x, y)
}

/// `∇F(p)` by central differences a hundredth of a sample apart.
pub fn gradient32(words: &[u32], at: usize, p: [f32; 3]) -> [f32; 3] {
    let r = Rec { w: &words[at..] };
    let (w, h) = r.dims();
    let q = sub(p, r.v3(8));
    let spacing = match r.kind() {
        0 => 1.0 / r.f(15).max(r.f(19)),
        1 => norm(q).max(r.f(11) * 1e-6) * PI / (h.max(w / 2) as f32),
        _ => {
            let axis = (q[0] * q[0] + q[2] * q[2]).sqrt().max(r.f(11) * 1e-6);
            (axis * 2.0 * PI / w as f32).min(1.0 / r.f(19))
        }
    };
    let step = 0.01 * spacing;
    std::array::from_fn(|k| {
        let (mut a, mut b) = (p, p);
        a[k] += step;
        b[k] -= step;
        (value32(words, at, a) - value32(words, at, b)) / (a[k] - b[k])
    })
}

/// The widened range of `F` over the box [lo, hi] (eye-relative).
pub fn range32(words: &[u32], at: usize, lo: [f32; 3], hi: [f32; 3]) -> (f32, f32) {
    let r = Rec { w: &words[at..] };
    let c: [f32; 3] = std::array::from_fn(|k| 0.5 * (lo[k] + hi[k]));
    let e: [f32; 3] = std::array::from_fn(|k| {
        let e = 0.5 * (hi[k] - lo[k]);
        e + KR * (c[k].abs() + e) + TINY
    });
    let o = r.v3(8);
    let (w, h) = (r.dims().0 as f32, r.dims().1 as f32);
    // (D range, X range, Y range, |∇h| bound, pads of X and Y in samples)
    let (dl, dh, xs, ys, grad, pad) = if r.kind() == 0 {
        let q = sub(c, o);
        let span = |a: [f32; 3]| a[0].abs() * e[0] + a[1].abs() * e[1] + a[2].abs() * e[2];
        let (n, u, v) = (r.v3(20), r.v3(12), r.v3(16));
        let (sx, sy) = (r.f(15), r.f(19));
        let mag = norm1(c) + norm1(o);
        let (dc, dr) = (dot(n, q), span(n));
        let ds = KR * (mag + dr) + TINY;
        let (xc, xr) = (dot(u, q) * sx, span(u) * sx);
        let (yc, yr) = (dot(v, q) * sy, span(v) * sy);
        let px = 0.02 + KR * (xc.abs() + xr + mag * sx);
        let py = 0.02 + KR * (yc.abs() + yr + mag * sy);
        let xs = (xc - xr - px, xc + xr + px);
        let ys = (yc - yr - py, yc + yr + py);
        let s = slopes(&r, xs, ys);
        let grad = (s[0] * sx + s[1] * sy) * (1.0 + KR);
        (dc - dr - ds, dc + dr + ds, xs, ys, grad, [px, py])
    } else if r.kind() == 2 {
        let (radius, sy) = (r.f(11), r.f(19));
        let cs = KR * (norm1(c) + norm1(e) + norm1(o)) + TINY;
        let lo_r: [f32; 3] = std::array::from_fn(|k| (c[k] - e[k]) - o[k] - cs);
        let hi_r: [f32; 3] = std::array::from_fn(|k| (c[k] + e[k]) - o[k] + cs);
        let near = [
            0.0f32.clamp(lo_r[0], hi_r[0]),
            0.0f32.clamp(lo_r[2], hi_r[2]),
        ];
        let far = [
            lo_r[0].abs().max(hi_r[0].abs()),
            lo_r[2].abs().max(hi_r[2].abs()),
        ];
        let dmin = (near[0] * near[0] + near[1] * near[1]).sqrt() * (1.0 - KR);
        let dmax = (far[0] * far[0] + far[1] * far[1]).sqrt() * (1.0 + KR);
        let px = 0.02 + 4.0 * APAD * w / (2.0 * PI);
        let py = 0.02 + KR * (lo_r[1].abs() + hi_r[1].abs()) * sy;
        let ys = (lo_r[1] * sy - py, hi_r[1] * sy + py);
        let (xs, grad) = if dmin <= 0.0 {
            ((-1.0 - px, w + px), INF)
        } else {
            let xs = angle_range32(lo_r, hi_r, w, px);
            let s = slopes(&r, xs, ys);
            (xs, (s[0] * w / (2.0 * PI * dmin) + s[1] * sy) * (1.0 + KR))
        };
        curved32(dmin, dmax, radius, xs, ys, grad, [px, py])
    } else {
        let radius = r.f(11);
        let cs = KR * (norm1(c) + norm1(e) + norm1(o)) + TINY;
        let lo_r: [f32; 3] = std::array::from_fn(|k| (c[k] - e[k]) - o[k] - cs);
        let hi_r: [f32; 3] = std::array::from_fn(|k| (c[k] + e[k]) - o[k] + cs);
        let near: [f32; 3] = std::array::from_fn(|k| 0.0f32.clamp(lo_r[k], hi_r[k]));
        let far: [f32; 3] = std::array::from_fn(|k| lo_r[k].abs().max(hi_r[k].abs()));
        let dmin = norm(near) * (1.0 - KR);
        let dmax = norm(far) * (1.0 + KR);
        let px = 0.02 + 4.0 * APAD * w / (2.0 * PI);
        let py = 0.02 + 4.0 * APAD * h / PI;
        let all_x = (-1.0 - px, w + px);
        let all_y = (-1.0 - py, h + py);
        let axis = (near[0] * near[0] + near[2] * near[2]).sqrt() * (1.0 - KR);
        let (xs, ys, grad) = if dmin <= 0.0 {
            (all_x, all_y, INF)
        } else {
            let xs = if axis <= 0.0 {
                all_x
            } else {
                angle_range32(lo_r, hi_r, w, px)
            };
            let up = 1.0 + KR;
            let dn = 1.0 - KR;
            let smax = if hi_r[1] > 0.0 {
                hi_r[1] / (dmin * dn)
            } else {
                hi_r[1] / (dmax * up)
            };
            let smin = if lo_r[1] < 0.0 {
                lo_r[1] / (dmin * dn)
            } else {
                lo_r[1] / (dmax * up)
            };
            let lat_hi = smax.clamp(-1.0, 1.0).asin();
            let lat_lo = smin.clamp(-1.0, 1.0).asin();
            let k = h / PI;
            let ys = (
                (0.5 * PI - lat_hi) * k - 0.5 - py,
                (0.5 * PI - lat_lo) * k - 0.5 + py,
            );
            let grad = if axis > 0.0 {
                let s = slopes(&r, xs, ys);
                (s[0] * w / (2.0 * PI * axis) + s[1] * h / (PI * dmin)) * (1.0 + KR)
            } else {
                INF
            };
            (xs, ys, grad)
        };
        curved32(dmin, dmax, radius, xs, ys, grad, [px, py])
    };
    let (hmax, hmin) = r.ranged(5, xs.0, xs.1, ys.0, ys.1);
    let hmag = hmax.abs().max(hmin.abs());
    let slack = KR * (dl.abs() + dh.abs() + hmag) + TINY;
    let mip = (dl - hmax - slack, dh - hmin + slack);
    // Lipschitz about the centre: the centre's value errs by its rounding and by the
    // coordinates' pad times the largest slope.
    let s = slopes(&r, xs, ys);
    let fc = value32(words, at, c);
    let rad = norm(e) * (1.0 + KR);
    let reach = (1.0 + grad) * rad;
    let fslack =
        s[0] * pad[0] + s[1] * pad[1] + KR * (fc.abs() + norm1(c) + norm1(o) + 4.0 * hmag) + TINY;
    let lip = if reach < INF {
        (fc - reach - fslack, fc + reach + fslack)
    } else {
        (-INF, INF)
    };
    (mip.0.max(lip.0), mip.1.min(lip.1))
}

/// A curved carrier's box coordinates: the distance range to the carrier's surface widened by
/// 2⁻²⁰ of the radius, then as computed.
#[allow(clippy::type_complexity)]
fn curved32(
    dmin: f32,
    dmax: f32,
    radius: f32,
    xs: (f32, f32),
    ys: (f32, f32),
    grad: f32,
    pad: [f32; 2],
) -> (f32, f32, (f32, f32), (f32, f32), f32, [f32; 2]) {
    let rs = KR * radius + TINY;
    (dmin - radius - rs, dmax - radius + rs, xs, ys, grad, pad)
}

/// The continuous sample x range (padded by `px`) of atan2(z, x) over the xz-rectangle of
/// [lo, hi], which does not contain the axis: the extremes are at its corners.
fn angle_range32(lo: [f32; 3], hi: [f32; 3], w: f32, px: f32) -> (f32, f32) {
    let mid = (0.5 * (lo[2] + hi[2])).atan2(0.5 * (lo[0] + hi[0]));
    let corner = |x: f32, z: f32| wrap(z.atan2(x) - mid + PI, 2.0 * PI) - PI;
    let d = [
        corner(lo[0], lo[2]),
        corner(lo[0], hi[2]),
        corner(hi[0], lo[2]),
        corner(hi[0], hi[2]),
    ];
    let (a, b) = (
        d[0].min(d[1]).min(d[2].min(d[3])),
        d[0].max(d[1]).max(d[2].max(d[3])),
    );
    let k = w / (2.0 * PI);
    ((mid + a + PI) * k - 0.5 - px, (mid + b + PI) * k - 0.5 + px)
}

/// The largest sample differences along x and y over the patches the coordinates touch.
fn slopes(r: &Rec, xs: (f32, f32), ys: (f32, f32)) -> [f32; 2] {
    let (x0, x1, y0, y1) = (xs.0 - 1.0, xs.1 + 1.0, ys.0 - 1.0, ys.1 + 1.0);
    [r.ranged(6, x0, x1, y0, y1).0, r.ranged(7, x0, x1, y0, y1).0]
}
