//! Voxelisation and the transfer to the full mesh: coplanar overlap (the Cornell light), area and
//! power conservation, degenerate triangles, target patch counts, transfer weights, smoothness,
//! and no leaks through a wall thinner than a voxel.

use crate::fixtures;
use glam::DVec3;
use proptest::prelude::*;
use relume::progress::Silent;
use relume::radiosity::formfactor::{form_factors, Estimator, FormFactorParams};
use relume::radiosity::geometry::{self, dominant_axis};
use relume::radiosity::patches::corners::interpolate;
use relume::radiosity::patches::overlap::{visible_parts, Face};
use relume::radiosity::patches::voxelize::{clip_to_voxels, voxelize, Resolution, VoxelizeParams};
use relume::radiosity::transport::{transport, Bounces, Power, TransportParams};
use relume::radiosity::PatchSet;
use relume::scene::builder::SceneBuilder;
use relume::scene::Scene;

fn patches(scene: &Scene, resolution: Resolution) -> PatchSet {
    voxelize(
        scene,
        &VoxelizeParams {
            resolution,
            samples_per_patch: 4,
        },
    )
    .unwrap()
}

fn cornell() -> Scene {
    relume::scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes/cornell-box/cornell_box.obj"),
        relume::scene::SceneOptions { scale: 0.001 },
    )
    .unwrap()
    .0
}

#[test]
fn cornell_light_in_the_ceiling_plane_neither_doubles_area_nor_loses_emission() {
    let scene = cornell();
    let light = scene.objects.iter().position(|o| o == "light").unwrap() as u32;
    let light_area: f64 = (0..scene.triangles.len())
        .filter(|&t| scene.triangle_object[t] == light)
        .map(|t| scene.triangle_area(t) as f64)
        .sum();
    let radiance = scene
        .materials
        .iter()
        .find(|m| m.name == "light")
        .unwrap()
        .emission;
    for target in [100, 600, 2000] {
        let set = patches(&scene, Resolution::TargetPatches(target));
        let area: f64 = set.patches.iter().map(|p| p.area as f64).sum();
        // The light covers part of the ceiling: that part counts once.
        let want = scene.total_area() - light_area;
        assert!(
            (area - want).abs() < 1e-5 * want,
            "{target}: {area} vs {want}"
        );
        assert_eq!(
            set.stats.covered_faces, 2,
            "both ceiling triangles lose area"
        );
        assert!((set.stats.covered_area - light_area).abs() < 1e-6);
        // Emitted power (Σ A·L) equals the light's, per channel.
        for (c, &l) in radiance.iter().enumerate() {
            let power: f64 = set
                .patches
                .iter()
                .map(|p| p.area as f64 * p.emission[c] as f64)
                .sum();
            let want = light_area * l as f64;
            assert!(
                (power - want).abs() < 1e-5 * want,
                "{target} channel {c}: {power} vs {want}"
            );
        }
        // Patch counts follow the target.
        let n = set.len() as f64;
        assert!(
            n > 0.75 * target as f64 && n < 1.35 * target as f64,
            "target {target}: {n}"
        );
        // Every patch names its source objects; the light's patches include "light".
        assert!(set.patches.iter().all(|p| !p.objects.is_empty()));
        assert!(set
            .patches
            .iter()
            .any(|p| p.objects.contains(&light) && p.emission[0] > 0.0));
    }
}

#[test]
fn degenerate_triangles_are_skipped_and_counted() {
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    s.rectangle("quad", DVec3::ZERO, DVec3::X, DVec3::Y, m);
    s.triangle("line", [DVec3::ZERO, DVec3::X, DVec3::X * 2.0], m);
    s.triangle("point", [DVec3::ONE, DVec3::ONE, DVec3::ONE], m);
    let scene = s.build();
    let set = patches(&scene, Resolution::VoxelSize(0.5));
    assert_eq!(set.stats.degenerate_triangles, 2);
    assert_eq!(set.len(), 16);
    for t in 2..4 {
        assert!(set.triangle_patches.list(t).0.is_empty());
        for c in 0..3 {
            assert!(set.corners.list(3 * t + c).0.is_empty());
        }
    }
    // A scene of nothing but degenerate triangles is refused.
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    s.triangle("line", [DVec3::ZERO, DVec3::X, DVec3::X * 2.0], m);
    let e = voxelize(
        &s.build(),
        &VoxelizeParams {
            resolution: Resolution::VoxelSize(1.0),
            samples_per_patch: 1,
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("no triangle with positive area"),
        "{e}"
    );
}

#[test]
fn transfer_weights_are_convex_and_orientation_compatible() {
    let scene = cornell();
    let set = patches(&scene, Resolution::TargetPatches(400));
    assert_eq!(set.stats.corners_without_patch, 0);
    for t in 0..scene.triangles.len() {
        let [a, b, c] = scene.corners(t).map(|v| v.as_dvec3());
        let axis = dominant_axis((b - a).cross(c - a));
        for k in 0..3 {
            let (p, w) = set.corners.list(3 * t + k);
            assert!(!p.is_empty() && p.len() <= 8);
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            assert!(w.iter().all(|&x| x > 0.0));
            assert!(p.iter().all(|&j| set.patches[j as usize].axis == axis));
        }
    }
    // Direct-light sample points lie on their patch's pieces.
    let frame = set.frame();
    for (i, patch) in set.patches.iter().enumerate() {
        for s in &set.samples[i * 4..i * 4 + 4] {
            let g = frame.to_grid(s.position);
            let d = set
                .patch_pieces(patch)
                .iter()
                .map(|p| {
                    let poly: Vec<DVec3> = p.vertices.iter().map(|&v| DVec3::from(v)).collect();
                    geometry::distance_to_polygon(g, &poly, DVec3::from(p.normal))
                })
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-4, "sample {d} voxels off patch {i}");
        }
    }
}

/// `corner_patches` weighs the corners at one position together, sharing their nearest-piece
/// searches: its lists must be those of weighting every corner on its own, bit for bit. The
/// door-ajar scene has vertices shared by many triangles, voxels holding several patches of one
/// orientation (the wall and door leaf) and occluded pairs.
#[test]
fn corner_lists_equal_weighting_each_corner_alone() {
    use relume::radiosity::patches::corners::PointTransfer;
    let scene = relume::scene::load_scene(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/generated/door-ajar.obj"),
        Default::default(),
    )
    .unwrap()
    .0;
    let set = patches(&scene, Resolution::TargetPatches(800));
    let vis = set.visibility(&scene);
    let transfer = PointTransfer::new(&scene, &set, &vis);
    let (mut blended, mut corners) = (0, 0);
    for t in 0..scene.triangles.len() {
        let on = transfer.on_triangle(&scene, t);
        for k in 0..3 {
            let (p, w) = set.corners.list(3 * t + k);
            if scene.is_degenerate(t) {
                assert!(p.is_empty());
                continue;
            }
            let v = scene.triangles[t][k] as usize;
            let want = on.weights(glam::Vec3::from(scene.positions[v]));
            let got: Vec<(u32, f32)> = p.iter().copied().zip(w.iter().copied()).collect();
            assert_eq!(got, want, "corner {k} of triangle {t}");
            blended += (p.len() > 1) as usize;
            corners += 1;
        }
    }
    // The scene exercises the shared searches: most positions are corners of several
    // triangles, and many corners blend several patches.
    assert!(corners > 3 * scene.positions.len(), "{corners} corners");
    assert!(
        blended > corners / 4,
        "{blended} of {corners} corners blended"
    );
}

#[test]
fn transfer_is_smooth_on_a_finely_meshed_floor() {
    // A 1×1 floor meshed as 12×12 quads, voxels of 0.25: corners shared by several triangles get
    // identical weights, and a linear function of the patch centroids interpolates to within a
    // voxel of the vertex position.
    let mut s = SceneBuilder::new();
    let m = s.material("grey", [0.5; 3], [0.0; 3]);
    let k = 12;
    let h = 0.5 / k as f64;
    for i in 0..k {
        for j in 0..k {
            let c = DVec3::new((2 * i + 1) as f64 * h, 0.0, (2 * j + 1) as f64 * h);
            s.rectangle("floor", c, DVec3::X * h, -DVec3::Z * h, m);
        }
    }
    let scene = s.build();
    let set = patches(&scene, Resolution::VoxelSize(0.25));
    assert_eq!(set.len(), 16);
    let xs: Vec<f32> = set.patches.iter().map(|p| p.centroid[0]).collect();
    let at = interpolate(&set.corners, &xs);
    let mut seen: std::collections::HashMap<[u32; 3], f32> = Default::default();
    for t in 0..scene.triangles.len() {
        for c in 0..3 {
            let v = scene.triangles[t][c] as usize;
            let p = scene.positions[v];
            let key = p.map(f32::to_bits);
            let value = at[3 * t + c];
            if let Some(&prev) = seen.get(&key) {
                assert_eq!(prev, value, "a shared vertex gets one value");
            }
            seen.insert(key, value);
            // Interior vertices (not within half a voxel of the border) interpolate x exactly.
            if p[0] > 0.125 && p[0] < 0.875 {
                assert!((value - p[0]).abs() < 1e-5, "x {} → {value}", p[0]);
            }
            assert!((value - p[0]).abs() <= 0.125 + 1e-5);
        }
    }
}

#[test]
fn no_light_leaks_through_a_wall_thinner_than_a_voxel() {
    // Rooms x ∈ [0, 1] and [1.05, 2.05]; voxels of 0.3 put both floors (and ceilings, back walls)
    // in the voxels that straddle the 0.05 wall. "No leak": no patch mixes the two rooms, no
    // corner of room B draws from a patch of room A, and light from room A's lamp gives exactly
    // zero indirect light anywhere in room B.
    let t = 0.05;
    let scene = fixtures::thin_wall_rooms(t);
    let set = patches(&scene, Resolution::VoxelSize(0.3));
    let frame = set.frame();
    let room_of = |x: f64| {
        if x <= 1.0 + 1e-6 {
            0
        } else {
            assert!(x >= 1.0 + t - 1e-6);
            1
        }
    };
    let patch_room: Vec<usize> = set
        .patches
        .iter()
        .map(|p| {
            let rooms: std::collections::BTreeSet<usize> = set
                .patch_pieces(p)
                .iter()
                .flat_map(|q| {
                    q.vertices
                        .iter()
                        .map(|&v| room_of(frame.to_world(DVec3::from(v)).x))
                })
                .collect();
            assert_eq!(rooms.len(), 1, "patch {:?} mixes both rooms", p.voxel);
            *rooms.iter().next().unwrap()
        })
        .collect();
    // The voxels straddling the wall hold two floor patches each (one per room).
    let floors_in = |v: [u32; 3]| {
        set.patches
            .iter()
            .filter(|p| p.voxel == v && p.axis == 2)
            .count()
    };
    assert_eq!(floors_in([3, 0, 0]), 2);
    assert_eq!(floors_in([2, 0, 0]), 1);
    let room_b = scene.objects.iter().position(|o| o == "room_b").unwrap() as u32;
    for tri in 0..scene.triangles.len() {
        if scene.triangle_object[tri] != room_b {
            continue;
        }
        for c in 0..3 {
            let (p, _) = set.corners.list(3 * tri + c);
            assert!(!p.is_empty());
            assert!(
                p.iter().all(|&j| patch_room[j as usize] == 1),
                "corner of room B draws from room A"
            );
        }
    }
    // End to end: form factors, infinite bounces, light only in room A.
    let f = form_factors(
        &scene,
        &set,
        &FormFactorParams {
            estimator: Estimator::Hemisphere,
            samples: 256,
            seed: 0,
        },
        &Silent,
    )
    .unwrap();
    let albedo: Vec<[f32; 3]> = set.patches.iter().map(|p| p.albedo).collect();
    let s = transport(
        &f.values,
        f.n,
        &albedo,
        &TransportParams {
            bounces: Bounces::Infinite,
            power: Power::Auto,
            max_memory: 1 << 40,
            solver: Default::default(),
        },
        &Silent,
    )
    .unwrap();
    let e: Vec<f64> = set
        .patches
        .iter()
        .map(|p| std::f64::consts::PI * p.emission[0] as f64)
        .collect();
    assert!(e.iter().sum::<f64>() > 0.0);
    let b = s.apply(0, &e);
    for (j, &room) in patch_room.iter().enumerate() {
        if room == 1 {
            assert_eq!(b[j], 0.0, "patch {j} in room B receives light");
        } else {
            assert!(b[j] > 0.0);
        }
    }
    let bf: Vec<f32> = b.iter().map(|&v| v as f32).collect();
    let corners = interpolate(&set.corners, &bf);
    for tri in 0..scene.triangles.len() {
        for c in 0..3 {
            let v = corners[3 * tri + c];
            if scene.triangle_object[tri] == room_b {
                assert_eq!(v, 0.0);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Clipping into voxels keeps the area and keeps every piece in its voxel.
    #[test]
    fn clipping_preserves_area(
        pts in prop::array::uniform9(0.0f64..6.0),
        dims in prop::array::uniform3(1u32..7),
    ) {
        let tri: Vec<DVec3> = (0..3).map(|k| DVec3::new(pts[3 * k], pts[3 * k + 1], pts[3 * k + 2])).collect();
        let whole = geometry::area(&tri);
        let pieces = clip_to_voxels(&tri, dims);
        let sum: f64 = pieces.iter().map(|(_, p)| geometry::area(p)).sum();
        prop_assert!((sum - whole).abs() <= 1e-9 * (1.0 + whole));
        for (v, p) in &pieces {
            for q in p {
                for a in 0..3 {
                    let lo = if v[a] == 0 { f64::NEG_INFINITY } else { v[a] as f64 - 1e-5 };
                    let hi = if v[a] + 1 == dims[a] { f64::INFINITY } else { v[a] as f64 + 1.0 + 1e-5 };
                    prop_assert!(q[a] >= lo && q[a] <= hi);
                }
            }
        }
    }

    /// Two coplanar triangles: the visible areas add up to the area of their union (checked
    /// against point sampling), whichever covers which.
    #[test]
    fn overlap_counts_the_union_once(
        a in prop::array::uniform6(0.0f64..1.0),
        b in prop::array::uniform6(0.0f64..1.0),
        emissive in any::<bool>(),
    ) {
        let tri = |p: [f64; 6]| {
            let mut c = [DVec3::new(p[0], p[1], 0.0), DVec3::new(p[2], p[3], 0.0), DVec3::new(p[4], p[5], 0.0)];
            if (c[1] - c[0]).cross(c[2] - c[0]).z < 0.0 { c.swap(1, 2); }
            c
        };
        let (ca, cb) = (tri(a), tri(b));
        prop_assume!(geometry::area(&ca) > 1e-3 && geometry::area(&cb) > 1e-3);
        let faces = [
            Face { corners: ca, normal: DVec3::Z, emissive },
            Face { corners: cb, normal: DVec3::Z, emissive: false },
        ];
        let v = visible_parts(&faces, 1e-9);
        let visible: f64 = v.polygons.iter().flatten().map(|p| geometry::area(p)).sum();
        let inside = |c: &[DVec3; 3], p: DVec3| (0..3).all(|k| (c[(k + 1) % 3] - c[k]).cross(p - c[k]).z >= 0.0);
        let g = 300;
        let mut hits = 0;
        for i in 0..g {
            for j in 0..g {
                let p = DVec3::new((i as f64 + 0.5) / g as f64, (j as f64 + 0.5) / g as f64, 0.0);
                if inside(&ca, p) || inside(&cb, p) { hits += 1; }
            }
        }
        let union = hits as f64 / (g * g) as f64;
        prop_assert!((visible - union).abs() < 0.01, "visible {} union {}", visible, union);
    }
}
