//! Watertight ray/triangle intersection, one triangle at a time or four in SSE lanes with the
//! same operations in the same order (so the same distances bit for bit, up to the sign of
//! zeros, which no comparison below sees).

use glam::{DVec3, Vec3A};

/// Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013): a ray through the
/// shared edge or vertex of two triangles hits at least one of them, so closed scenes do not leak
/// rays through their seams (obvhs's Möller–Trumbore test does).
///
/// The paper's shear `(a[kx] − sx·a[kz], a[ky] − sy·a[kz], sz·a[kz])` of a vertex a (relative to
/// the origin) is taken as three dot products with rows holding 1, −s and 0 in the permuted
/// axes: each product by 1 or 0 is exact and adding an exact 0 changes nothing, so every value
/// is the paper's bit for bit (no FMA contraction in Rust), without indexing by kx, ky, kz.
pub struct Watertight {
    origin: Vec3A,
    rows: [Vec3A; 3],
    /// The permuted axes (kx, ky, kz) and the shear (−sx, −sy, sz) for the lane-wise test.
    axes: [usize; 3],
    shear: [f32; 3],
}

impl Watertight {
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        let d = dir.as_vec3();
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let row = |k: usize, kz_weight: f32| {
            let mut r = [0.0f32; 3];
            r[k] = 1.0;
            r[kz] = kz_weight;
            Vec3A::from_array(r)
        };
        let sz = 1.0 / d[kz];
        let mut z = [0.0f32; 3];
        z[kz] = sz;
        Watertight {
            axes: [kx, ky, kz],
            shear: [-(d[kx] / d[kz]), -(d[ky] / d[kz]), sz],
            origin: Vec3A::from(origin.as_vec3()),
            rows: [
                row(kx, -(d[kx] / d[kz])),
                row(ky, -(d[ky] / d[kz])),
                Vec3A::from_array(z),
            ],
        }
    }

    /// Distance to the triangle, or infinity when missed or outside `[tmin, tmax]`.
    #[inline]
    pub fn intersect(&self, v: &[Vec3A; 3], tmin: f32, tmax: f32) -> f32 {
        let [rx, ry, rz] = self.rows;
        let shear = |p: Vec3A| {
            let q = p - self.origin;
            (q.dot(rx), q.dot(ry), q.dot(rz))
        };
        let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (shear(v[0]), shear(v[1]), shear(v[2]));
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return f32::INFINITY;
        }
        let det = u + v + w;
        if det == 0.0 {
            return f32::INFINITY;
        }
        let t = (u * az + v * bz + w * cz) / det;
        if t >= tmin && t <= tmax {
            t
        } else {
            f32::INFINITY
        }
    }
}

/// Triangles stored by component (structure of arrays) in slot order, padded by four copies of
/// the last triangle, so that the four slots from any index load as one SSE vector each.
pub struct TriangleLanes {
    /// `v[i][c][s]`: component c of vertex i of slot s.
    v: [[Vec<f32>; 3]; 3],
}

impl TriangleLanes {
    pub fn new(tris: &[[Vec3A; 3]]) -> Self {
        let mut v: [[Vec<f32>; 3]; 3] = Default::default();
        for (i, vi) in v.iter_mut().enumerate() {
            for (c, vc) in vi.iter_mut().enumerate() {
                vc.extend(tris.iter().map(|t| t[i][c]));
                let last = vc.last().copied().unwrap_or(0.0);
                vc.extend([last; 4]);
            }
        }
        TriangleLanes { v }
    }

    /// The distances of [`Watertight::intersect`] to slots `first..first + 4` (lanes `count..`
    /// are left out: infinity).
    #[inline(always)]
    pub fn intersect4(
        &self,
        wt: &Watertight,
        first: usize,
        count: usize,
        tmin: f32,
        tmax: f32,
    ) -> [f32; 4] {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: SSE2 is part of x86_64; `first + 4` is within the padded arrays when
            // `first` is a slot.
            unsafe { self.intersect4_sse(wt, first, count, tmin, tmax) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            std::array::from_fn(|k| {
                if k < count {
                    let s = first + k;
                    let v = std::array::from_fn(|i| {
                        Vec3A::new(self.v[i][0][s], self.v[i][1][s], self.v[i][2][s])
                    });
                    wt.intersect(&v, tmin, tmax)
                } else {
                    f32::INFINITY
                }
            })
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn intersect4_sse(
        &self,
        wt: &Watertight,
        first: usize,
        count: usize,
        tmin: f32,
        tmax: f32,
    ) -> [f32; 4] {
        use std::arch::x86_64::*;
        let [kx, ky, kz] = wt.axes;
        let o = wt.origin.to_array();
        let (nsx, nsy, sz) = (
            _mm_set1_ps(wt.shear[0]),
            _mm_set1_ps(wt.shear[1]),
            _mm_set1_ps(wt.shear[2]),
        );
        assert!(first + 4 <= self.v[0][0].len());
        let load = |i: usize, c: usize| {
            // SAFETY: in bounds (asserted above).
            _mm_sub_ps(
                _mm_loadu_ps(self.v[i][c].as_ptr().add(first)),
                _mm_set1_ps(o[c]),
            )
        };
        // Sheared vertex i: (q[kx] + q[kz]·(−sx), q[ky] + q[kz]·(−sy), q[kz]·sz), the scalar
        // test's dot products without their exact zero terms.
        let shear = |i: usize| {
            let (qx, qy, qz) = (load(i, kx), load(i, ky), load(i, kz));
            (
                _mm_add_ps(qx, _mm_mul_ps(qz, nsx)),
                _mm_add_ps(qy, _mm_mul_ps(qz, nsy)),
                _mm_mul_ps(qz, sz),
            )
        };
        let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (shear(0), shear(1), shear(2));
        let u = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
        let v = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
        let w = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
        let zero = _mm_setzero_ps();
        let lanes = (1u32 << count) - 1;
        let neg = _mm_or_ps(
            _mm_or_ps(_mm_cmplt_ps(u, zero), _mm_cmplt_ps(v, zero)),
            _mm_cmplt_ps(w, zero),
        );
        let pos = _mm_or_ps(
            _mm_or_ps(_mm_cmpgt_ps(u, zero), _mm_cmpgt_ps(v, zero)),
            _mm_cmpgt_ps(w, zero),
        );
        let det = _mm_add_ps(_mm_add_ps(u, v), w);
        let t = _mm_div_ps(
            _mm_add_ps(
                _mm_add_ps(_mm_mul_ps(u, az), _mm_mul_ps(v, bz)),
                _mm_mul_ps(w, cz),
            ),
            det,
        );
        let miss = _mm_or_ps(_mm_and_ps(neg, pos), _mm_cmpeq_ps(det, zero));
        let inside = _mm_and_ps(
            _mm_cmpge_ps(t, _mm_set1_ps(tmin)),
            _mm_cmple_ps(t, _mm_set1_ps(tmax)),
        );
        let hit = _mm_andnot_ps(miss, inside);
        let mut out = [0.0f32; 4];
        _mm_storeu_ps(
            out.as_mut_ptr(),
            _mm_blendv_or(hit, t, _mm_set1_ps(f32::INFINITY)),
        );
        // A zero edge function is decided again in f64 (the ray meets an edge's line): those
        // lanes take the scalar path, which does exactly that.
        let edge = _mm_or_ps(
            _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
            _mm_cmpeq_ps(w, zero),
        );
        let mut redo = _mm_movemask_ps(edge) as u32 & lanes;
        let skip = !lanes & 0xf;
        for (k, x) in out.iter_mut().enumerate() {
            if skip & (1 << k) != 0 {
                *x = f32::INFINITY;
            }
        }
        while redo != 0 {
            let k = redo.trailing_zeros() as usize;
            redo &= redo - 1;
            let s = first + k;
            let v = std::array::from_fn(|i| {
                Vec3A::new(self.v[i][0][s], self.v[i][1][s], self.v[i][2][s])
            });
            out[k] = wt.intersect(&v, tmin, tmax);
        }
        out
    }
}

/// `mask ? a : b` lane-wise with SSE2 only.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn _mm_blendv_or(
    mask: std::arch::x86_64::__m128,
    a: std::arch::x86_64::__m128,
    b: std::arch::x86_64::__m128,
) -> std::arch::x86_64::__m128 {
    use std::arch::x86_64::*;
    _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b))
}
