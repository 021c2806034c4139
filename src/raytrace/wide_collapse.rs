//! The shape of the 8-wide tree: obvhs builds a binary tree with leaves of one triangle
//! (`build_bvh2_from_tris`: PLOC over pre-split boxes, then its reinsertion optimiser, twice:
//! the tree quality that matters most), and this collapses it into
//! nodes of up to eight children and leaves of up to four triangles by the dynamic programme of
//! Ylitie, Karras and Laine ("Efficient incoherent ray traversal on GPUs through compressed
//! wide BVHs", HPG 2017), as obvhs's own CWBVH conversion does, with two differences:
//! - **Leaves of up to four triangles**, the four lanes of one watertight test
//!   (`watertight::TriangleBlocks`); the CWBVH format caps them at three.
//! - **A flat leaf cost.** obvhs charges a leaf 0.3 of a node per triangle. Here a leaf of one
//!   to four triangles costs [`LEAF_COST`] times a node test whatever its count, since its four
//!   lanes are tested in one pass. On the furnished room the leaves grew from 1.6 to 3.4
//!   triangles on average; the random soup's rays got 7–11 % faster, the furnished room's
//!   did not move (docs/radiosity.md).
//!
//! The decisions are written into obvhs's own converter (`Bvh2Converter::decisions`), whose
//! `get_children` then lists each node's up to eight children as obvhs does.
//!
//! Preconditions: at least one primitive, and every leaf of the binary tree holds exactly one
//! (`build_bvh2_from_tris` with `max_prims_per_leaf: 1`).

use obvhs::bvh2::Bvh2;
use obvhs::cwbvh::bvh2_to_cwbvh::{Bvh2Converter, Decision, DecisionKind};

/// Most triangles in a leaf: the lanes of one four-lane test.
pub const MAX_LEAF: u32 = 4;

/// A leaf's cost relative to a node test's, per unit of half area (SAH). Measured on the
/// random soup and the furnished room between 0.3 and 2.5 (docs/radiosity.md): 1.0 and 1.5
/// were best and within noise of each other.
pub const LEAF_COST: f32 = 1.0;

/// One child of a collapsed node: an inner node (its index in the visit order of [`collapse`])
/// or a leaf (its primitives, in order).
pub enum Child {
    Node(usize),
    Leaf(Vec<u32>),
}

/// The collapsed tree as the 8-wide BVH's builder takes it: for each node (root first,
/// depth-first) its up to eight children. A leaf's primitives are the binary tree's
/// `primitive_indices` entries under it, each primitive once (a pre-split triangle's pieces
/// may fall into one leaf).
pub fn collapse(bvh2: &Bvh2) -> Vec<Vec<Child>> {
    assert!(!bvh2.nodes.is_empty(), "collapse needs a non-empty tree");
    let mut conv = Bvh2Converter::new(bvh2, false, false);
    costs(&mut conv.decisions, bvh2, 0);
    let mut nodes = Vec::new();
    node(&mut conv, 0, &mut nodes);
    nodes
}

/// Append binary node `n2`'s collapsed node (and, after it, its inner children's), and return
/// its index.
fn node(conv: &mut Bvh2Converter, n2: usize, out: &mut Vec<Vec<Child>>) -> usize {
    let index = out.len();
    out.push(Vec::new());
    let mut children = [u32::MAX; 8];
    let mut count = 0;
    conv.get_children(n2, &mut children, &mut count, 0);
    let mut list = Vec::with_capacity(count as usize);
    for &c in &children[..count as usize] {
        let c = c as usize;
        // A binary leaf's decisions are all LEAF (`costs`).
        let leaf = conv.decisions[c * 7].kind == DecisionKind::LEAF;
        list.push(if leaf {
            Child::Leaf(primitives(conv.bvh2, c))
        } else {
            Child::Node(node(conv, c, out))
        });
    }
    out[index] = list;
    index
}

/// The primitives under binary node `n`, sorted, each once.
fn primitives(bvh2: &Bvh2, n: usize) -> Vec<u32> {
    let mut out = Vec::new();
    let mut stack = vec![n];
    while let Some(n) = stack.pop() {
        let node = &bvh2.nodes[n];
        if node.is_leaf() {
            let first = node.first_index as usize;
            out.extend_from_slice(&bvh2.primitive_indices[first..first + node.prim_count as usize]);
        } else {
            stack.push(node.first_index as usize + 1);
            stack.push(node.first_index as usize);
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Fill the decisions of binary node `n`'s subtree (seven per node: the best cost of the
/// subtree spread over at most i + 1 slots, i = 0..7, and how) and return its primitive count.
/// obvhs's `calculate_cost_impl` (after jan-van-bergen's GPU-Raytracer), with the leaf cost of
/// the module notes.
fn costs(dec: &mut [Decision], bvh2: &Bvh2, n: usize) -> u32 {
    let node = &bvh2.nodes[n];
    let area = node.aabb().half_area();
    let base = n * 7;
    if node.is_leaf() {
        for d in &mut dec[base..base + 7] {
            d.kind = DecisionKind::LEAF;
            d.cost = area * LEAF_COST;
        }
        return node.prim_count;
    }
    let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
    let count = costs(dec, bvh2, l) + costs(dec, bvh2, r);
    let (l7, r7) = (l * 7, r * 7);
    // One slot: a leaf, or an inner node whose children share eight slots.
    let leaf = if count <= MAX_LEAF {
        area * LEAF_COST
    } else {
        f32::INFINITY
    };
    let (mut split, mut dl, mut dr) = (f32::INFINITY, u8::MAX, u8::MAX);
    for k in 0..7 {
        let c = dec[l7 + k].cost + dec[r7 + 6 - k].cost;
        if c < split {
            (split, dl, dr) = (c, k as u8, 6 - k as u8);
        }
    }
    let inner = split + area;
    let d = &mut dec[base];
    (d.kind, d.cost) = if leaf < inner {
        (DecisionKind::LEAF, leaf)
    } else {
        (DecisionKind::INTERNAL, inner)
    };
    (d.distribute_left, d.distribute_right) = (dl, dr);
    // i + 1 slots: the best of i slots, or the two children spread over them.
    for i in 1..7 {
        let mut best = dec[base + i - 1].cost;
        let (mut dl, mut dr) = (u8::MAX, u8::MAX);
        for k in 0..i {
            let c = dec[l7 + k].cost + dec[r7 + i - k - 1].cost;
            if c < best {
                (best, dl, dr) = (c, k as u8, (i - k - 1) as u8);
            }
        }
        dec[base + i] = if dl == u8::MAX {
            dec[base + i - 1]
        } else {
            Decision {
                cost: best,
                kind: DecisionKind::DISTRIBUTE,
                distribute_left: dl,
                distribute_right: dr,
            }
        };
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;
    use obvhs::triangle::Triangle;
    use proptest::prelude::*;

    /// `n` random triangles in the unit cube, some tiny, some long.
    fn soup(n: usize, seed: u64) -> Vec<Triangle> {
        let mut s = seed | 1;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|_| {
                let a = Vec3A::new(next(), next(), next());
                let size = if next() < 0.2 { 0.6 } else { 0.05 };
                let mut v = || a + (Vec3A::new(next(), next(), next()) - 0.5) * size;
                Triangle {
                    v0: a,
                    v1: v(),
                    v2: v(),
                }
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]
        /// The collapse is a tree of up to eight children per node and one to four primitives
        /// per leaf, and it holds every triangle: exactly once without pre-splits; with them, at
        /// least once and never twice in one leaf.
        #[test]
        fn collapse_is_a_tree_holding_every_triangle(
            n in 1usize..400, seed in any::<u64>(), pre_split in any::<bool>(),
        ) {
            let tris = soup(n, seed);
            let params = obvhs::BvhBuildParams {
                pre_split,
                ..obvhs::BvhBuildParams::very_slow_build()
            };
            let bvh2 = obvhs::bvh2::builder::build_bvh2_from_tris(
                &tris,
                obvhs::BvhBuildParams { max_prims_per_leaf: 1, ..params },
                &mut std::time::Duration::default(),
            );
            let nodes = collapse(&bvh2);
            let mut parents = vec![0usize; nodes.len()];
            let mut seen = vec![0usize; n];
            for children in &nodes {
                prop_assert!((1..=8).contains(&children.len()));
                for child in children {
                    match child {
                        Child::Node(c) => parents[*c] += 1,
                        Child::Leaf(prims) => {
                            prop_assert!((1..=MAX_LEAF as usize).contains(&prims.len()));
                            prop_assert!(prims.windows(2).all(|w| w[0] < w[1]));
                            for &p in prims {
                                seen[p as usize] += 1;
                            }
                        }
                    }
                }
            }
            prop_assert_eq!(parents[0], 0, "the root is nobody's child");
            prop_assert!(parents[1..].iter().all(|&p| p == 1), "every other node has one parent");
            if pre_split {
                prop_assert!(seen.iter().all(|&k| k >= 1));
            } else {
                prop_assert!(seen.iter().all(|&k| k == 1));
            }
        }
    }
}
