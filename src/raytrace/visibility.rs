//! Ray visibility through an 8-wide BVH over the scene's triangles, in grid coordinates (f32).
//! Two queries: the closest hit (hemisphere shooting) and occlusion of a segment (pairwise form
//! factors, patch clustering, the transfer's leak test).
//!
//! obvhs builds a binary tree (its highest-quality preset), [`wide_collapse`] makes it 8-wide
//! with leaves of up to four triangles, and [`WideBvh`] gives it exact f32 child boxes and
//! traverses it with AVX2 slab tests (wide_bvh.rs).
//! Triangles are tested with a watertight intersection (no rays lost through shared edges).
//! Alpha-masked triangles stop a ray only where their mask is opaque ([`crate::raytrace::alpha`]);
//! leaves holding one are tested lane by lane, all others four lanes at once.
//! Rays start `BACKOFF` behind their origin (see there). The closest hit is order-independent:
//! of two hits at the same distance (a shared edge) the lower leaf slot wins.

use crate::raytrace::alpha::{AlphaMasks, Cutout, MaskedTriangle};
use crate::raytrace::watertight::{TriangleBlocks, Watertight};
use crate::raytrace::wide_bvh::{AnyLeaf, ClosestLeaf, WideBvh};
use crate::raytrace::wide_collapse;
use crate::raytrace::wide_node::BoxRay;
use crate::raytrace::Frame;
use crate::scene::Scene;
use glam::{DVec3, Vec3A};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::time::Duration;

/// The scene's non-degenerate triangles in a BVH.
pub struct Visibility {
    bvh: WideBvh,
    tris: Vec<Triangle>,
    /// Scene triangle index of each BVH triangle.
    ids: Vec<u32>,
    /// The triangles of each BVH leaf, one four-lane block per leaf (a triangle split into
    /// several boxes appears once per box). Slot `4·leaf + lane` names one.
    blocks: TriangleBlocks,
    /// Scene triangle index and unit geometric normal (counter-clockwise winding) of each slot.
    info: Vec<SlotInfo>,
    /// The scene's alpha masks and the masked triangles (`SlotInfo::mask` indexes them);
    /// None when no triangle is masked.
    alpha: Option<(AlphaMasks, Vec<MaskedTriangle>)>,
    /// Per leaf: true when one of its slots is masked.
    leaf_masked: Vec<bool>,
    /// Smallest ray parameter accepted, in grid units (above f32 self-intersection noise).
    pub epsilon: f32,
}

/// Rays start `BACKOFF` behind their origin and only hits at or beyond `BACKOFF` count. (obvhs's
/// own CWBVH traversal, used until the wide BVH replaced it, clamps entry distances to an absolute
/// 1e-4 and lost nearer hits; the offset stays so that every distance is the one it measured.)
pub const BACKOFF: f32 = 2.5e-4;

/// The closest surface a ray hits.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Scene triangle index.
    pub triangle: u32,
    pub t: f32,
    /// True when the ray hit the triangle's front (counter-clockwise) side.
    pub front: bool,
}

impl Visibility {
    /// Build over the triangles of `scene` listed in `triangles` (scene indices), mapped into
    /// grid coordinates by `frame`. `extent` is the grid's largest dimension, which sets the
    /// ray epsilon.
    pub fn new(scene: &Scene, triangles: &[u32], frame: &Frame, extent: f64) -> Self {
        Self::with_build(
            scene,
            triangles,
            frame,
            extent,
            BvhBuildParams::very_slow_build(),
        )
    }

    /// [`Visibility::new`] with obvhs's build settings `params`. Every query's answer is the
    /// same for any tree (the traversal is conservative and the leaf tests exact), except which
    /// of two hits at exactly the same distance a closest-hit query reports; a cheaper build
    /// serves a few queries, the highest-quality one millions.
    pub fn with_build(
        scene: &Scene,
        triangles: &[u32],
        frame: &Frame,
        extent: f64,
        params: BvhBuildParams,
    ) -> Self {
        // Triangles cut out everywhere are not there for light.
        let masks = AlphaMasks::new(scene);
        let triangles: Vec<u32> = triangles
            .iter()
            .copied()
            .filter(|&t| masks.cutout(scene, t as usize) != Cutout::Everywhere)
            .collect();
        let mut masked = Vec::new();
        let mask_of: Vec<u32> = triangles
            .iter()
            .map(|&t| match masks.cutout(scene, t as usize) {
                Cutout::Masked(image) => {
                    let uv = masks.corner_uvs(scene, t as usize);
                    masked.push(MaskedTriangle { image, uv });
                    masked.len() as u32 - 1
                }
                _ => NO_MASK,
            })
            .collect();
        let tris: Vec<Triangle> = triangles
            .iter()
            .map(|&t| {
                let [a, b, c] = scene.triangles[t as usize]
                    .map(|v| frame.to_grid(scene.positions[v as usize]).as_vec3().into());
                Triangle {
                    v0: a,
                    v1: b,
                    v2: c,
                }
            })
            .collect();
        let normals: Vec<Vec3A> = tris.iter().map(|t| t.compute_normal()).collect();
        // obvhs's highest-quality preset: on the furnished room (78,324 triangles) it traces
        // 2.3x the rays per second of `slow_build` for 2x its build time (0.15 s against
        // 0.07 s), where the form-factor stage casts millions of rays (benches/visibility_embree.rs).
        let collapsed = if tris.is_empty() {
            Vec::new()
        } else {
            // Leaves of one triangle, as the collapse takes them.
            let params = BvhBuildParams {
                max_prims_per_leaf: 1,
                ..params
            };
            let bvh2 = build_bvh2_from_tris(&tris, params, &mut Duration::default());
            wide_collapse::collapse(&bvh2)
        };
        let (bvh, order) = WideBvh::from_collapsed(&collapsed, |k| {
            let t = &tris[k as usize];
            (
                t.v0.min(t.v1).min(t.v2).to_array(),
                t.v0.max(t.v1).max(t.v2).to_array(),
            )
        });
        let mut blocks = TriangleBlocks::default();
        let mut info = Vec::with_capacity(4 * bvh.leaves().len());
        let mut leaf_masked = Vec::with_capacity(bvh.leaves().len());
        for &(first, count) in bvh.leaves() {
            let ks = &order[first as usize..(first + count) as usize];
            let leaf: Vec<[Vec3A; 3]> = ks
                .iter()
                .map(|&k| {
                    let t = &tris[k as usize];
                    [t.v0, t.v1, t.v2]
                })
                .collect();
            blocks.push(&leaf);
            leaf_masked.push(ks.iter().any(|&k| mask_of[k as usize] != NO_MASK));
            info.extend((0..4).map(|lane| {
                let k = ks[lane.min(ks.len() - 1)] as usize;
                SlotInfo {
                    normal: normals[k].to_array(),
                    triangle: triangles[k],
                    mask: mask_of[k],
                }
            }));
        }
        Visibility {
            bvh,
            blocks,
            info,
            alpha: (!masked.is_empty()).then_some((masks, masked)),
            leaf_masked,
            tris,
            ids: triangles,
            epsilon: ray_epsilon(extent),
        }
    }

    /// The BVH's triangles as (scene triangle index, vertices in grid coordinates, f32): what
    /// an independent tracer needs to trace the same rays (tests/radiosity/visibility_embree.rs).
    pub fn triangles(&self) -> impl Iterator<Item = (u32, [[f32; 3]; 3])> + '_ {
        self.ids
            .iter()
            .zip(&self.tris)
            .map(|(&id, t)| (id, [t.v0, t.v1, t.v2].map(|v| [v.x, v.y, v.z])))
    }

    /// Number of triangles in the BVH.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The closest hit along `dir` (unit) from `origin`. Callers start rays slightly off the
    /// surface (lifted by [`Visibility::epsilon`] along its normal), so every hit with t ≥ 0 counts.
    #[inline]
    pub fn closest_hit(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        self.trace_closest(&Ray::new(origin, dir))
    }

    /// The closest hit of `ray` (any `tmax` it carries is ignored).
    #[inline]
    pub fn trace_closest(&self, ray: &Ray) -> Option<Hit> {
        let wt = Watertight::new(ray.start, ray.dir);
        let boxes = BoxRay::new(ray.start.to_array(), ray.dir.to_array());
        let mut leaf = Closest {
            vis: self,
            wt: &wt,
            start: ray.start,
            d: ray.dir,
            best: u32::MAX,
        };
        let t = self.bvh.closest(&boxes, BACKOFF, f32::INFINITY, &mut leaf);
        self.hit(leaf.best, t, ray.dir)
    }

    /// The hit on slot `s` (none for `u32::MAX`) at `t` from the backed-off start.
    #[inline(always)]
    fn hit(&self, s: u32, t: f32, d: Vec3A) -> Option<Hit> {
        let info = self.info.get(s as usize)?;
        Some(Hit {
            triangle: info.triangle,
            t: t - BACKOFF,
            front: Vec3A::from(info.normal).dot(d) < 0.0,
        })
    }

    /// Every slot as (slot, triangle), in slot order.
    fn all_slots(&self) -> impl Iterator<Item = (u32, [Vec3A; 3])> + '_ {
        self.bvh
            .leaves()
            .iter()
            .enumerate()
            .flat_map(move |(leaf, &(_, count))| {
                (0..count as usize)
                    .map(move |k| ((4 * leaf + k) as u32, self.blocks.triangle(leaf, k)))
            })
    }

    /// [`Visibility::closest_hit`] by testing every triangle slot in order with the scalar test:
    /// the same answer bit for bit (tests/radiosity/visibility.rs), without the tree.
    pub fn closest_hit_brute_force(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        self.trace_closest_brute_force(&Ray::new(origin, dir))
    }

    /// [`Visibility::trace_closest`] by testing every triangle slot in order with the scalar test.
    pub fn trace_closest_brute_force(&self, ray: &Ray) -> Option<Hit> {
        let (start, d) = (ray.start, ray.dir);
        let wt = Watertight::new(start, d);
        let (mut best, mut tmax) = (u32::MAX, f32::INFINITY);
        for (s, tri) in self.all_slots() {
            let t = wt.intersect(&tri, BACKOFF, tmax);
            if self.counts(s, t, d) && t < tmax && self.opaque(s, &tri, start + d * t) {
                (best, tmax) = (s, t);
            }
        }
        self.hit(best, tmax, d)
    }

    /// [`Visibility::occluded`] by testing every triangle slot with the scalar test.
    pub fn occluded_brute_force(&self, from: DVec3, to: DVec3) -> bool {
        Ray::segment(from, to).is_some_and(|ray| self.trace_occluded_brute_force(&ray))
    }

    /// [`Visibility::trace_occluded`] by testing every triangle slot with the scalar test.
    pub fn trace_occluded_brute_force(&self, ray: &Ray) -> bool {
        let wt = Watertight::new(ray.start, ray.dir);
        self.all_slots().any(|(s, tri)| {
            let t = wt.intersect(&tri, BACKOFF, ray.tmax);
            self.counts(s, t, ray.dir) && self.opaque(s, &tri, ray.start + ray.dir * t)
        })
    }

    /// True when slot `s` (triangle `tri`) is opaque at the point `p` a ray hit.
    #[inline(always)]
    fn opaque(&self, s: u32, tri: &[Vec3A; 3], p: Vec3A) -> bool {
        let mask = self.info[s as usize].mask;
        match &self.alpha {
            Some((masks, masked)) if mask != NO_MASK => {
                masked[mask as usize].opaque_at(masks, tri, p)
            }
            _ => true,
        }
    }

    /// True when leaf `leaf` holds a masked triangle.
    #[inline(always)]
    fn leaf_masked(&self, leaf: u32) -> bool {
        self.alpha.is_some() && self.leaf_masked[leaf as usize]
    }

    /// Whether a distance `t` of the watertight test (from the start `BACKOFF` behind the
    /// caller's origin) to slot `s` stops the ray. Infinity (a miss) does not. A back face closer
    /// than [`Visibility::epsilon`] to the origin does not either: it is a surface the origin lies
    /// on (within rounding: a sample on the edge of a concave corner lies in the plane of the
    /// adjoining wall), which the ray leaves through its front side. A front face at any distance
    /// does.
    #[inline(always)]
    fn counts(&self, s: u32, t: f32, d: Vec3A) -> bool {
        t.is_finite()
            && (t - BACKOFF >= self.epsilon
                || Vec3A::from(self.info[s as usize].normal).dot(d) < 0.0)
    }

    /// True when a surface lies on the segment from `from` to `to` (both lifted off their
    /// surfaces by the caller).
    #[inline]
    pub fn occluded(&self, from: DVec3, to: DVec3) -> bool {
        Ray::segment(from, to).is_some_and(|ray| self.trace_occluded(&ray))
    }

    /// True when a surface lies on `ray` up to its `tmax`.
    #[inline]
    pub fn trace_occluded(&self, ray: &Ray) -> bool {
        let wt = Watertight::new(ray.start, ray.dir);
        let boxes = BoxRay::new(ray.start.to_array(), ray.dir.to_array());
        let mut leaf = Occluding {
            vis: self,
            wt: &wt,
            start: ray.start,
            d: ray.dir,
            tmax: ray.tmax,
        };
        self.bvh.any(&boxes, BACKOFF, ray.tmax, &mut leaf)
    }
}

/// The occlusion leaf test: some slot's watertight distance counts and lies within `tmax`.
struct Occluding<'a> {
    vis: &'a Visibility,
    wt: &'a Watertight,
    start: Vec3A,
    d: Vec3A,
    tmax: f32,
}

impl AnyLeaf for Occluding<'_> {
    #[inline(always)]
    fn leaf(&mut self, leaf: u32, count: u32) -> bool {
        let lanes = self.vis.blocks.lanes4(
            self.wt,
            leaf as usize,
            count as usize,
            (BACKOFF, self.tmax),
            self.vis.epsilon,
        );
        if self.vis.leaf_masked(leaf) {
            return (0..count as usize).any(|k| {
                let (s, t) = (4 * leaf + k as u32, lanes.ts[k]);
                let tri = self.vis.blocks.triangle(leaf as usize, k);
                self.vis.counts(s, t, self.d) && self.vis.opaque(s, &tri, self.start + self.d * t)
            });
        }
        // A hit beyond the epsilon stops the ray ([`Visibility::counts`]); only a nearer one
        // needs its normal.
        if lanes.hit & !lanes.near != 0 {
            return true;
        }
        lanes.near != 0
            && (0..count as usize)
                .any(|k| self.vis.counts(4 * leaf + k as u32, lanes.ts[k], self.d))
    }
}

/// The closest-hit leaf test: the watertight distance to each slot's triangle; of equal
/// distances the lower slot wins, so the answer does not depend on the traversal order.
struct Closest<'a> {
    vis: &'a Visibility,
    wt: &'a Watertight,
    start: Vec3A,
    d: Vec3A,
    best: u32,
}

impl ClosestLeaf for Closest<'_> {
    #[inline(always)]
    fn leaf(&mut self, leaf: u32, count: u32, mut tmax: f32) -> f32 {
        let lanes = self.vis.blocks.lanes4(
            self.wt,
            leaf as usize,
            count as usize,
            (BACKOFF, tmax),
            self.vis.epsilon,
        );
        let masked = self.vis.leaf_masked(leaf);
        if lanes.near == 0 && !masked {
            let (t, lane) = lanes.nearest;
            // Every hit lies beyond the epsilon and counts ([`Visibility::counts`]); distances
            // are at most `tmax`, so the nearest lane wins unless it ties a lower slot.
            let s = 4 * leaf + lane;
            if lanes.hit != 0 && (t < tmax || s < self.best) {
                self.best = s;
                return t;
            }
            return tmax;
        }
        for (k, &t) in lanes.ts.iter().enumerate().take(count as usize) {
            let s = 4 * leaf + k as u32;
            if !self.vis.counts(s, t, self.d) {
                continue;
            }
            if masked {
                let tri = self.vis.blocks.triangle(leaf as usize, k);
                if !self.vis.opaque(s, &tri, self.start + self.d * t) {
                    continue;
                }
            }
            if t < tmax || (t == tmax && s < self.best) {
                tmax = t;
                self.best = s;
            }
        }
        tmax
    }
}

/// What a hit on a slot reports: the scene triangle and its unit normal; and its mask.
struct SlotInfo {
    normal: [f32; 3],
    triangle: u32,
    /// Index of its [`MaskedTriangle`], or [`NO_MASK`].
    mask: u32,
}

/// [`SlotInfo::mask`] of an opaque triangle.
const NO_MASK: u32 = u32::MAX;

/// A ray as the tracer takes it, in f32 grid coordinates: its start `BACKOFF` behind the
/// caller's origin, its unit direction, and the far end of the segment (from the start) for an
/// occlusion query.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub start: Vec3A,
    pub dir: Vec3A,
    pub tmax: f32,
}

impl Ray {
    /// The ray from `origin` along `dir` (unit), unbounded: the start is backed off in f64 and
    /// rounded once.
    #[inline]
    pub fn new(origin: DVec3, dir: DVec3) -> Ray {
        Ray {
            start: Vec3A::from((origin - dir * BACKOFF as f64).as_vec3()),
            dir: Vec3A::from(dir.as_vec3()),
            tmax: f32::INFINITY,
        }
    }

    /// The segment `from → to` (length and direction in f64), or none for an empty segment.
    #[inline]
    pub fn segment(from: DVec3, to: DVec3) -> Option<Ray> {
        let delta = to - from;
        let len = delta.length();
        if len <= 0.0 {
            return None;
        }
        Some(Ray {
            tmax: len as f32 + BACKOFF,
            ..Ray::new(from, delta * (1.0 / len))
        })
    }

    /// The ray an f32 tracer such as Embree takes: `origin`, unit `dir`, and the segment's
    /// length `len` (infinity for a closest-hit ray), all in f32. The far end is inclusive with
    /// one ulp to spare, so that a closest hit's reported distance is always within it (as an
    /// Embree occlusion query up to a hit's `tfar` is).
    #[inline]
    pub fn from_f32(origin: [f32; 3], dir: [f32; 3], len: f32) -> Ray {
        let (origin, dir) = (Vec3A::from(origin), Vec3A::from(dir));
        // len + BACKOFF > 0: the next float up is one more in its bits (f32::next_up needs Rust
        // 1.86, above this crate's minimum).
        let end = len + BACKOFF;
        Ray {
            start: origin - dir * BACKOFF,
            dir,
            tmax: if end.is_finite() {
                f32::from_bits(end.to_bits() + 1)
            } else {
                end
            },
        }
    }
}

/// The ray epsilon for a grid whose largest coordinate is `extent`: a few hundred f32 ulps of the
/// coordinates, never below 1e-5 of a voxel.
pub fn ray_epsilon(extent: f64) -> f32 {
    (256.0 * f32::EPSILON as f64 * extent.max(1.0)).max(1e-5) as f32
}
