//! Shape textures, compiled: a carrier quadric (plane, sphere or cylinder) displaced along its
//! unit normal
//! by the bilinear interpolation of a height grid (docs/freeform.md, "Shape textures").
//!
//! The field is `F(p) = D(p) − h(X(p), Y(p))`: `D` the signed distance to the carrier (exact for
//! these three), `(X, Y)` continuous sample coordinates of the carrier's parameterisation
//! (plane: projections on its axes; sphere: longitude and latitude, equirectangular; cylinder:
//! angle and height) and `h` the bilinear interpolation of the samples (heights in world units).
//! Solid is where `F < 0`, below the displaced surface.
//!
//! **Bounds** over a box (the multilevel caster's cells, the reference's ray segments), two of
//! them, intersected:
//! - *mipmap*: `[D_min − h_max, D_max − h_min]`, `D`'s exact range over the box and `h`'s from
//!   the min/max mipmap (`heightmap::minmax_mipmap`) over the samples the box's `(X, Y)` range
//!   reaches — a bilinear value lies between its four samples' min and max;
//! - *Lipschitz*: `F(centre) ± L·r`, r the box's half-diagonal and L a bound of |∇F| over it:
//!   `|∇D| ≤ 1` and `|∇h| ≤ S_x·|∇X| + S_y·|∇Y|`, S the largest difference between neighbouring
//!   samples over the box (the slope of a bilinear patch never exceeds its edges'; a mipmap of
//!   the differences gives it per box). The mipmap bound alone
//!   never tightens below the local relief; the Lipschitz bound shrinks with the box, which is
//!   what lets the reference's bisection stop near a crossing.
//!
//! The bounds are in `texture_bounds.rs`, the certified cast along a ray in `texture_cast.rs`.
//!
//! Preconditions: grids of at least 2×2 finite samples, an inline grid (the loader reads
//! files); the sphere's parameterisation is singular at its poles and centre, the cylinder's on
//! its axis, where the bounds fall back to the whole height range. Why these three carriers: the
//! displaced surface has an exact implicit form only where the distance to the carrier and a
//! parameterisation constant along its normals are both closed-form — true of planes, spheres and
//! circular cylinders, not of a general quadric (an ellipsoid's normals cross, its distance is a
//! sextic root).

use crate::error::{Error, Result};
use crate::heightmap::minmax_mipmap::MinMaxMipmap;
use crate::heightmap::HeightMap;
use crate::scene::freeform::{Carrier, HeightGrid, TexturedSurface};
use std::f64::consts::PI;

/// Segments the reference bisects on one ray before it decides the rest by end points.
pub const MAX_SEGMENTS: u32 = 1 << 22;

/// The carrier's geometry in world space.
#[derive(Clone, Debug, PartialEq)]
pub enum CarrierGeom {
    /// Unit axes u, v and normal n = u × v; `scale` = samples per world unit along u and v.
    Plane {
        origin: [f64; 3],
        u: [f64; 3],
        v: [f64; 3],
        n: [f64; 3],
        scale: [f64; 2],
    },
    Sphere {
        centre: [f64; 3],
        radius: f64,
    },
    /// Axis vertical through `base`; `scale_y` = sample rows per world unit along it.
    Cylinder {
        base: [f64; 3],
        radius: f64,
        scale_y: f64,
    },
}

/// A compiled shape texture.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub carrier: CarrierGeom,
    pub width: usize,
    pub height: usize,
    /// Heights in world units, row-major, after level of detail and morph.
    pub heights: Vec<f32>,
    pub mip: MinMaxMipmap,
    /// Per sample, |difference| to the next sample along x and along y, and their mipmaps:
    /// the largest slope of the bilinear patches a box covers.
    pub(super) slope_mip: [MinMaxMipmap; 2],
    from: Vec<f32>,
    to: Option<Vec<f32>>,
}

pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(super) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = norm(a);
    a.map(|x| x / l)
}

/// Box-filter a grid by 2^lod (edge blocks average what exists); at least 2×2 remain.
fn filtered(w: usize, h: usize, v: &[f32], lod: u32) -> (usize, usize, Vec<f32>) {
    let mut k = 1usize << lod;
    while k > 1 && (w.div_ceil(k) < 2 || h.div_ceil(k) < 2) {
        k /= 2;
    }
    if k == 1 {
        return (w, h, v.to_vec());
    }
    let (nw, nh) = (w.div_ceil(k), h.div_ceil(k));
    let mut out = vec![0.0f32; nw * nh];
    for by in 0..nh {
        for bx in 0..nw {
            let (mut s, mut n) = (0.0f64, 0usize);
            for y in by * k..((by + 1) * k).min(h) {
                for x in bx * k..((bx + 1) * k).min(w) {
                    s += v[y * w + x] as f64;
                    n += 1;
                }
            }
            out[by * nw + bx] = (s / n as f64) as f32;
        }
    }
    (nw, nh, out)
}

fn inline(g: &HeightGrid) -> Result<(usize, usize, &[f32])> {
    match g {
        HeightGrid::Grid {
            width,
            height,
            values,
        } => Ok((*width, *height, values)),
        HeightGrid::File { path, .. } => Err(Error::knob(format!(
            "the height grid file {path} was not read (load the scene with load::freeform_scene)"
        ))),
    }
}

impl Texture {
    /// Compile a shape texture at morph parameter 0.
    pub fn compile(t: &TexturedSurface) -> Result<Texture> {
        let (w0, h0, a) = inline(&t.heights)?;
        let scale = |v: &[f32]| -> Vec<f32> {
            v.iter()
                .map(|&x| (x as f64 * t.height_scale) as f32)
                .collect()
        };
        let scaled = scale(a);
        if scaled.iter().any(|v| !v.is_finite()) {
            return Err(Error::knob(format!(
                "heights x height_scale ({}) overflow single precision",
                t.height_scale
            )));
        }
        let (w, h, from) = filtered(w0, h0, &scaled, t.lod);
        let to = match &t.morph_to {
            Some(g) => {
                let (wb, hb, b) = inline(g)?;
                if (wb, hb) != (w0, h0) {
                    return Err(Error::knob(format!(
                        "morph_to is {wb}x{hb}, heights {w0}x{h0}: a morph needs grids of one size"
                    )));
                }
                let scaled = scale(b);
                if scaled.iter().any(|v| !v.is_finite()) {
                    return Err(Error::knob(format!(
                        "morph_to x height_scale ({}) overflows single precision",
                        t.height_scale
                    )));
                }
                Some(filtered(wb, hb, &scaled, t.lod).2)
            }
            None => None,
        };
        let carrier = match t.carrier {
            Carrier::Plane {
                origin,
                u_axis,
                v_axis,
                size,
            } => {
                let (u, v) = (unit(u_axis), unit(v_axis));
                let n = unit([
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ]);
                CarrierGeom::Plane {
                    origin,
                    u,
                    v,
                    n,
                    scale: [(w - 1) as f64 / size[0], (h - 1) as f64 / size[1]],
                }
            }
            Carrier::Sphere { centre, radius } => CarrierGeom::Sphere { centre, radius },
            Carrier::Cylinder {
                base,
                radius,
                length,
            } => CarrierGeom::Cylinder {
                base,
                radius,
                scale_y: (h - 1) as f64 / length,
            },
        };
        let mut tex = Texture {
            carrier,
            width: w,
            height: h,
            heights: Vec::new(),
            mip: MinMaxMipmap::build(&grid_map(w, h, vec![0.0; w * h])),
            slope_mip: [
                MinMaxMipmap::build(&grid_map(w, h, vec![0.0; w * h])),
                MinMaxMipmap::build(&grid_map(w, h, vec![0.0; w * h])),
            ],
            from,
            to,
        };
        tex.set_morph(0.0);
        Ok(tex)
    }

    /// Morph toward the second grid: heights `(1 − s)·a + s·b` (s clamped to [0, 1]); rebuilds
    /// the mipmap and slopes. Without a second grid the heights stay.
    pub fn set_morph(&mut self, s: f64) {
        let s = s.clamp(0.0, 1.0);
        self.heights = match &self.to {
            Some(b) => self
                .from
                .iter()
                .zip(b)
                .map(|(&a, &b)| ((1.0 - s) * a as f64 + s * b as f64) as f32)
                .collect(),
            None => self.from.clone(),
        };
        let (w, h) = (self.width, self.height);
        let hs = &self.heights;
        // Differences rounded up a hair (f32 subtraction rounds), so that they bound the f64
        // slopes of the patches.
        let diff = |a: f32, b: f32| ((b as f64 - a as f64).abs() * (1.0 + 1e-6)) as f32;
        let mut sx = vec![0.0f32; w * h];
        let mut sy = vec![0.0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let c = hs[y * w + x];
                if x + 1 < w || self.wraps() {
                    sx[y * w + x] = diff(c, hs[y * w + (x + 1) % w]);
                }
                if y + 1 < h {
                    sy[y * w + x] = diff(c, hs[(y + 1) * w + x]);
                }
            }
        }
        self.slope_mip = [
            MinMaxMipmap::build(&grid_map(w, h, sx)),
            MinMaxMipmap::build(&grid_map(w, h, sy)),
        ];
        self.mip = MinMaxMipmap::build(&grid_map(w, h, self.heights.clone()));
    }

    /// Whether the texture has a second grid to morph toward.
    pub fn morphs(&self) -> bool {
        self.to.is_some()
    }

    /// The mipmaps of the sample differences along x and along y.
    pub fn slope_mips(&self) -> [&MinMaxMipmap; 2] {
        [&self.slope_mip[0], &self.slope_mip[1]]
    }

    pub(super) fn wraps(&self) -> bool {
        !matches!(self.carrier, CarrierGeom::Plane { .. })
    }

    /// Continuous sample x of the angle atan2(z, x) about a vertical axis.
    fn angle_x(&self, z: f64, x: f64) -> f64 {
        (z.atan2(x) + PI) / (2.0 * PI) * self.width as f64 - 0.5
    }

    /// `(D, X, Y)` at p: signed carrier distance and continuous sample coordinates.
    pub fn coords(&self, p: [f64; 3]) -> (f64, f64, f64) {
        match self.carrier {
            CarrierGeom::Plane {
                origin,
                u,
                v,
                n,
                scale,
            } => {
                let q = sub(p, origin);
                (dot(n, q), dot(u, q) * scale[0], dot(v, q) * scale[1])
            }
            CarrierGeom::Sphere { centre, radius } => {
                let r = sub(p, centre);
                let rho = norm(r);
                let lon = r[2].atan2(r[0]);
                let lat = if rho > 0.0 {
                    (r[1] / rho).clamp(-1.0, 1.0).asin()
                } else {
                    0.0
                };
                (
                    rho - radius,
                    (lon + PI) / (2.0 * PI) * self.width as f64 - 0.5,
                    (0.5 * PI - lat) / PI * self.height as f64 - 0.5,
                )
            }
            CarrierGeom::Cylinder {
                base,
                radius,
                scale_y,
            } => {
                let (r, axis) = axial(p, base);
                (axis - radius, self.angle_x(r[2], r[0]), r[1] * scale_y)
            }
        }
    }

    /// The bilinear height at continuous sample coordinates (x clamped, or wrapped on a
    /// sphere; y clamped).
    pub fn height_at(&self, x: f64, y: f64) -> f64 {
        let (w, h) = (self.width, self.height);
        let y = y.clamp(0.0, (h - 1) as f64);
        let j = (y.floor() as usize).min(h - 2);
        let fy = y - j as f64;
        let (i0, i1, fx) = if self.wraps() {
            let x = x.rem_euclid(w as f64);
            let i = (x.floor() as usize).min(w - 1);
            (i, (i + 1) % w, x - i as f64)
        } else {
            let x = x.clamp(0.0, (w - 1) as f64);
            let i = (x.floor() as usize).min(w - 2);
            (i, i + 1, x - i as f64)
        };
        let s = |i: usize, j: usize| self.heights[j * w + i] as f64;
        let top = s(i0, j) + fx * (s(i1, j) - s(i0, j));
        let bottom = s(i0, j + 1) + fx * (s(i1, j + 1) - s(i0, j + 1));
        top + fy * (bottom - top)
    }

    /// `F(p)`.
    pub fn value(&self, p: [f64; 3]) -> f64 {
        let (d, x, y) = self.coords(p);
        d - self.height_at(x, y)
    }

    /// The surface point at continuous sample coordinates (x, y): the carrier point displaced
    /// by the bilinear height (on a sphere y runs from −0.5, the north pole, to height − 0.5).
    pub fn point_at(&self, x: f64, y: f64) -> [f64; 3] {
        let h = self.height_at(x, y);
        match self.carrier {
            CarrierGeom::Plane {
                origin,
                u,
                v,
                n,
                scale,
            } => {
                let (a, b) = (x / scale[0], y / scale[1]);
                std::array::from_fn(|k| origin[k] + a * u[k] + b * v[k] + h * n[k])
            }
            CarrierGeom::Sphere { centre, radius } => {
                let lon = (x + 0.5) / self.width as f64 * 2.0 * PI - PI;
                let colat = (y + 0.5) / self.height as f64;
                let lat = 0.5 * PI - colat * PI;
                // The poles exactly on the axis (cos(π/2) is not 0 in f64).
                let d = match colat {
                    c if c <= 0.0 => [0.0, 1.0, 0.0],
                    c if c >= 1.0 => [0.0, -1.0, 0.0],
                    _ => [lat.cos() * lon.cos(), lat.sin(), lat.cos() * lon.sin()],
                };
                std::array::from_fn(|k| centre[k] + (radius + h) * d[k])
            }
            CarrierGeom::Cylinder {
                base,
                radius,
                scale_y,
            } => {
                let a = (x + 0.5) / self.width as f64 * 2.0 * PI - PI;
                let r = radius + h;
                [
                    base[0] + r * a.cos(),
                    base[1] + y / scale_y,
                    base[2] + r * a.sin(),
                ]
            }
        }
    }

    /// An upper bound of the distance from p to the (closed) surface: |F(p)| — F is the signed
    /// distance along the carrier's normal to the displaced surface, whose height depends on
    /// the carrier point alone. On a sphere, where the longitudes converge and the surface
    /// folds onto the polar axis (Newton projection fails there), also the distance to the
    /// polar segments and, within two rows of a pole, to the nearest of 17×17 surface points
    /// over ±1 sample around p's coordinates.
    pub fn distance_bound(&self, p: [f64; 3]) -> f64 {
        let mut best = self.value(p).abs();
        if let CarrierGeom::Sphere { centre, radius } = self.carrier {
            // The polar segments: every longitude's surface meets the axis at its pole row's
            // height, so the closure holds the segment of those heights.
            let r = sub(p, centre);
            let off_axis = (r[0] * r[0] + r[2] * r[2]).sqrt();
            for (row, sign) in [(0, 1.0), (self.height - 1, -1.0)] {
                let hs = &self.heights[row * self.width..(row + 1) * self.width];
                let (lo, hi) = hs
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                        (l.min(v as f64), h.max(v as f64))
                    });
                let along = sign * r[1];
                let nearest = along.clamp(radius + lo, radius + hi);
                best = best.min((off_axis * off_axis + (along - nearest).powi(2)).sqrt());
            }
            let (_, x, y) = self.coords(p);
            let h = self.height as f64;
            if y < 2.0 || y > h - 3.0 {
                for i in 0..17 {
                    for j in 0..17 {
                        let yy = (y + (j as f64 - 8.0) / 8.0).clamp(-0.5, h - 0.5);
                        let q = self.point_at(x + (i as f64 - 8.0) / 8.0, yy);
                        best = best.min(norm(sub(p, q)));
                    }
                }
            }
        }
        best
    }

    /// `∇F(p)` by central differences a hundredth of a sample apart (the bilinear surface has
    /// no gradient on sample lines; this gives the one-sided mean there).
    pub fn gradient(&self, p: [f64; 3]) -> [f64; 3] {
        let step = 0.01 * self.sample_spacing(p);
        std::array::from_fn(|k| {
            let (mut a, mut b) = (p, p);
            a[k] += step;
            b[k] -= step;
            (self.value(a) - self.value(b)) / (2.0 * step)
        })
    }

    /// World distance between neighbouring samples near p.
    fn sample_spacing(&self, p: [f64; 3]) -> f64 {
        match self.carrier {
            CarrierGeom::Plane { scale, .. } => 1.0 / scale[0].max(scale[1]),
            CarrierGeom::Sphere { centre, radius } => {
                let rho = norm(sub(p, centre)).max(radius * 1e-6);
                rho * PI / self.height.max(self.width / 2) as f64
            }
            CarrierGeom::Cylinder {
                base,
                radius,
                scale_y,
            } => {
                let rho = axial(p, base).1.max(radius * 1e-6);
                (rho * 2.0 * PI / self.width as f64).min(1.0 / scale_y)
            }
        }
    }
}

/// `p − base` and its distance from the vertical axis through `base`.
pub(super) fn axial(p: [f64; 3], base: [f64; 3]) -> ([f64; 3], f64) {
    let r = sub(p, base);
    (r, (r[0] * r[0] + r[2] * r[2]).sqrt())
}

fn grid_map(w: usize, h: usize, heights: Vec<f32>) -> HeightMap {
    HeightMap {
        width: w,
        height: h,
        heights,
        cell_size: [1.0, 1.0],
        height_scale: 1.0,
    }
}
