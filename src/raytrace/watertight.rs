//! Watertight ray/triangle intersection, one triangle at a time or four in SSE lanes with the
//! same operations in the same order (so the same distances bit for bit).

use glam::Vec3A;

/// Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013): a ray through the
/// shared edge or vertex of two triangles hits at least one of them, so closed scenes do not leak
/// rays through their seams (obvhs's Möller–Trumbore test does).
///
/// The paper's shear of a vertex a (relative to the origin) is `(a[kx] + a[kz]·(−sx),
/// a[ky] + a[kz]·(−sy), a[kz]·sz)` with `sz = 1/d[kz]`, `sx = d[kx]·sz`, `sy = d[ky]·sz` (one
/// division; watertightness needs only that every vertex of a ray's triangles is sheared the
/// same way), with no FMA contraction (Rust has none), here and in every SSE lane of
/// [`TriangleBlocks::lanes4`].
pub struct Watertight {
    origin: Vec3A,
    /// The permuted axes (kx, ky, kz) and the shear (−sx, −sy, sz).
    axes: [usize; 3],
    shear: [f32; 3],
}

impl Watertight {
    /// For the ray from `origin` along `d` (f32; both as the caller rounded them).
    #[inline]
    pub fn new(origin: Vec3A, d: Vec3A) -> Self {
        // kz is the axis of the largest |d| (x, then y, on ties); kx and ky follow it in cyclic
        // order, swapped when d[kz] < 0 so that the sheared triangles keep their winding. Found
        // without branches and read from a table, and d read as an array: hemisphere rays point
        // anywhere, and branching on them (or indexing a `Vec3A`, which matches on the index)
        // mispredicted often enough to make this set-up cost about as much as two node visits.
        const AXES: [[usize; 3]; 6] = [
            [1, 2, 0],
            [2, 1, 0],
            [2, 0, 1],
            [0, 2, 1],
            [0, 1, 2],
            [1, 0, 2],
        ];
        let a = d.abs();
        let da = d.to_array();
        let x_wins = (a.x >= a.y) & (a.x >= a.z);
        let kz = (!x_wins as usize) * (1 + (a.y < a.z) as usize);
        let dz = da[kz];
        let axes = AXES[2 * kz + (dz < 0.0) as usize];
        let sz = 1.0 / dz;
        Watertight {
            axes,
            shear: [-(da[axes[0]] * sz), -(da[axes[1]] * sz), sz],
            origin,
        }
    }

    /// Distance to the triangle, or infinity when missed or outside `[tmin, tmax]`.
    #[inline]
    pub fn intersect(&self, v: &[Vec3A; 3], tmin: f32, tmax: f32) -> f32 {
        let [kx, ky, kz] = self.axes;
        let [nsx, nsy, sz] = self.shear;
        let shear = |p: Vec3A| {
            let q = (p - self.origin).to_array();
            (q[kx] + q[kz] * nsx, q[ky] + q[kz] * nsy, q[kz] * sz)
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

/// Up to four triangles stored by vertex, component and lane, so that each component of the
/// four loads as one SSE vector: one block per BVH leaf, contiguous (144 bytes).
#[derive(Clone, Copy)]
#[repr(C, align(16))]
struct Block {
    /// `v[i][c][k]`: component c of vertex i of lane k.
    v: [[[f32; 4]; 3]; 3],
}

/// The triangles of every BVH leaf, one four-lane block each.
#[derive(Default)]
pub struct TriangleBlocks {
    blocks: Vec<Block>,
}

impl TriangleBlocks {
    /// Append a block of `tris` (1 to 4 triangles); unused lanes repeat the first triangle.
    pub fn push(&mut self, tris: &[[Vec3A; 3]]) {
        assert!(
            (1..=4).contains(&tris.len()),
            "a block holds 1 to 4 triangles"
        );
        let mut b = Block {
            v: [[[0.0; 4]; 3]; 3],
        };
        for k in 0..4 {
            let t = tris.get(k).unwrap_or(&tris[0]);
            for (i, vi) in b.v.iter_mut().enumerate() {
                for (c, vc) in vi.iter_mut().enumerate() {
                    vc[k] = t[i][c];
                }
            }
        }
        self.blocks.push(b);
    }

    /// Lane `k`'s triangle of block `block`.
    pub fn triangle(&self, block: usize, k: usize) -> [Vec3A; 3] {
        let b = &self.blocks[block];
        std::array::from_fn(|i| Vec3A::new(b.v[i][0][k], b.v[i][1][k], b.v[i][2][k]))
    }

    /// The distances of [`Watertight::intersect`] to the first `count` triangles of block
    /// `block` (lanes `count..` hold infinity), one lane at a time: what
    /// [`TriangleBlocks::lanes4`] computes in SSE lanes on x86_64.
    #[cfg(not(target_arch = "x86_64"))]
    fn intersect4(
        &self,
        wt: &Watertight,
        block: usize,
        count: usize,
        tmin: f32,
        tmax: f32,
    ) -> [f32; 4] {
        std::array::from_fn(|k| {
            if k < count {
                wt.intersect(&self.triangle(block, k), tmin, tmax)
            } else {
                f32::INFINITY
            }
        })
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn intersect4_sse(
        &self,
        wt: &Watertight,
        block: usize,
        count: usize,
        tmin: f32,
        tmax: f32,
    ) -> std::arch::x86_64::__m128 {
        use std::arch::x86_64::*;
        let [kx, ky, kz] = wt.axes;
        let o = wt.origin.to_array();
        let (nsx, nsy, sz) = (
            _mm_set1_ps(wt.shear[0]),
            _mm_set1_ps(wt.shear[1]),
            _mm_set1_ps(wt.shear[2]),
        );
        let b = &self.blocks[block];
        let load = |i: usize, c: usize| {
            // SAFETY: a lane row is four f32, 16-byte aligned (`Block` is `align(16)`).
            _mm_sub_ps(_mm_load_ps(b.v[i][c].as_ptr()), _mm_set1_ps(o[c]))
        };
        // Sheared vertex i: (q[kx] + q[kz]·(−sx), q[ky] + q[kz]·(−sy), q[kz]·sz), as in the
        // scalar test.
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
        // Lanes past `count` (unused, repeating the first triangle) always miss.
        let used = _mm_castsi128_ps(_mm_cmplt_epi32(
            _mm_setr_epi32(0, 1, 2, 3),
            _mm_set1_epi32(count as i32),
        ));
        let hit = _mm_and_ps(_mm_andnot_ps(miss, inside), used);
        let out = _mm_blendv_or(hit, t, _mm_set1_ps(f32::INFINITY));
        // A zero edge function is decided again in f64 (the ray meets an edge's line): those
        // lanes take the scalar path, which does exactly that.
        let edge = _mm_or_ps(
            _mm_or_ps(_mm_cmpeq_ps(u, zero), _mm_cmpeq_ps(v, zero)),
            _mm_cmpeq_ps(w, zero),
        );
        let redo = _mm_movemask_ps(edge) as u32 & lanes;
        if redo == 0 {
            out
        } else {
            self.redo(wt, block, redo, out, tmin, tmax)
        }
    }

    /// The lanes of `redo` by the scalar test, the others as in `out`: out of line, so that the
    /// rare path's calls do not make the vector test spill its registers.
    #[cfg(target_arch = "x86_64")]
    #[cold]
    #[inline(never)]
    fn redo(
        &self,
        wt: &Watertight,
        block: usize,
        mut redo: u32,
        out: std::arch::x86_64::__m128,
        tmin: f32,
        tmax: f32,
    ) -> std::arch::x86_64::__m128 {
        use std::arch::x86_64::*;
        let mut lanes = [0.0f32; 4];
        // SAFETY: SSE2 is part of x86_64; `lanes` holds four f32.
        unsafe { _mm_storeu_ps(lanes.as_mut_ptr(), out) };
        while redo != 0 {
            let k = redo.trailing_zeros() as usize;
            redo &= redo - 1;
            lanes[k] = wt.intersect(&self.triangle(block, k), tmin, tmax);
        }
        // SAFETY: as above.
        unsafe { _mm_loadu_ps(lanes.as_ptr()) }
    }

    /// The distances of [`Watertight::intersect`] to the first `count` triangles of block `block`
    /// (lanes `count..` hold infinity), read in the vector registers: the lanes hit,
    /// those hit less than `epsilon` past `tmin` (`t − tmin < epsilon`, in f32), which need a
    /// second look, and the nearest lane.
    #[inline(always)]
    pub fn lanes4(
        &self,
        wt: &Watertight,
        block: usize,
        count: usize,
        (tmin, tmax): (f32, f32),
        epsilon: f32,
    ) -> Lanes4 {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: SSE2 is part of x86_64.
        unsafe {
            use std::arch::x86_64::*;
            let t = self.intersect4_sse(wt, block, count, tmin, tmax);
            let mut ts = [0.0f32; 4];
            _mm_storeu_ps(ts.as_mut_ptr(), t);
            let near = _mm_cmplt_ps(_mm_sub_ps(t, _mm_set1_ps(tmin)), _mm_set1_ps(epsilon));
            let m = _mm_min_ps(t, _mm_shuffle_ps::<0b01_00_11_10>(t, t));
            let m = _mm_min_ps(m, _mm_shuffle_ps::<0b10_11_00_01>(m, m));
            // Some lane equals the minimum (no NaN arises), so the mask is not empty.
            let lane = (_mm_movemask_ps(_mm_cmpeq_ps(t, m)) as u32).trailing_zeros();
            Lanes4 {
                hit: _mm_movemask_ps(_mm_cmplt_ps(t, _mm_set1_ps(f32::INFINITY))) as u32,
                near: _mm_movemask_ps(near) as u32,
                nearest: (_mm_cvtss_f32(m), lane),
                ts,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let ts = self.intersect4(wt, block, count, tmin, tmax);
            let mask = |f: &dyn Fn(f32) -> bool| (0..4).fold(0, |m, k| m | (f(ts[k]) as u32) << k);
            let t = ts.iter().fold(f32::INFINITY, |a, &b| a.min(b));
            Lanes4 {
                hit: mask(&|t| t < f32::INFINITY),
                near: mask(&|t| t - tmin < epsilon),
                nearest: (t, ts.iter().position(|&x| x == t).unwrap_or(0) as u32),
                ts,
            }
        }
    }
}

/// What [`TriangleBlocks::lanes4`] reads from a block's four distances.
pub struct Lanes4 {
    /// Every lane's distance (infinity for a miss).
    pub ts: [f32; 4],
    /// Lanes hit.
    pub hit: u32,
    /// Lanes hit less than the epsilon past `tmin` (a subset of `hit`).
    pub near: u32,
    /// The smallest distance (infinity when every lane missed) and its lowest lane.
    pub nearest: (f32, u32),
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The paper's set-up as written out with branches (Woop, Benthin and Wald 2013): kz the
    /// largest dimension of |d| (the first on ties, as relume always chose), kx and ky the next
    /// two cyclically, swapped when d[kz] < 0.
    fn paper(d: [f32; 3]) -> ([usize; 3], [f32; 3]) {
        let a = d.map(f32::abs);
        let kz = if a[0] >= a[1] && a[0] >= a[2] {
            0
        } else if a[1] >= a[2] {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / d[kz];
        ([kx, ky, kz], [-(d[kx] * sz), -(d[ky] * sz), sz])
    }

    fn component() -> impl Strategy<Value = f32> {
        // Ties between axes (equal magnitudes, either sign) and signed zeros are the cases the
        // branch-free selection must order as the paper does.
        prop_oneof![
            Just(0.0f32),
            Just(-0.0f32),
            Just(0.5f32),
            Just(-0.5f32),
            -1.0f32..1.0
        ]
    }

    proptest! {
        #[test]
        fn the_set_up_is_the_papers(d in prop::array::uniform3(component())) {
            let wt = Watertight::new(Vec3A::ZERO, Vec3A::from(d));
            let (axes, shear) = paper(d);
            prop_assert_eq!(wt.axes, axes);
            prop_assert_eq!(wt.shear.map(f32::to_bits), shear.map(f32::to_bits));
        }
    }
}
