//! Albedo and opaque coverage of textured pieces: the mean of factor × texture over the part of a
//! piece its alpha mask keeps, and the fraction it keeps.
//!
//! A piece is a planar polygon inside one scene triangle, so the affine map from the triangle to
//! its texture coordinates takes it to a polygon in texel space, and its mean albedo is the mean
//! of the texture over that polygon (an affine map scales every area by the same factor). The
//! texture is read as a piecewise-constant function (one value per texel, nearest-texel lookup,
//! linear light) and integrated over the polygon **exactly**, in time proportional to its
//! boundary rather than its area:
//!
//! - a summed-area table (Crow, 1984) over one copy of the image gives the sum over any
//!   texel-aligned rectangle in O(1); a rectangle outside the image is split along each axis
//!   into pieces of the image by the wrap mode (repeat, mirrored repeat, clamp to edge);
//! - the polygon's bounding rectangle is halved recursively; a cell the polygon covers entirely
//!   adds its table sum, a cell it misses adds nothing, a single texel it covers in part adds its
//!   value times the covered area (exact, since the texel is constant).
//!
//! The recursion stops at cells of several texels only for polygons whose boundary crosses more
//! than [`MAX_BOUNDARY_CELLS`] texels (a guard against texture coordinates scaled by thousands);
//! there it weights each boundary cell's mean by the covered area, and [`Integral::bound`]
//! reports the error bound: the area of those cells times the texture's range. On the Dabrovic
//! Sponza no piece comes near the guard, and a cap of 512 would save a third of the time for
//! errors up to 0.026 in a piece's albedo (`cargo test --release --test library
//! textures::the_boundary -- --nocapture`), so the default is exact in practice.
//! Preconditions: the scene passed [`Scene::validate`] and the pieces lie in their triangles.

use crate::radiosity::Piece;
use crate::raytrace::Frame;
use crate::scene::texture::{channel_value, srgb_table, Texture, TextureRef, Wrap};
use crate::scene::{Material, Scene};
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// Most boundary cells of one polygon's recursion before it stops at cells larger than a texel.
pub const MAX_BOUNDARY_CELLS: f64 = 65536.0;

/// What a textured piece reflects and keeps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Mean linear albedo (factor included) over the opaque part.
    pub albedo: DVec3,
    /// Fraction of the piece's area that is opaque, in [0, 1].
    pub coverage: f64,
}

/// The surface of every piece whose material is textured or alpha-masked (None: the material's
/// plain albedo, opaque). Materials are processed one at a time, pieces in parallel.
pub fn piece_surfaces(
    scene: &Scene,
    frame: &Frame,
    pieces: &[(u64, Piece)],
) -> Vec<Option<Surface>> {
    piece_surfaces_with(scene, frame, pieces, MAX_BOUNDARY_CELLS)
}

/// [`piece_surfaces`] with another cap on boundary cells (`f64::INFINITY`: exact).
pub fn piece_surfaces_with(
    scene: &Scene,
    frame: &Frame,
    pieces: &[(u64, Piece)],
    max_boundary_cells: f64,
) -> Vec<Option<Surface>> {
    let mut out = vec![None; pieces.len()];
    for (mi, m) in scene.materials.iter().enumerate() {
        let mine: Vec<usize> = (0..pieces.len())
            .filter(|&i| scene.triangle_material[pieces[i].1.triangle as usize] as usize == mi)
            .collect();
        if mine.is_empty() || (m.albedo_texture.is_none() && m.alpha.is_none()) {
            continue;
        }
        let tables = MaterialTables::new(scene, m);
        let found: Vec<Surface> = mine
            .par_iter()
            .map(|&i| tables.surface(scene, frame, &pieces[i].1, max_boundary_cells))
            .collect();
        for (i, s) in mine.into_iter().zip(found) {
            out[i] = Some(s);
        }
    }
    out
}

/// The summed-area tables a material needs: colour × opaque and opaque on the colour texture's
/// texels, and a separate opaque table when the mask is another image or mapping.
struct MaterialTables {
    factor: DVec3,
    colour: Option<(TextureRef, Table)>,
    /// True when `colour`'s fourth channel is the mask (one image and mapping for both).
    mask_in_colour: bool,
    /// A mask read through another reference than the colour's.
    mask: Option<(TextureRef, Table)>,
    /// The material's coverage when no texture decides it (alpha factor alone, or opaque).
    constant_coverage: f64,
}

impl MaterialTables {
    fn new(scene: &Scene, m: &Material) -> Self {
        let lut = srgb_table();
        let alpha = m.alpha.as_ref();
        let mask_ref = alpha.and_then(|a| a.texture.as_ref());
        let opaque = |t: [u8; 4]| match (alpha, mask_ref) {
            (Some(a), Some((_, channel))) => {
                !a.cuts(a.factor * channel_value(t, *channel)) as u8 as f64
            }
            _ => 1.0,
        };
        let mask_in_colour = match (&m.albedo_texture, mask_ref) {
            (Some(c), Some((r, _))) => same_lookup(scene, c, r),
            _ => false,
        };
        let colour = m.albedo_texture.as_ref().map(|r| {
            let table = Table::new(r.of(&scene.textures), |t| {
                let o = if mask_in_colour { opaque(t) } else { 1.0 };
                let [r, g, b] = [0, 1, 2].map(|c| o * lut[t[c] as usize] as f64);
                [r, g, b, o]
            });
            (r.clone(), table.with_wrap(r.wrap))
        });
        let mask = mask_ref.filter(|_| !mask_in_colour).map(|(r, _)| {
            let table = Table::new(r.of(&scene.textures), |t| [0.0, 0.0, 0.0, opaque(t)]);
            (r.clone(), table.with_wrap(r.wrap))
        });
        let constant_coverage = match alpha {
            Some(a) if a.texture.is_none() => !a.cuts(a.factor) as u8 as f64,
            _ => 1.0,
        };
        MaterialTables {
            factor: glam::Vec3::from(m.albedo).as_dvec3(),
            colour,
            mask_in_colour,
            mask,
            constant_coverage,
        }
    }

    fn surface(&self, scene: &Scene, frame: &Frame, piece: &Piece, cap: f64) -> Surface {
        let mut coverage = self.constant_coverage;
        let mut albedo = self.factor;
        if let Some((r, table)) = &self.colour {
            let i = table.integrate_with(&texel_polygon(scene, frame, piece, r, table.size()), cap);
            if i.sum[3] > 0.0 {
                albedo *= DVec3::new(i.sum[0], i.sum[1], i.sum[2]) / i.sum[3];
            }
            if self.mask_in_colour {
                coverage = i.sum[3] / i.area;
            }
        }
        if let Some((r, table)) = &self.mask {
            let i = table.integrate_with(&texel_polygon(scene, frame, piece, r, table.size()), cap);
            coverage = i.sum[3] / i.area;
        }
        Surface {
            albedo,
            coverage: coverage.clamp(0.0, 1.0),
        }
    }
}

/// True when two references read the same texels at the same coordinates.
fn same_lookup(scene: &Scene, a: &TextureRef, b: &TextureRef) -> bool {
    let (ta, tb) = (a.of(&scene.textures), b.of(&scene.textures));
    (a.texture == b.texture || (ta.width, ta.height) == (tb.width, tb.height))
        && a.transform == b.transform
        && a.wrap == b.wrap
}

/// The piece's polygon in texel units of `tex` as `r` maps it.
fn texel_polygon(
    scene: &Scene,
    frame: &Frame,
    piece: &Piece,
    r: &TextureRef,
    [width, height]: [f64; 2],
) -> Vec<DVec2> {
    let t = piece.triangle as usize;
    let tri = scene.triangles[t];
    let [a, b, c] = tri.map(|v| frame.to_grid(scene.positions[v as usize]));
    let uv = tri.map(|v| {
        let m = r.apply(scene.uvs[v as usize]);
        DVec2::new(m[0] as f64 * width, m[1] as f64 * height)
    });
    let (e0, e1) = (b - a, c - a);
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let denom = d00 * d11 - d01 * d01;
    piece
        .vertices
        .iter()
        .map(|&p| {
            let e2 = DVec3::from(p) - a;
            let (d20, d21) = (e2.dot(e0), e2.dot(e1));
            let beta = (d11 * d20 - d01 * d21) / denom;
            let gamma = (d00 * d21 - d01 * d20) / denom;
            uv[0] + (uv[1] - uv[0]) * beta + (uv[2] - uv[0]) * gamma
        })
        .collect()
}

/// A summed-area table of up to four channels over one copy of an image, with its wrap modes.
pub struct Table {
    width: i64,
    height: i64,
    wrap: [Wrap; 2],
    /// `(width + 1) · (height + 1)` prefix sums, row-major, 4 channels each.
    sums: Vec<[f64; 4]>,
}

/// The integral of a table over a polygon.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integral {
    /// Σ value × covered area, per channel (texel units²).
    pub sum: [f64; 4],
    /// The polygon's area (texel units²).
    pub area: f64,
    /// Area of the cells larger than a texel that the polygon's boundary crosses: the error of
    /// `sum` is at most this times the channel's range.
    pub bound: f64,
}

impl Table {
    /// The table of `value(texel)` (up to four channels) over `tex`, repeating.
    pub fn new(tex: &Texture, value: impl Fn([u8; 4]) -> [f64; 4] + Sync) -> Self {
        let (w, h) = (tex.width as usize, tex.height as usize);
        // Row prefix sums in parallel, then each row adds the one above (32 bytes per texel).
        let mut sums = vec![[0.0; 4]; (w + 1) * (h + 1)];
        sums[w + 1..]
            .par_chunks_mut(w + 1)
            .enumerate()
            .for_each(|(y, row)| {
                let mut acc = [0.0; 4];
                for x in 0..w {
                    let v = value(tex.texel(x as i64, y as i64, [Wrap::Repeat; 2]));
                    for (s, v) in acc.iter_mut().zip(v) {
                        *s += v;
                    }
                    row[x + 1] = acc;
                }
            });
        for y in 1..h {
            let (above, below) = sums.split_at_mut((y + 1) * (w + 1));
            let prev = &above[y * (w + 1)..];
            for (b, a) in below[..w + 1].iter_mut().zip(prev) {
                for k in 0..4 {
                    b[k] += a[k];
                }
            }
        }
        Table {
            width: w as i64,
            height: h as i64,
            wrap: [Wrap::Repeat; 2],
            sums,
        }
    }

    /// Width and height of the image, in texels.
    pub fn size(&self) -> [f64; 2] {
        [self.width as f64, self.height as f64]
    }

    /// The same table read with other wrap modes.
    pub fn with_wrap(mut self, wrap: [Wrap; 2]) -> Self {
        self.wrap = wrap;
        self
    }

    /// Sum over texels `[x0, x1) × [y0, y1)` of the image itself (no wrapping).
    fn base_sum(&self, x0: i64, x1: i64, y0: i64, y1: i64) -> [f64; 4] {
        let w = self.width as usize + 1;
        let at = |x: i64, y: i64| self.sums[y as usize * w + x as usize];
        let (a, b, c, d) = (at(x1, y1), at(x0, y1), at(x1, y0), at(x0, y0));
        std::array::from_fn(|k| a[k] - b[k] - c[k] + d[k])
    }

    /// Sum over texels `[x0, x1) × [y0, y1)` of the wrapped (unbounded) texture.
    pub fn rect_sum(&self, x0: i64, x1: i64, y0: i64, y1: i64) -> [f64; 4] {
        if x0 >= 0 && x1 <= self.width && y0 >= 0 && y1 <= self.height {
            return self.base_sum(x0, x1, y0, y1);
        }
        let xs = segments(x0, x1, self.width, self.wrap[0]);
        let ys = segments(y0, y1, self.height, self.wrap[1]);
        let mut out = [0.0; 4];
        for &(a, b, kx) in xs.as_slice() {
            for &(c, d, ky) in ys.as_slice() {
                let s = self.base_sum(a, b, c, d);
                for k in 0..4 {
                    out[k] += kx * ky * s[k];
                }
            }
        }
        out
    }

    /// The integral over a polygon in texel units (either winding). A polygon of no area (all
    /// its texture coordinates on a line) reads the texel under its first vertex, as if it
    /// covered exactly that texel.
    pub fn integrate(&self, poly: &[DVec2]) -> Integral {
        self.integrate_with(poly, MAX_BOUNDARY_CELLS)
    }

    /// [`Table::integrate`] with at most about `max_boundary_cells` boundary cells
    /// (`f64::INFINITY`: exact, down to single texels).
    pub fn integrate_with(&self, poly: &[DVec2], max_boundary_cells: f64) -> Integral {
        let area = shoelace(poly).abs();
        let lo = poly.iter().fold(DVec2::INFINITY, |a, &p| a.min(p));
        let hi = poly.iter().fold(DVec2::NEG_INFINITY, |a, &p| a.max(p));
        let flat = area.partial_cmp(&(1e-12 * (1.0 + (hi - lo).length_squared())));
        if flat != Some(std::cmp::Ordering::Greater) {
            let p = poly.first().copied().unwrap_or_default().floor();
            let (x, y) = (p.x as i64, p.y as i64);
            return Integral {
                sum: self.rect_sum(x, x + 1, y, y + 1),
                area: 1.0,
                bound: 0.0,
            };
        }
        let mut acc = Integral {
            sum: [0.0; 4],
            area,
            bound: 0.0,
        };
        if poly.len() > Poly::MAX_INPUT {
            // A fan of triangles covers the (convex) polygon once.
            for i in 1..poly.len() - 1 {
                let part =
                    self.integrate_with(&[poly[0], poly[i], poly[i + 1]], max_boundary_cells);
                for k in 0..4 {
                    acc.sum[k] += part.sum[k];
                }
                acc.bound += part.bound;
            }
            return acc;
        }
        let perimeter: f64 = (0..poly.len())
            .map(|i| (poly[(i + 1) % poly.len()] - poly[i]).length())
            .sum();
        let min_cell = (perimeter / max_boundary_cells).max(1.0);
        let rect = [
            lo.x.floor() as i64,
            hi.x.ceil() as i64,
            lo.y.floor() as i64,
            hi.y.ceil() as i64,
        ];
        let rect = [
            rect[0],
            rect[1].max(rect[0] + 1),
            rect[2],
            rect[3].max(rect[2] + 1),
        ];
        self.cell(&Poly::from_slice(poly), rect, min_cell, &mut acc);
        acc
    }

    fn cell(&self, poly: &Poly, [x0, x1, y0, y1]: [i64; 4], min_cell: f64, acc: &mut Integral) {
        let rect = [x0 as f64, x1 as f64, y0 as f64, y1 as f64];
        let (w, h) = (x1 - x0, y1 - y0);
        let cell_area = (w * h) as f64;
        // Cells inside the polygon (most of a large one's) need no clipping.
        if poly.contains_rect(rect) {
            let s = self.rect_sum(x0, x1, y0, y1);
            for (a, v) in acc.sum.iter_mut().zip(s) {
                *a += v;
            }
            return;
        }
        let poly = poly.clip_rect(rect);
        let covered = shoelace(poly.as_slice()).abs();
        if covered <= 0.0 {
            return;
        }
        let full = covered >= cell_area * (1.0 - 1e-12);
        if full || (w as f64) <= min_cell && (h as f64) <= min_cell {
            let s = self.rect_sum(x0, x1, y0, y1);
            let weight = if full { 1.0 } else { covered / cell_area };
            for (a, v) in acc.sum.iter_mut().zip(s) {
                *a += weight * v;
            }
            if !full && cell_area > 1.0 {
                acc.bound += cell_area;
            }
            return;
        }
        if w >= h {
            let m = x0 + w / 2;
            self.cell(&poly, [x0, m, y0, y1], min_cell, acc);
            self.cell(&poly, [m, x1, y0, y1], min_cell, acc);
        } else {
            let m = y0 + h / 2;
            self.cell(&poly, [x0, x1, y0, m], min_cell, acc);
            self.cell(&poly, [x0, x1, m, y1], min_cell, acc);
        }
    }
}

/// Up to eight ranges of an image axis, each with how many times it is read.
struct Segments {
    items: [(i64, i64, f64); 8],
    len: usize,
}

impl Segments {
    fn push(&mut self, lo: i64, hi: i64, count: f64) {
        self.items[self.len] = (lo, hi, count);
        self.len += 1;
    }

    fn as_slice(&self) -> &[(i64, i64, f64)] {
        &self.items[..self.len]
    }
}

/// Split `[a, b)` along an axis of `n` texels into ranges of the image `[lo, hi) ⊆ [0, n)`, each
/// read `count` times, by the wrap mode. Repeat gives at most 3 ranges (a head, whole copies, a
/// tail) and mirrored repeat at most 6, so eight always suffice.
fn segments(a: i64, b: i64, n: i64, wrap: Wrap) -> Segments {
    let mut out = Segments {
        items: [(0, 0, 0.0); 8],
        len: 0,
    };
    match wrap {
        Wrap::ClampToEdge => {
            if a < 0 {
                out.push(0, 1, (b.min(0) - a) as f64);
            }
            let (lo, hi) = (a.max(0), b.min(n));
            if lo < hi {
                out.push(lo, hi, 1.0);
            }
            if b > n {
                out.push(n - 1, n, (b - a.max(n)) as f64);
            }
        }
        Wrap::Repeat | Wrap::MirroredRepeat => {
            let mirrored = wrap == Wrap::MirroredRepeat;
            let period = if mirrored { 2 * n } else { n };
            let mut x = a;
            while x < b {
                if x.rem_euclid(period) == 0 && b - x >= period {
                    let k = (b - x) / period;
                    out.push(0, n, if mirrored { 2 * k } else { k } as f64);
                    x += k * period;
                    continue;
                }
                let q = x.div_euclid(n);
                let r = x - q * n;
                let end = b.min((q + 1) * n);
                let len = end - x;
                if mirrored && q.rem_euclid(2) == 1 {
                    out.push(n - r - len, n - r, 1.0);
                } else {
                    out.push(r, r + len, 1.0);
                }
                x = end;
            }
        }
    }
    out
}

/// Signed area of a polygon.
fn shoelace(poly: &[DVec2]) -> f64 {
    let n = poly.len();
    0.5 * (0..n)
        .map(|i| poly[i].perp_dot(poly[(i + 1) % n]))
        .sum::<f64>()
}

/// A convex polygon of at most [`Poly::CAPACITY`] vertices, on the stack.
#[derive(Clone, Copy)]
struct Poly {
    v: [DVec2; Poly::CAPACITY],
    len: usize,
}

impl Poly {
    const CAPACITY: usize = 48;
    /// Largest polygon taken whole: clipping a convex n-gon to a rectangle leaves at most n + 4
    /// distinct vertices, and repeated vertices are not kept, so any clip of it fits.
    const MAX_INPUT: usize = 32;

    fn from_slice(p: &[DVec2]) -> Self {
        let mut out = Poly {
            v: [DVec2::ZERO; Self::CAPACITY],
            len: 0,
        };
        for &q in p {
            out.push(q);
        }
        out
    }

    fn as_slice(&self) -> &[DVec2] {
        &self.v[..self.len]
    }

    /// Append `p` unless it repeats the last vertex. (A full polygon drops it: rounding alone
    /// could get there, never an exact clip, by the bound on [`Poly::MAX_INPUT`].)
    fn push(&mut self, p: DVec2) {
        if self.len > 0 && self.v[self.len - 1] == p || self.len == Self::CAPACITY {
            return;
        }
        self.v[self.len] = p;
        self.len += 1;
    }

    /// True when the rectangle `[x0, x1] × [y0, y1]` lies inside the (convex) polygon: its four
    /// corners lie on the inner side of every edge, whichever the winding.
    fn contains_rect(&self, [x0, x1, y0, y1]: [f64; 4]) -> bool {
        let v = self.as_slice();
        let n = v.len();
        if n < 3 {
            return false;
        }
        let sign = shoelace(v).signum();
        let corners = [
            DVec2::new(x0, y0),
            DVec2::new(x1, y0),
            DVec2::new(x1, y1),
            DVec2::new(x0, y1),
        ];
        (0..n).all(|i| {
            let (a, b) = (v[i], v[(i + 1) % n]);
            corners
                .iter()
                .all(|&c| sign * (b - a).perp_dot(c - a) >= 0.0)
        })
    }

    /// Sutherland–Hodgman clip to the rectangle `[x0, x1] × [y0, y1]`.
    fn clip_rect(&self, [x0, x1, y0, y1]: [f64; 4]) -> Poly {
        let planes: [(usize, f64, f64); 4] =
            [(0, x0, 1.0), (0, x1, -1.0), (1, y0, 1.0), (1, y1, -1.0)];
        let mut poly = *self;
        for (axis, at, sign) in planes {
            if poly.len == 0 {
                break;
            }
            let src = poly.as_slice();
            if src.iter().all(|p| sign * (p[axis] - at) >= 0.0) {
                continue;
            }
            let inside = |p: DVec2| sign * (p[axis] - at) >= 0.0;
            let mut out = Poly {
                v: [DVec2::ZERO; Self::CAPACITY],
                len: 0,
            };
            for i in 0..src.len() {
                let (p, q) = (src[i], src[(i + 1) % src.len()]);
                let (pin, qin) = (inside(p), inside(q));
                if pin {
                    out.push(p);
                }
                if pin != qin {
                    let t = (at - p[axis]) / (q[axis] - p[axis]);
                    let mut x = p + (q - p) * t;
                    x[axis] = at;
                    out.push(x);
                }
            }
            if out.len > 1 && out.v[0] == out.v[out.len - 1] {
                out.len -= 1;
            }
            poly = out;
        }
        poly
    }
}
