//! An 8-wide BVH with uncompressed f32 child boxes, traversed one ray at a time with all eight
//! slab tests in one AVX2 pass (chosen at run time; a portable loop elsewhere). The node and its
//! slab test are in [`crate::raytrace::wide_node`]; this file builds the tree and walks it.
//!
//! Why not obvhs's own traversal: its CWBVH node stores 8-bit child planes that every visit
//! decodes, and it tests them four at a time with SSE2. On the rays of the form-factor stage
//! that ran at 0.44–0.85x Embree per core (docs/radiosity.md); this layout (Embree's BVH8 idea:
//! boxes stored as 6 × 8 floats, a child's entry distance from one fused multiply-subtract per
//! plane) is what `benches/visibility_embree.rs` measures against it.
//!
//! The tree's *shape* comes from obvhs's binary tree (its PLOC build and reinsertion optimiser
//! make the tree quality that matters most, see docs/radiosity.md), collapsed to eight children
//! and leaves of up to four triangles by [`crate::raytrace::wide_collapse`]; the child boxes are exact,
//! refitted from the primitives' own boxes, and sit in their node's slots largest first (the
//! order occlusion visits them in, [`WideBvh::any`]).
//!
//! Preconditions: primitive boxes are finite. The traversal is conservative: a child box is
//! entered whenever the exact ray meets it (the rounding argument is at [`BoxRay`]), so a leaf
//! test that hits a primitive in exact arithmetic is always reached.

use crate::raytrace::wide_collapse::{Child, MAX_LEAF};
#[cfg(target_arch = "x86_64")]
use crate::raytrace::wide_node::node_hits_avx2;
use crate::raytrace::wide_node::{node_hits_portable, BoxRay, Node, EMPTY, LEAF};
use obvhs::aabb::Aabb;

/// The tree. Leaf tests get a leaf's number; [`WideBvh::leaves`] maps it to its primitives.
pub struct WideBvh {
    nodes: Vec<Node>,
    /// Each leaf's primitives as (first, count): positions in the primitive order of
    /// [`WideBvh::from_collapsed`].
    leaves: Vec<(u32, u32)>,
    root: u32,
    avx2: bool,
    /// Boxes up to this far beyond `tmax` are still entered: a leaf test's distance is rounded
    /// (the watertight test's by a few ulps of the largest coordinate, not of the distance), so
    /// a box whose rounded entry lies just past a hit may hold a triangle whose rounded distance
    /// ties or beats it. 2⁻¹⁸ of the largest coordinate magnitude: 64 of its ulps.
    margin: f32,
}

/// What a leaf test reports to a closest-hit traversal.
pub trait ClosestLeaf {
    /// Test the `count` primitives of leaf number `leaf` (closest hits below `tmax`) and return
    /// the new `tmax` (unchanged when none is closer).
    fn leaf(&mut self, leaf: u32, count: u32, tmax: f32) -> f32;
}

/// What a leaf test reports to an occlusion traversal.
pub trait AnyLeaf {
    /// Whether one of the `count` primitives of leaf number `leaf` stops the ray.
    fn leaf(&mut self, leaf: u32, count: u32) -> bool;
}

impl WideBvh {
    /// The tree of the collapsed `nodes` ([`crate::raytrace::wide_collapse::collapse`]), with exact child
    /// boxes: `prim_box(p)` is the box of primitive `p` as (min, max). Returns the tree and the
    /// primitives in leaf order ([`WideBvh::leaves`] indexes them).
    pub fn from_collapsed(
        nodes: &[Vec<Child>],
        prim_box: impl Fn(u32) -> ([f32; 3], [f32; 3]),
    ) -> (Self, Vec<u32>) {
        let avx2 = crate::cpu::has_avx2_fma();
        if nodes.is_empty() {
            let empty = WideBvh {
                nodes: Vec::new(),
                leaves: Vec::new(),
                root: EMPTY,
                avx2,
                margin: 0.0,
            };
            return (empty, Vec::new());
        }
        let mut tree = Refit {
            src: nodes,
            prim_box: &prim_box,
            nodes: vec![Node::EMPTY; nodes.len()],
            leaves: Vec::new(),
            order: Vec::new(),
        };
        let whole = tree.node(0);
        let largest = whole.min.abs().max(whole.max.abs()).max_element();
        let bvh = WideBvh {
            nodes: tree.nodes,
            leaves: tree.leaves,
            root: 0,
            avx2,
            margin: largest * (1.0 / (1 << 18) as f32),
        };
        (bvh, tree.order)
    }

    /// Each leaf's primitives as (first, count), by leaf number: positions in the primitive
    /// order that [`WideBvh::from_collapsed`] returned; count ≤ 4.
    pub fn leaves(&self) -> &[(u32, u32)] {
        &self.leaves
    }

    /// The closest hit below `tmax`: every leaf whose box the ray meets before the current
    /// closest distance (plus the rounding margin) is handed to `leaf`. Of a node's hit
    /// children the nearest is visited next and the others wait on the stack in slot order
    /// (sorting them all cost more than it saved: furnished room 210 → 199 ns per ray, soup
    /// 510 → 477, docs/radiosity.md), each dropped when popped beyond the closest distance.
    /// Returns the final `tmax`.
    pub fn closest<L: ClosestLeaf>(&self, ray: &BoxRay, tmin: f32, tmax: f32, leaf: &mut L) -> f32 {
        // Entry distances are ≥ tmin and compared by their bits, which order like the floats
        // only for positive values.
        debug_assert!(tmin > 0.0);
        if self.root == EMPTY {
            return tmax;
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: AVX2 and FMA were detected at run time.
            return unsafe { self.closest_avx2(ray, tmin, tmax, leaf) };
        }
        self.closest_with(ray, tmin, tmax, leaf, node_hits_portable)
    }

    /// True when some leaf test reports a hit: `leaf.leaf(leaf, count)` is asked for every leaf whose
    /// box the ray meets in `[tmin, tmax]` until one says true.
    ///
    /// Order: a node's children sit in its slots largest box first (half surface area), and
    /// the traversal takes them in slot order: its hit leaves first, then its hit inner
    /// children (the first visited next, the others pushed last slot first, so popped in slot
    /// order). A larger box is more likely to hold what stops the ray; on the furnished room
    /// this order made occlusion 8–10 % faster than the collapse's own child order
    /// (docs/radiosity.md, form_factors, "the largest box first").
    pub fn any(&self, ray: &BoxRay, tmin: f32, tmax: f32, leaf: &mut impl AnyLeaf) -> bool {
        if self.root == EMPTY {
            return false;
        }
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: AVX2 and FMA were detected at run time.
            return unsafe { self.any_avx2(ray, tmin, tmax, leaf) };
        }
        self.any_with(ray, tmin, tmax, leaf, node_hits_portable)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn closest_avx2<L: ClosestLeaf>(
        &self,
        ray: &BoxRay,
        tmin: f32,
        tmax: f32,
        leaf: &mut L,
    ) -> f32 {
        self.closest_with(ray, tmin, tmax, leaf, |n, r, a, b, d| unsafe {
            node_hits_avx2(n, r, a, b, d)
        })
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn any_avx2(&self, ray: &BoxRay, tmin: f32, tmax: f32, leaf: &mut impl AnyLeaf) -> bool {
        self.any_with(ray, tmin, tmax, leaf, |n, r, a, b, d| unsafe {
            node_hits_avx2(n, r, a, b, d)
        })
    }

    #[inline(always)]
    fn closest_with<L: ClosestLeaf>(
        &self,
        ray: &BoxRay,
        tmin: f32,
        mut tmax: f32,
        leaf: &mut L,
        hits: impl Fn(&Node, &BoxRay, f32, f32, &mut [f32; 8]) -> u32,
    ) -> f32 {
        // Entries (entry distance bits << 32 | child): distances are ≥ tmin ≥ 0, so their bits
        // order like the floats.
        let mut stack = Stack::<u64>::new();
        let mut current = self.root;
        let mut dist = [0.0f32; 8];
        loop {
            if current & LEAF != 0 {
                tmax = leaf.leaf((current & !LEAF) >> 3, current & 7, tmax);
            } else {
                let node = &self.nodes[current as usize];
                let mut mask = hits(node, ray, tmin, tmax + self.margin, &mut dist) & 0xff;
                if mask != 0 {
                    let k = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if mask == 0 {
                        current = node.child[k];
                        continue;
                    }
                    // Visit the nearest hit child next; push the others (slot order).
                    let mut best = (dist[k].to_bits() as u64) << 32 | k as u64;
                    let mut rest = mask;
                    while rest != 0 {
                        let j = rest.trailing_zeros() as usize;
                        rest &= rest - 1;
                        best = best.min((dist[j].to_bits() as u64) << 32 | j as u64);
                    }
                    let nearest = best as u32 as usize;
                    let mut others = (mask | 1 << k) & !(1 << nearest);
                    while others != 0 {
                        let j = others.trailing_zeros() as usize;
                        others &= others - 1;
                        stack.push((dist[j].to_bits() as u64) << 32 | node.child[j] as u64);
                    }
                    current = node.child[nearest];
                    continue;
                }
            }
            // Pop the nearest entry still in front of the closest hit.
            loop {
                let Some(e) = stack.pop() else {
                    return tmax;
                };
                if f32::from_bits((e >> 32) as u32) <= tmax + self.margin {
                    current = e as u32;
                    break;
                }
            }
        }
    }

    #[inline(always)]
    fn any_with(
        &self,
        ray: &BoxRay,
        tmin: f32,
        tmax: f32,
        leaf: &mut impl AnyLeaf,
        hits: impl Fn(&Node, &BoxRay, f32, f32, &mut [f32; 8]) -> u32,
    ) -> bool {
        // Leaves are tested at the node that holds them, so the stack only ever holds nodes;
        // the first hit node is visited next without going through the stack.
        let mut items = [const { std::mem::MaybeUninit::<u32>::uninit() }; STACK];
        let mut sp = 0usize;
        let mut current = self.root;
        if current & LEAF != 0 {
            return leaf.leaf((current & !LEAF) >> 3, current & 7);
        }
        let mut dist = [0.0f32; 8];
        loop {
            let node = &self.nodes[current as usize];
            let both = hits(node, ray, tmin, tmax + self.margin, &mut dist);
            let mut leaves = both & (both >> 8) & 0xff;
            let mut inner = both & !(both >> 8) & 0xff;
            while leaves != 0 {
                let k = leaves.trailing_zeros() as usize;
                leaves &= leaves - 1;
                let c = node.child[k];
                if leaf.leaf((c & !LEAF) >> 3, c & 7) {
                    return true;
                }
            }
            if inner != 0 {
                let k = inner.trailing_zeros() as usize;
                inner &= inner - 1;
                current = node.child[k];
                assert!(sp + 8 <= STACK, "BVH traversal stack overflow");
                while inner != 0 {
                    let k = 31 - inner.leading_zeros() as usize;
                    inner &= !(1 << k);
                    // SAFETY: sp + 7 < STACK, checked above.
                    unsafe { items.get_unchecked_mut(sp).write(node.child[k]) };
                    sp += 1;
                }
                continue;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: slots below sp were written above.
            current = unsafe { items.get_unchecked(sp).assume_init() };
        }
    }
}

/// Deep enough for any tree obvhs builds: each level pushes at most 7 entries, and a tree of
/// 2³¹ leaves of 8-wide nodes is under 32 levels deep when balanced; PLOC trees are not balanced,
/// so the bound is kept wide (a deeper tree panics on the push rather than writing past it).
const STACK: usize = 1024;

/// The traversal stack, left uninitialised: zeroing 1024 entries per ray cost more than tracing
/// the Cornell box (measured: 2.8 against 4.8 Mrays/s).
struct Stack<T: Copy> {
    items: [std::mem::MaybeUninit<T>; STACK],
    len: usize,
}

impl<T: Copy> Stack<T> {
    #[inline(always)]
    fn new() -> Self {
        Stack {
            items: [const { std::mem::MaybeUninit::uninit() }; STACK],
            len: 0,
        }
    }

    #[inline(always)]
    fn push(&mut self, x: T) {
        self.items[self.len].write(x);
        self.len += 1;
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: every slot below `len` was written by `push`.
        Some(unsafe { self.items[self.len].assume_init() })
    }
}

/// The exact boxes of a collapsed tree, filled from its root.
struct Refit<'a, F> {
    src: &'a [Vec<Child>],
    prim_box: &'a F,
    nodes: Vec<Node>,
    leaves: Vec<(u32, u32)>,
    order: Vec<u32>,
}

impl<F: Fn(u32) -> ([f32; 3], [f32; 3])> Refit<'_, F> {
    /// Fill `nodes[index]` from the collapsed node of the same index and return its exact box.
    fn node(&mut self, index: usize) -> Aabb {
        let src = self.src;
        let mut whole = Aabb::INVALID;
        assert!(src[index].len() <= 8, "a node has at most eight children");
        let mut slots = Vec::with_capacity(8);
        for child in src[index].iter() {
            let (reference, b) = match child {
                Child::Node(c) => (*c as u32, self.node(*c)),
                Child::Leaf(prims) => {
                    assert!(
                        (1..=MAX_LEAF as usize).contains(&prims.len()),
                        "a leaf holds 1 to {MAX_LEAF} primitives"
                    );
                    let mut b = Aabb::INVALID;
                    for &p in prims {
                        let (lo, hi) = (self.prim_box)(p);
                        b = b.union(&Aabb::new(lo.into(), hi.into()));
                    }
                    let id = self.leaves.len() as u32;
                    assert!(id < 1 << 28, "more leaves than a reference can address");
                    self.leaves
                        .push((self.order.len() as u32, prims.len() as u32));
                    self.order.extend_from_slice(prims);
                    (LEAF | id << 3 | prims.len() as u32, b)
                }
            };
            slots.push((b.half_area(), b, reference));
            whole = whole.union(&b);
        }
        // Largest box first: see the occlusion traversal in [`WideBvh::any`].
        slots.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (slot, (_, b, reference)) in slots.into_iter().enumerate() {
            self.nodes[index].set(slot, (b.min.to_array(), b.max.to_array()), reference);
        }
        whole
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;
    use proptest::prelude::*;

    proptest! {
        /// The refit keeps every child and puts a node's children largest box first, each
        /// slot holding the exact union of its primitives' boxes.
        #[test]
        fn refit_puts_children_largest_box_first(
            sizes in prop::collection::vec((0u8..4, prop::array::uniform3(0.0f32..4.0), prop::array::uniform3(0.01f32..3.0)), 2..=8),
        ) {
            // A root whose children are one-primitive leaves and, for a size of 0, a node of two.
            let mut boxes = Vec::new();
            let mut nodes: Vec<Vec<Child>> = vec![Vec::new()];
            for (kind, lo, e) in &sizes {
                let b = (*lo, std::array::from_fn(|k| lo[k] + e[k]));
                if *kind == 0 {
                    let half = (*lo, std::array::from_fn(|k| lo[k] + 0.5 * e[k]));
                    boxes.extend([b, half]);
                    let n = boxes.len() as u32;
                    let c = nodes.len();
                    nodes[0].push(Child::Node(c));
                    nodes.push(vec![Child::Leaf(vec![n - 2]), Child::Leaf(vec![n - 1])]);
                } else {
                    boxes.push(b);
                    nodes[0].push(Child::Leaf(vec![boxes.len() as u32 - 1]));
                }
            }
            let (bvh, order) = WideBvh::from_collapsed(&nodes, |p| boxes[p as usize]);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            prop_assert_eq!(sorted, (0..boxes.len() as u32).collect::<Vec<_>>());
            for node in &bvh.nodes {
                let used: Vec<_> = (0..8).filter(|&k| node.child[k] != EMPTY).collect();
                let area: Vec<f32> = used
                    .iter()
                    .map(|&k| {
                        let corner = |r: usize| Vec3A::from_array(std::array::from_fn(|a| node.planes[r + a][k]));
                        Aabb::new(corner(0), corner(3)).half_area()
                    })
                    .collect();
                prop_assert!(area.windows(2).all(|w| w[0] >= w[1]), "slots out of order: {:?}", area);
                prop_assert_eq!(used.len(), used.last().map_or(0, |&k| k + 1), "slots not packed");
            }
            // Root slots hold exactly the children's boxes (a node child: the first of its two).
            let root = &bvh.nodes[0];
            let mut found: Vec<[u32; 6]> = (0..sizes.len())
                .map(|k| std::array::from_fn(|r| root.planes[r][k].to_bits()))
                .collect();
            let mut want: Vec<[u32; 6]> = sizes
                .iter()
                .map(|(_, lo, e)| {
                    let hi: [f32; 3] = std::array::from_fn(|k| lo[k] + e[k]);
                    std::array::from_fn(|r| if r < 3 { lo[r] } else { hi[r - 3] }.to_bits())
                })
                .collect();
            found.sort_unstable();
            want.sort_unstable();
            prop_assert_eq!(found, want);
        }
    }
}
