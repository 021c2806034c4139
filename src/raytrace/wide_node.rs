//! One node of the 8-wide BVH and the ray prepared for it: eight child boxes stored as planes
//! (6 × 8 floats, Embree's BVH8 layout) and the slab test of all eight at once, in one AVX2 pass
//! where AVX2 and FMA are detected and a portable loop with the same operations elsewhere.
//!
//! The test is conservative: a box the exact ray meets within `[tmin, tmax]` is always entered
//! (the rounding argument is at [`BoxRay`]). [`crate::raytrace::wide_bvh`] builds and walks the tree.

/// A child reference: a node index, or a leaf (`LEAF` bit set): `LEAF | leaf << 3 | count`, the
/// leaf's number (its position in [`WideBvh::leaves`], depth-first order) and its primitive count.
pub(super) const LEAF: u32 = 1 << 31;
pub(super) const EMPTY: u32 = u32::MAX;

/// 1 + 2γ₃ with γₙ = n·u / (1 − n·u), u = 2⁻²⁴, rounded up (Ize 2013, eq. 14).
const FAR_SCALE: f32 = 1.0 + 2.0 * (3.0 * 5.960_464_5e-8 / (1.0 - 3.0 * 5.960_464_5e-8)) * 1.0001;

/// Eight children: their boxes as planes (min x, y, z, max x, y, z) × 8 lanes, and references.
/// An empty slot has an inverted box (+∞ … −∞) that no ray enters.
#[derive(Clone, Copy)]
#[repr(C, align(32))]
pub(super) struct Node {
    pub(super) planes: [[f32; 8]; 6],
    pub(super) child: [u32; 8],
}

impl Node {
    /// Eight empty slots.
    pub(super) const EMPTY: Node = Node {
        planes: [
            [f32::INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::NEG_INFINITY; 8],
        ],
        child: [EMPTY; 8],
    };

    /// Put the box `lo..hi` with reference `child` into `slot`.
    pub(super) fn set(&mut self, slot: usize, (lo, hi): ([f32; 3], [f32; 3]), child: u32) {
        for k in 0..3 {
            self.planes[k][slot] = lo[k];
            self.planes[3 + k][slot] = hi[k];
        }
        self.child[slot] = child;
    }
}

/// A ray prepared for the slab tests, which compute a plane's distance as one fused
/// multiply-subtract `b·(1/d) − o·(1/d)`.
///
/// Rounding: `1/d`, the product `o·(1/d)` and the fused result are each rounded. The product's
/// error is absolute (up to an ulp of `o/d`, which can dwarf the distance), so the offset is
/// stored twice, pushed 4 ulps outward: the near planes subtract `o/d + e` and the far planes
/// `o/d − e`, which moves every near distance down and every far one up by more than that
/// error. The other two roundings are relative to the distance and covered by scaling the far
/// distance by 1 + 2γ₃ (Ize, "Robust BVH ray traversal", JCGT 2013). So a box the exact ray
/// meets within `[tmin, tmax]` is always entered.
///
/// A direction component under 2⁻⁶⁴ in magnitude (zero included) is replaced by ±2⁻⁶⁴ (the
/// sign of the component, so −0 counts as negative) and its slab widened by 2⁻³² on both sides
/// (2³² added to the offsets' push): up to t = 2³², far beyond any grid, the true ray stays
/// within 2⁻³² of its origin on that axis, so the widened slab holds it wherever the slab does,
/// and nothing is ever ∞ − ∞ or 0 · ∞ (the proptest below checks against exact slabs).
#[derive(Clone, Copy)]
pub struct BoxRay {
    inv: [f32; 3],
    /// `o/d` pushed outward: subtracted for the near planes (`near_offset` ≥ o/d) and for the
    /// far planes (`far_offset` ≤ o/d).
    near_offset: [f32; 3],
    far_offset: [f32; 3],
    /// For each axis the plane row (0..6) a ray enters the slab through.
    near: [usize; 3],
}

impl BoxRay {
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Self {
        const TINY: f32 = 1.0 / (1u64 << 63) as f32 / 2.0; // 2⁻⁶⁴
        const WIDEN: f32 = (1u64 << 32) as f32; // 2³²: 2⁻³² of slab at 1/TINY per unit
        let tiny = dir.map(|d| d.abs() < TINY);
        let d: [f32; 3] = std::array::from_fn(|k| {
            if tiny[k] {
                TINY.copysign(dir[k])
            } else {
                dir[k]
            }
        });
        // One division for the three axes.
        let inv = (glam::Vec3A::ONE / glam::Vec3A::from(d)).to_array();
        let mut ray = BoxRay {
            inv,
            near_offset: [0.0; 3],
            far_offset: [0.0; 3],
            near: [0; 3],
        };
        for k in 0..3 {
            let oi = origin[k] * inv[k];
            let e = oi.abs() * (4.0 * f32::EPSILON) + if tiny[k] { WIDEN } else { 0.0 };
            ray.near_offset[k] = oi + e;
            ray.far_offset[k] = oi - e;
            ray.near[k] = if d[k] < 0.0 { 3 + k } else { k };
        }
        ray
    }
}

/// The slab test of the eight children, one lane at a time: bit k of the result is set when the
/// ray meets child k's box within `[tmin, tmax]`, and `dist[k]` is then its entry distance; bit
/// 8 + k when child k is a leaf (or an empty slot, which no ray enters).
#[inline(always)]
pub(super) fn node_hits_portable(
    node: &Node,
    ray: &BoxRay,
    tmin: f32,
    tmax: f32,
    dist: &mut [f32; 8],
) -> u32 {
    let mut mask = 0;
    for (k, dist) in dist.iter_mut().enumerate() {
        let mut near = tmin;
        let mut far = f32::INFINITY;
        for a in 0..3 {
            let n = node.planes[ray.near[a]][k].mul_add(ray.inv[a], -ray.near_offset[a]);
            let f = node.planes[(ray.near[a] + 3) % 6][k].mul_add(ray.inv[a], -ray.far_offset[a]);
            near = near.max(n);
            far = far.min(f);
        }
        far = (far * FAR_SCALE).min(tmax);
        *dist = near;
        if near <= far {
            mask |= 1 << k;
        }
        if node.child[k] & LEAF != 0 {
            mask |= 1 << (8 + k);
        }
    }
    mask
}

/// [`node_hits_portable`] for all eight lanes at once (AVX2 + FMA). Same operations, same order
/// per lane, so the same masks and distances (the leaf bits are the references' sign bits): `mul_add` is the fused operation, `max`/`min` of
/// two floats are exact (no NaN arises: see [`BoxRay`]), and the running near bound never holds
/// −0 (it starts at `tmin` > 0).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline]
pub(super) unsafe fn node_hits_avx2(
    node: &Node,
    ray: &BoxRay,
    tmin: f32,
    tmax: f32,
    dist: &mut [f32; 8],
) -> u32 {
    use std::arch::x86_64::*;
    let p = node.planes.as_ptr() as *const f32;
    let mut near = _mm256_set1_ps(tmin);
    let mut far = _mm256_set1_ps(f32::INFINITY);
    for a in 0..3 {
        let inv = _mm256_set1_ps(ray.inv[a]);
        let row_near = ray.near[a];
        let row_far = (row_near + 3) % 6;
        // SAFETY: rows are 32-byte aligned (`Node` is `align(32)`, each row 32 bytes).
        let n = _mm256_fmsub_ps(
            _mm256_load_ps(p.add(8 * row_near)),
            inv,
            _mm256_set1_ps(ray.near_offset[a]),
        );
        let f = _mm256_fmsub_ps(
            _mm256_load_ps(p.add(8 * row_far)),
            inv,
            _mm256_set1_ps(ray.far_offset[a]),
        );
        near = _mm256_max_ps(n, near);
        far = _mm256_min_ps(f, far);
    }
    let far = _mm256_min_ps(
        _mm256_mul_ps(far, _mm256_set1_ps(FAR_SCALE)),
        _mm256_set1_ps(tmax),
    );
    _mm256_storeu_ps(dist.as_mut_ptr(), near);
    let leaves = _mm256_movemask_ps(_mm256_load_ps(node.child.as_ptr() as *const f32)) as u32;
    _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(near, far)) as u32 | leaves << 8
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn node(boxes: &[([f32; 3], [f32; 3])]) -> Node {
        let mut n = Node::EMPTY;
        for (k, b) in boxes.iter().enumerate() {
            n.set(k, *b, k as u32);
        }
        n
    }

    fn coordinate() -> impl Strategy<Value = f32> {
        // Grid-like values, so that origins often lie exactly on box planes.
        prop_oneof![(-4i32..5).prop_map(|x| x as f32 * 0.25), -2.0f32..2.0]
    }

    fn direction() -> impl Strategy<Value = f32> {
        prop_oneof![Just(0.0f32), Just(-0.0f32), -1.0f32..1.0]
    }

    proptest! {
        /// The AVX2 node test is the portable one's twin: the same hit and leaf masks and the
        /// same entry distances bit for bit, with empty slots, flat boxes and zero direction
        /// components.
        #[test]
        fn avx2_node_test_equals_the_portable_one(
            boxes in prop::collection::vec((prop::array::uniform3(coordinate()), prop::array::uniform3(0u8..3)), 0..=8),
            o in prop::array::uniform3(coordinate()),
            d in prop::array::uniform3(direction()),
            tmax in prop_oneof![Just(f32::INFINITY), 0.1f32..5.0],
        ) {
            let boxes: Vec<_> = boxes
                .iter()
                .map(|(lo, size)| (*lo, std::array::from_fn(|a| lo[a] + size[a] as f32 * 0.25)))
                .collect();
            let n = node(&boxes);
            let ray = BoxRay::new(o, d);
            let mut a = [0.0; 8];
            let full = node_hits_portable(&n, &ray, 1e-4, tmax, &mut a);
            let ma = full & 0xff;
            // The test's children are node references; only the empty slots have the leaf bit.
            prop_assert_eq!(full >> 8, (0xff << boxes.len()) & 0xff);
            // Exact reference: the ray meets the box where every axis allows it.
            for (k, (lo, hi)) in boxes.iter().enumerate() {
                let (mut near, mut far) = (1e-4f64, tmax as f64);
                for ax in 0..3 {
                    let (o, d) = (o[ax] as f64, d[ax] as f64);
                    if d == 0.0 {
                        if (o < lo[ax] as f64) || (o > hi[ax] as f64) {
                            far = -1.0;
                        }
                    } else {
                        let (t0, t1) = ((lo[ax] as f64 - o) / d, (hi[ax] as f64 - o) / d);
                        near = near.max(t0.min(t1));
                        far = far.min(t0.max(t1));
                    }
                }
                if near <= far {
                    prop_assert!(ma & (1 << k) != 0, "box {k} {lo:?}..{hi:?} missed, exact {near}..{far}");
                }
            }
            prop_assert_eq!(ma >> boxes.len(), 0, "an empty slot was entered");
            #[cfg(target_arch = "x86_64")]
            if crate::cpu::has_avx2_fma() {
                let mut b = [0.0; 8];
                // SAFETY: AVX2 and FMA detected.
                let mb = unsafe { node_hits_avx2(&n, &ray, 1e-4, tmax, &mut b) };
                prop_assert_eq!(full, mb);
                for k in 0..8 {
                    if ma & (1 << k) != 0 {
                        prop_assert_eq!(a[k].to_bits(), b[k].to_bits());
                    }
                }
            }
        }

    }
}
