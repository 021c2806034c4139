//! Alpha masks in the tracer: a ray through a cut-out texel passes, through an opaque one stops.
//! The expected answer is read from the mask texel under the point where the ray crosses the
//! masked quad (computed here, not by the tracer); the tree and the brute-force slot loop must
//! both give it.

use glam::DVec3;
use proptest::prelude::*;
use relume::radiosity::geometry::Frame;
use relume::raytrace::visibility::Visibility;
use relume::scene::texture::AlphaMask;
use relume::scene::Scene;

const N: u32 = 8;

/// A 4 × 4 floor at y = 0 and above it, at y = 1, a 4 × 4 quad masked by an N × N texture
/// whose opaque texels are the set bits of `bits` (texel (x, y) ↔ bit y·N + x), u = x/4,
/// v = z/4.
fn masked_scene(bits: u64) -> Scene {
    let texels = (0..N * N)
        .flat_map(|i| [90, 90, 90, if bits >> i & 1 == 1 { 255 } else { 0 }])
        .collect();
    crate::fixtures::masked_leaf_over_floor((0.0, 4.0), 0.5, (0.0, 4.0), N, texels)
}

fn visibility(scene: &Scene) -> Visibility {
    let frame = Frame {
        origin: DVec3::ZERO,
        scale: 1.0,
    };
    Visibility::new(scene, &[0, 1, 2, 3], &frame, 4.0)
}

/// Whether the mask is opaque where (x, 1, z) lies; None near a texel edge.
fn opaque_at(bits: u64, x: f64, z: f64) -> Option<bool> {
    let (tx, tz) = (x / 4.0 * N as f64, z / 4.0 * N as f64);
    let edge = |c: f64| (c - c.round()).abs() < 1e-3;
    if edge(tx) || edge(tz) {
        return None;
    }
    let i = tz.floor() as u32 * N + tx.floor() as u32;
    Some(bits >> i & 1 == 1)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn rays_pass_cut_out_texels_and_stop_at_opaque_ones(
        bits in any::<u64>(),
        rays in prop::collection::vec((0.05f64..3.95, 0.05f64..3.95, -0.3f64..0.3, -0.3f64..0.3), 40),
    ) {
        let scene = masked_scene(bits);
        let vis = visibility(&scene);
        for (x, z, dx, dz) in rays {
            // From above the quad, down and a little sideways, to the floor.
            let from = DVec3::new(x, 2.0, z);
            let dir = DVec3::new(dx, -1.0, dz).normalize();
            let at_quad = from + dir * (1.0 / -dir.y);
            let Some(opaque) = opaque_at(bits, at_quad.x, at_quad.z) else { continue };
            let floor = from + dir * (2.0 / -dir.y) + DVec3::new(0.0, 1e-3, 0.0);
            let inside = |p: DVec3| (0.01..3.99).contains(&p.x) && (0.01..3.99).contains(&p.z);
            if !inside(at_quad) || !inside(floor) {
                continue;
            }
            prop_assert_eq!(vis.occluded(from, floor), opaque, "segment to the floor at {:?}", at_quad);
            prop_assert_eq!(vis.occluded_brute_force(from, floor), opaque);
            let hit = vis.closest_hit(from, dir).expect("the floor or the quad");
            let brute = vis.closest_hit_brute_force(from, dir).unwrap();
            prop_assert_eq!(hit.triangle >= 2, opaque, "closest hit {:?} at {:?}", hit, at_quad);
            prop_assert_eq!((hit.triangle, hit.t), (brute.triangle, brute.t));
        }
    }
}

/// A material cut out everywhere (alpha factor below the cutoff, no texture) is not there.
#[test]
fn a_material_cut_out_everywhere_blocks_nothing() {
    let mut scene = masked_scene(u64::MAX);
    let leaf = &mut scene.materials[1];
    leaf.albedo_texture = None;
    leaf.alpha = Some(AlphaMask {
        factor: 0.3,
        texture: None,
        cutoff: 0.5,
    });
    let vis = visibility(&scene);
    assert_eq!(vis.len(), 2, "only the floor is in the tree");
    let from = DVec3::new(2.0, 2.0, 2.0);
    assert!(!vis.occluded(from, DVec3::new(2.1, 0.001, 2.2)));
}

/// Direct-light sample points of a partly cut-out patch lie on opaque texels (a point on a
/// cut-out texel is drawn again), and its area counts only the opaque half.
#[test]
fn sample_points_of_masked_patches_lie_on_opaque_texels() {
    use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
    // A checkerboard: every 1 × 1 voxel of the quad holds two opaque and two cut-out texels.
    let bits = 0xaa55_aa55_aa55_aa55u64;
    let scene = masked_scene(bits);
    let params = VoxelizeParams {
        resolution: Resolution::VoxelSize(1.0),
        samples_per_patch: 16,
    };
    let set = voxelize(&scene, &params).unwrap();
    let spp = set.samples_per_patch as usize;
    let mut checked = 0;
    for (i, p) in set.patches.iter().enumerate() {
        if (p.centroid[1] - 1.0).abs() > 1e-6 {
            continue; // the floor
        }
        assert!(
            (p.area - 0.5).abs() < 1e-6,
            "half of a 1 × 1 patch is opaque: {}",
            p.area
        );
        for s in &set.samples[i * spp..(i + 1) * spp] {
            let [x, _, z] = s.position.map(f64::from);
            if let Some(opaque) = opaque_at(bits, x, z) {
                assert!(opaque, "sample at ({x}, {z}) lies on a cut-out texel");
                checked += 1;
            }
        }
    }
    assert!(checked > 150, "{checked} samples checked");
}
