//! The wide BVH's traversal (AVX2 slab tests where the CPU has them, four-lane watertight leaf
//! tests) against testing every triangle with the scalar watertight test: the same closest
//! triangle at the same distance bit for bit, and the same occlusion answer. Rays aim at
//! vertices and edge midpoints (shared edges, where a lost box or a leaf test that differs from
//! the scalar one would show), along the axes (zero direction components) and at random.

use crate::fixtures::random_soup;
use glam::DVec3;
use proptest::prelude::*;
use relume::radiosity::geometry::Frame;
use relume::raytrace::visibility::{Ray, Visibility};
use relume::scene::builder::SceneBuilder;
use relume::scene::Scene;

fn visibility(scene: &Scene) -> Visibility {
    let all: Vec<u32> = (0..scene.triangles.len() as u32).collect();
    let frame = Frame {
        origin: DVec3::ZERO,
        scale: 1.0,
    };
    Visibility::new(scene, &all, &frame, 1.0)
}

/// A closed box of `n`×`n` quads per face (two triangles each) on the unit cube, with a thin
/// wall through its middle: axis-aligned triangles whose boxes are flat, and many shared edges.
fn tiled_box(n: usize) -> Scene {
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    let h = 1.0 / n as f64;
    for axis in 0..3 {
        let (u, v) = (DVec3::AXES[(axis + 1) % 3], DVec3::AXES[(axis + 2) % 3]);
        for side in [0.0, 0.5, 1.0] {
            let base = DVec3::AXES[axis] * side;
            for i in 0..n {
                for j in 0..n {
                    let c = base + u * ((i as f64 + 0.5) * h) + v * ((j as f64 + 0.5) * h);
                    s.rectangle("tile", c, u * (h / 2.0), v * (h / 2.0), m);
                }
            }
        }
    }
    s.build()
}

/// Points a ray may aim at: every vertex and edge midpoint of the scene.
fn targets(scene: &Scene) -> Vec<DVec3> {
    let p = |v: u32| DVec3::from(scene.positions[v as usize].map(f64::from));
    let mut out = Vec::new();
    for t in &scene.triangles {
        for k in 0..3 {
            out.push(p(t[k]));
            out.push((p(t[k]) + p(t[(k + 1) % 3])) / 2.0);
        }
    }
    out
}

fn check(vis: &Visibility, origin: DVec3, dir: DVec3) -> Result<(), TestCaseError> {
    let fast = vis.closest_hit(origin, dir);
    let slow = vis.closest_hit_brute_force(origin, dir);
    match (fast, slow) {
        (None, None) => {}
        (Some(a), Some(b)) => {
            prop_assert_eq!(a.triangle, b.triangle, "origin {} dir {}", origin, dir);
            prop_assert_eq!(a.t.to_bits(), b.t.to_bits());
            prop_assert_eq!(a.front, b.front);
        }
        _ => prop_assert!(
            false,
            "tree {fast:?} brute force {slow:?}, origin {origin} dir {dir}"
        ),
    }
    for len in [0.05, 0.3, 2.0] {
        let to = origin + dir * len;
        prop_assert_eq!(
            vis.occluded(origin, to),
            vis.occluded_brute_force(origin, to)
        );
    }
    // The same ray as an f32 tracer (Embree, benches/visibility_embree.rs) takes it: origin,
    // direction and length in f32.
    let (o, d) = (origin.as_vec3().to_array(), dir.as_vec3().to_array());
    let ray = Ray::from_f32(o, d, f32::INFINITY);
    let (fast, slow) = (vis.trace_closest(&ray), vis.trace_closest_brute_force(&ray));
    prop_assert_eq!(
        fast.map(|h| (h.triangle, h.t.to_bits())),
        slow.map(|h| (h.triangle, h.t.to_bits()))
    );
    for len in [0.05f32, 0.3, 2.0] {
        let seg = Ray::from_f32(o, d, len);
        prop_assert_eq!(
            vis.trace_occluded(&seg),
            vis.trace_occluded_brute_force(&seg)
        );
    }
    // Occlusion up to a closest hit's reported distance includes that hit (the bench's cut
    // rays rely on it, as Embree's occlusion up to its own tfar does).
    if let Some(h) = fast {
        prop_assert!(
            vis.trace_occluded(&Ray::from_f32(o, d, h.t)),
            "hit at {} not occluding",
            h.t
        );
    }
    Ok(())
}

fn unit(v: DVec3) -> Option<DVec3> {
    (v.length() > 1e-9).then(|| v.normalize())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Occlusion answers do not depend on the tree (conservative traversal, exact leaf tests):
    /// the voxel-size search builds with obvhs's medium preset and must cluster as the slowest
    /// build would.
    #[test]
    fn occlusion_is_the_same_for_a_cheaper_build(
        seed in 0u64..1000,
        n in 1usize..400,
        segments in prop::collection::vec((prop::array::uniform3(-0.2f64..1.2), prop::array::uniform3(-0.2f64..1.2)), 64),
    ) {
        let scene = random_soup(n, seed);
        let all: Vec<u32> = (0..scene.triangles.len() as u32).collect();
        let frame = Frame { origin: DVec3::ZERO, scale: 1.0 };
        let best = Visibility::new(&scene, &all, &frame, 1.0);
        let medium = Visibility::with_build(&scene, &all, &frame, 1.0, obvhs::BvhBuildParams::medium_build());
        for (a, b) in segments {
            let (a, b) = (DVec3::from(a), DVec3::from(b));
            let want = best.occluded_brute_force(a, b);
            prop_assert_eq!(best.occluded(a, b), want);
            prop_assert_eq!(medium.occluded(a, b), want, "{} -> {}", a, b);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn soup_rays_hit_what_every_triangle_test_hits(
        seed in 0u64..1000,
        n in 1usize..400,
        rays in prop::collection::vec((prop::array::uniform3(-0.2f64..1.2), prop::array::uniform3(-1.0f64..1.0), 0usize..10_000, 0u8..3), 64),
    ) {
        let scene = random_soup(n, seed);
        let vis = visibility(&scene);
        let aims = targets(&scene);
        for (o, d, pick, kind) in rays {
            let origin = DVec3::from(o);
            let dir = match kind {
                0 => unit(DVec3::from(d)),
                1 => unit(aims[pick % aims.len()] - origin),
                _ => Some(DVec3::AXES[pick % 3] * if d[0] < 0.0 { -1.0 } else { 1.0 }),
            };
            if let Some(dir) = dir {
                check(&vis, origin, dir)?;
            }
        }
    }

    #[test]
    fn rays_through_the_seams_of_a_tiled_box_hit_what_every_triangle_test_hits(
        n in 1usize..6,
        rays in prop::collection::vec((prop::array::uniform3(0.01f64..0.99), 0usize..10_000, prop::array::uniform3(-1.0f64..1.0), 0u8..3), 64),
    ) {
        let scene = tiled_box(n);
        let vis = visibility(&scene);
        let aims = targets(&scene);
        for (o, pick, d, kind) in rays {
            let origin = DVec3::from(o);
            let dir = match kind {
                0 => unit(aims[pick % aims.len()] - origin),
                1 => Some(DVec3::AXES[pick % 3] * if d[0] < 0.0 { -1.0 } else { 1.0 }),
                _ => unit(DVec3::from(d)),
            };
            if let Some(dir) = dir {
                check(&vis, origin, dir)?;
            }
        }
    }
}

/// Rays that start on a vertex of the tiled box and run along its edges and faces: they graze
/// flat boxes (zero extent on one axis) edge-on.
#[test]
fn rays_along_the_faces_of_a_tiled_box_hit_what_every_triangle_test_hits() {
    let scene = tiled_box(4);
    let vis = visibility(&scene);
    let mut count = 0;
    for o in targets(&scene) {
        let origin = o.clamp(DVec3::splat(1e-3), DVec3::splat(1.0 - 1e-3));
        for dir in [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::new(1.0, 1.0, 0.0).normalize(),
            DVec3::new(0.0, -1.0, 1.0).normalize(),
            DVec3::new(1.0, 0.0, -1.0).normalize(),
        ] {
            check(&vis, origin, dir).unwrap();
            count += 1;
        }
    }
    assert!(count > 1000);
}
