//! Geometry shared by the radiosity stages: the voxel-grid frame, convex polygons (splitting by a
//! plane, area, centroid, distance), area sampling and the seeded random numbers.
//!
//! All radiosity geometry is computed in *grid coordinates*: `g = (world − origin) / voxel_size`,
//! in f64. Voxel `(i, j, k)` is the unit cube `[i, i+1) × [j, j+1) × [k, k+1)`. Working relative to
//! the scene's own corner and in units of the voxel makes every tolerance scale-free: a scene
//! translated by 1e5 units or shrunk to 1e-6 units gives the same numbers.

use glam::DVec3;
use rand_core::{RngCore, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A convex planar polygon (counter-clockwise about its normal).
pub type Polygon = Vec<DVec3>;

/// Maps world coordinates to grid coordinates and back (the ray tracer's frame: it traces in
/// the voxel grid).
pub use crate::raytrace::Frame;

/// Index 0..6 of the dominant axis direction of a normal: +x, −x, +y, −y, +z, −z.
pub fn dominant_axis(n: DVec3) -> u8 {
    let a = n.abs();
    let (axis, v) = if a.x >= a.y && a.x >= a.z {
        (0, n.x)
    } else if a.y >= a.z {
        (1, n.y)
    } else {
        (2, n.z)
    };
    axis * 2 + u8::from(v < 0.0)
}

/// The unit vector of a dominant-axis index.
pub fn axis_vector(axis: u8) -> DVec3 {
    let mut v = DVec3::ZERO;
    v[(axis / 2) as usize] = if axis.is_multiple_of(2) { 1.0 } else { -1.0 };
    v
}

/// Split a convex polygon by the plane `n·x = d` into the parts with `n·x ≤ d` and `n·x ≥ d`.
/// Both parts share the exact same cut vertices. Parts with fewer than 3 vertices are empty.
pub fn split(poly: &[DVec3], n: DVec3, d: f64) -> (Polygon, Polygon) {
    split_by(
        poly,
        |p| n.dot(p) - d,
        |a, b, sa, sb| a + (b - a) * (sa / (sa - sb)),
    )
}

/// [`split`] by the axis-aligned plane `x[axis] = value`; cut vertices lie exactly on the plane.
pub fn split_axis(poly: &[DVec3], axis: usize, value: f64) -> (Polygon, Polygon) {
    split_by(
        poly,
        |p| p[axis] - value,
        |a, b, sa, sb| {
            let mut q = a + (b - a) * (sa / (sa - sb));
            q[axis] = value;
            q
        },
    )
}

fn split_by(
    poly: &[DVec3],
    side: impl Fn(DVec3) -> f64,
    cut: impl Fn(DVec3, DVec3, f64, f64) -> DVec3,
) -> (Polygon, Polygon) {
    let mut below = Vec::with_capacity(poly.len() + 1);
    let mut above = Vec::with_capacity(poly.len() + 1);
    let s: Vec<f64> = poly.iter().map(|&p| side(p)).collect();
    for i in 0..poly.len() {
        let j = (i + 1) % poly.len();
        let (a, b, sa, sb) = (poly[i], poly[j], s[i], s[j]);
        if sa <= 0.0 {
            below.push(a);
        }
        if sa >= 0.0 {
            above.push(a);
        }
        if (sa < 0.0 && sb > 0.0) || (sa > 0.0 && sb < 0.0) {
            // Cut from the lower-index end so both halves get the identical point.
            let q = if i < j {
                cut(a, b, sa, sb)
            } else {
                cut(b, a, sb, sa)
            };
            below.push(q);
            above.push(q);
        }
    }
    if below.len() < 3 {
        below.clear();
    }
    if above.len() < 3 {
        above.clear();
    }
    (below, above)
}

/// Vector area of a polygon (its normal times its area).
pub fn vector_area(poly: &[DVec3]) -> DVec3 {
    let mut s = DVec3::ZERO;
    for i in 1..poly.len().saturating_sub(1) {
        s += (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]);
    }
    0.5 * s
}

/// Area of a planar polygon.
pub fn area(poly: &[DVec3]) -> f64 {
    vector_area(poly).length()
}

/// Area-weighted centroid of a planar convex polygon.
pub fn centroid(poly: &[DVec3]) -> DVec3 {
    let mut c = DVec3::ZERO;
    let mut w = 0.0;
    for i in 1..poly.len().saturating_sub(1) {
        let a = 0.5 * (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]).length();
        c += a * (poly[0] + poly[i] + poly[i + 1]) / 3.0;
        w += a;
    }
    if w > 0.0 {
        c / w
    } else {
        poly.iter().copied().sum::<DVec3>() / poly.len().max(1) as f64
    }
}

/// The point of a convex planar polygon with unit normal `n` closest to `p`.
pub fn closest_point_on_polygon(p: DVec3, poly: &[DVec3], n: DVec3) -> DVec3 {
    let q = p - n.dot(p - poly[0]) * n;
    let inside = (0..poly.len()).all(|i| {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        n.dot((b - a).cross(q - a)) >= 0.0
    });
    if inside {
        return q;
    }
    let mut best = (f64::INFINITY, poly[0]);
    for i in 0..poly.len() {
        let a = poly[i];
        let b = poly[(i + 1) % poly.len()];
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        let c = a + t * ab;
        let d = (c - p).length_squared();
        if d < best.0 {
            best = (d, c);
        }
    }
    best.1
}

/// Distance from `p` to a convex planar polygon with unit normal `n`.
pub fn distance_to_polygon(p: DVec3, poly: &[DVec3], n: DVec3) -> f64 {
    (closest_point_on_polygon(p, poly, n) - p).length()
}

/// Form factor from a differential area at `x` with unit normal `n` to the triangle `tri`
/// (unit normal `tn`), unoccluded: Lambert's contour formula
/// `F = 1/(2π) Σ_k β_k n·Γ_k` over the part of the triangle in front of `x` (the triangle is
/// clipped to the half-space `n·(y − x) ≥ 0`; a triangle facing away from `x` gives 0).
pub fn point_to_triangle(x: DVec3, n: DVec3, tri: [DVec3; 3], tn: DVec3) -> f64 {
    if tn.dot(x - tri[0]) <= 0.0 {
        return 0.0;
    }
    let front = split(&tri, n, n.dot(x)).1;
    let mut s = 0.0;
    for k in 0..front.len() {
        let a = front[k] - x;
        let b = front[(k + 1) % front.len()] - x;
        let c = a.cross(b);
        let len = c.length();
        if len > 0.0 {
            s += len.atan2(a.dot(b)) * n.dot(c / len);
        }
    }
    (s / std::f64::consts::TAU).abs()
}

/// The incentre and inradius of the triangle `a b c` (inradius 0 for a degenerate one).
pub fn incircle(a: DVec3, b: DVec3, c: DVec3) -> (DVec3, f64) {
    let (la, lb, lc) = ((b - c).length(), (c - a).length(), (a - b).length());
    let perimeter = la + lb + lc;
    if perimeter <= 0.0 {
        return (a, 0.0);
    }
    let centre = (a * la + b * lb + c * lc) / perimeter;
    (centre, (b - a).cross(c - a).length() / perimeter)
}

/// A point drawn uniformly from the triangle `a b c` with `u, v` in [0, 1).
pub fn point_in_triangle(a: DVec3, b: DVec3, c: DVec3, u: f64, v: f64) -> DVec3 {
    let su = u.sqrt();
    a * (1.0 - su) + b * (su * (1.0 - v)) + c * (su * v)
}

/// An orthonormal basis (t, b) around a unit vector (the scene builder's discs use it too).
pub use crate::scene::builder::basis;

/// A cosine-distributed direction about the unit normal `n` from `u, v` in [0, 1).
pub fn cosine_direction(n: DVec3, u: f64, v: f64) -> DVec3 {
    let r = u.sqrt();
    let phi = std::f64::consts::TAU * v;
    let (t, b) = basis(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u).max(0.0).sqrt()).normalize()
}

/// Triangles of a set of convex polygons (fans) with their cumulative area, for drawing points
/// uniformly by area.
#[derive(Clone, Debug, Default)]
pub struct AreaSampler {
    /// (a, b, c, normal) of each fan triangle.
    triangles: Vec<(DVec3, DVec3, DVec3, DVec3)>,
    /// The polygon (its index in the order given) each fan triangle comes from.
    sources: Vec<u32>,
    /// Cumulative areas, normalised so the last is 1.
    cumulative: Vec<f64>,
    /// Total area.
    pub area: f64,
}

impl AreaSampler {
    /// A sampler over `polygons` (each with its unit normal).
    pub fn new<'a>(polygons: impl IntoIterator<Item = (&'a [DVec3], DVec3)>) -> Self {
        let mut s = AreaSampler::default();
        let mut total = 0.0;
        for (source, (poly, n)) in polygons.into_iter().enumerate() {
            for i in 1..poly.len().saturating_sub(1) {
                let (a, b, c) = (poly[0], poly[i], poly[i + 1]);
                let area = 0.5 * (b - a).cross(c - a).length();
                if area > 0.0 {
                    total += area;
                    s.triangles.push((a, b, c, n));
                    s.sources.push(source as u32);
                    s.cumulative.push(total);
                }
            }
        }
        if total > 0.0 {
            for c in &mut s.cumulative {
                *c /= total;
            }
        }
        s.area = total;
        s
    }

    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The fan triangles (a, b, c, unit normal).
    pub fn triangles(&self) -> &[(DVec3, DVec3, DVec3, DVec3)] {
        &self.triangles
    }

    /// The point and normal for a point `(u, v)` of the unit square, keeping its stratification:
    /// `u` chooses the fan triangle by area and, rescaled within that triangle's share, is the
    /// first coordinate inside it.
    pub fn sample_square(&self, u: f64, v: f64) -> (DVec3, DVec3) {
        self.sample_square_inset(u, v, 0.0)
    }

    /// The polygon (index in the order given to [`AreaSampler::new`]) that
    /// [`AreaSampler::sample_square`] draws `u` from.
    pub fn source(&self, u: f64) -> usize {
        let k = self
            .cumulative
            .partition_point(|&c| c <= u)
            .min(self.triangles.len() - 1);
        self.sources[k] as usize
    }

    /// [`AreaSampler::sample_square`] in each fan triangle shrunk about its incentre so that its
    /// edges move `inset` inwards (half its inradius where that is less): a ray origin drawn on
    /// a patch's edge at a concave corner would otherwise lie, by the rounding of the grid's
    /// f32 triangles, on either side of the adjoining wall, and a ray from outside it escapes
    /// the scene.
    pub fn sample_square_inset(&self, u: f64, v: f64, inset: f64) -> (DVec3, DVec3) {
        let k = self
            .cumulative
            .partition_point(|&c| c <= u)
            .min(self.triangles.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.cumulative[k - 1] };
        let hi = self.cumulative[k];
        let w = if hi > lo {
            ((u - lo) / (hi - lo)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let (a, b, c, n) = self.triangles[k];
        let p = point_in_triangle(a, b, c, w, v);
        if inset <= 0.0 {
            return (p, n);
        }
        let (centre, r) = incircle(a, b, c);
        if r <= 0.0 {
            return (p, n);
        }
        let d = inset.min(0.5 * r);
        (centre + (p - centre) * (1.0 - d / r), n)
    }

    /// The point and normal at `select` (chooses the triangle by area) and `u, v` (inside it).
    pub fn sample(&self, select: f64, u: f64, v: f64) -> (DVec3, DVec3) {
        let k = self
            .cumulative
            .partition_point(|&c| c <= select)
            .min(self.triangles.len() - 1);
        let (a, b, c, n) = self.triangles[k];
        // Reuse the leftover of `select` inside the chosen triangle would correlate; use u, v.
        (point_in_triangle(a, b, c, u, v), n)
    }
}

/// The random number generator of one work item (a patch, a patch pair): PCG seeded from the
/// global seed and the item's indices, so results do not depend on scheduling.
pub fn item_rng(seed: u64, a: u64, b: u64) -> Rng {
    let mut z = seed ^ 0x9e37_79b9_7f4a_7c15;
    for x in [a, b] {
        z = splitmix(z ^ splitmix(x.wrapping_add(0x632b_e59b_d9b4_e019)));
    }
    Rng(Pcg64Mcg::seed_from_u64(z))
}

fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Seeded uniform numbers.
pub struct Rng(Pcg64Mcg);

impl Rng {
    /// Uniform in [0, 1) with 53 random bits.
    pub fn f64(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform integer in [0, n).
    pub fn below(&mut self, n: usize) -> usize {
        ((self.0.next_u64() as u128 * n as u128) >> 64) as usize
    }

    /// A random permutation of 0..n (Fisher–Yates).
    pub fn permutation(&mut self, n: usize) -> Vec<u32> {
        let mut p: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            p.swap(i, self.below(i + 1));
        }
        p
    }

    /// `n` points of the unit square, jittered-stratified: the cells of a `g × g` grid
    /// (`g = ⌈√n⌉`) in random order, the first `n` of them, one random point in each.
    pub fn jittered(&mut self, n: usize) -> Vec<(f64, f64)> {
        let g = ((n as f64).sqrt().ceil() as usize).max(1);
        let cells = self.permutation(g * g);
        cells[..n]
            .iter()
            .map(|&c| {
                let (cx, cy) = ((c as usize % g) as f64, (c as usize / g) as f64);
                ((cx + self.f64()) / g as f64, (cy + self.f64()) / g as f64)
            })
            .collect()
    }

    /// `n` Latin-hypercube values in [0, 1): one in each stratum `[k/n, (k+1)/n)`, shuffled.
    pub fn strata(&mut self, n: usize) -> Vec<f64> {
        let perm = self.permutation(n);
        perm.iter()
            .map(|&k| (k as f64 + self.f64()) / n as f64)
            .collect()
    }
}

/// Group key of a piece: voxel (x fastest) then axis.
pub fn group_key(voxel: [u32; 3], axis: u8, dims: [u32; 3]) -> u64 {
    let linear =
        voxel[0] as u64 + dims[0] as u64 * (voxel[1] as u64 + dims[1] as u64 * voxel[2] as u64);
    linear * 8 + axis as u64
}

/// Voxel and axis of a group key.
pub fn split_key(key: u64, dims: [u32; 3]) -> ([u32; 3], u8) {
    let axis = (key % 8) as u8;
    let mut l = key / 8;
    let x = (l % dims[0] as u64) as u32;
    l /= dims[0] as u64;
    let y = (l % dims[1] as u64) as u32;
    let z = (l / dims[1] as u64) as u32;
    ([x, y, z], axis)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Polygon {
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        ]
    }

    #[test]
    fn splitting_keeps_area() {
        let (a, b) = split_axis(&square(), 0, 0.5);
        assert!((area(&a) - 1.0).abs() < 1e-12 && (area(&b) - 3.0).abs() < 1e-12);
        let (a, b) = split(&square(), DVec3::new(1.0, 1.0, 0.0).normalize(), 1.0);
        assert!((area(&a) + area(&b) - 4.0).abs() < 1e-12);
        let (a, b) = split_axis(&square(), 0, 5.0);
        assert_eq!((area(&a), b.len()), (4.0, 0));
    }

    #[test]
    fn distance_inside_and_outside() {
        let n = DVec3::Z;
        assert_eq!(
            distance_to_polygon(DVec3::new(1.0, 1.0, 3.0), &square(), n),
            3.0
        );
        assert!((distance_to_polygon(DVec3::new(3.0, 1.0, 0.0), &square(), n) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn axes_and_basis() {
        assert_eq!(dominant_axis(DVec3::new(0.1, -0.9, 0.2)), 3);
        assert_eq!(axis_vector(5), DVec3::NEG_Z);
        for n in [
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::new(0.3, -0.4, 0.5).normalize(),
        ] {
            let (t, b) = basis(n);
            assert!(t.dot(n).abs() < 1e-12 && b.dot(n).abs() < 1e-12 && t.dot(b).abs() < 1e-12);
        }
    }

    /// Distance from `p` to the line through `a` and `b`.
    fn to_line(p: DVec3, a: DVec3, b: DVec3) -> f64 {
        (p - a).cross(b - a).length() / (b - a).length()
    }

    proptest::proptest! {
        /// Inset samples keep `min(inset, r/2)` from every edge line of their fan triangle
        /// (brute-force distances, 1e-9 relative margin for f64 rounding) and stay in its plane.
        #[test]
        fn inset_samples_keep_off_the_edges(
            b in (0.01f64..3.0, -2.0f64..2.0),
            c in (-2.0f64..2.0, 1e-6f64..2.0),
            u in 0.0f64..1.0, v in 0.0f64..1.0, inset in 1e-7f64..0.5,
        ) {
            let (a, b, c) = (DVec3::ZERO, DVec3::new(b.0, b.1, 0.0), DVec3::new(c.0, c.1, 0.0));
            let s = AreaSampler::new([(&[a, b, c][..], DVec3::Z)]);
            let (p, n) = s.sample_square_inset(u, v, inset);
            let r = 2.0 * area(&[a, b, c]) / ((b - a).length() + (c - b).length() + (a - c).length());
            let d = inset.min(0.5 * r);
            proptest::prop_assert_eq!(n, DVec3::Z);
            proptest::prop_assert_eq!(p.z, 0.0);
            let inside = (b - a).cross(p - a).z.signum() == (c - b).cross(p - b).z.signum()
                && (c - b).cross(p - b).z.signum() == (a - c).cross(p - c).z.signum();
            proptest::prop_assert!(inside, "{p:?} outside");
            for (e0, e1) in [(a, b), (b, c), (c, a)] {
                let dist = to_line(p, e0, e1);
                proptest::prop_assert!(dist >= d * (1.0 - 1e-9), "{dist} < {d}");
            }
        }
    }

    #[test]
    fn seeded_numbers_are_reproducible() {
        let a: Vec<f64> = (0..4).map(|_| item_rng(1, 2, 3).f64()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        assert_ne!(item_rng(1, 2, 3).f64(), item_rng(1, 3, 2).f64());
        let s = item_rng(0, 0, 0).strata(8);
        let mut k: Vec<usize> = s.iter().map(|x| (x * 8.0) as usize).collect();
        k.sort();
        assert_eq!(k, (0..8).collect::<Vec<_>>());
    }
}
