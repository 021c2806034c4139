//! Per-object light against a closed form.

use crate::fixtures;
use relume::radiosity::mesh::objects::object_light;
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};

/// A constant B over every patch gives H = B / ρ on every object, both ways.
#[test]
fn constant_light_gives_b_over_albedo() {
    let scene = fixtures::thin_wall_rooms(0.05);
    let params = VoxelizeParams {
        resolution: Resolution::VoxelSize(0.2),
        samples_per_patch: 1,
    };
    let set = voxelize(&scene, &params).unwrap();
    let b = vec![[0.35f32, 0.7, 0.07]; set.patches.len()];
    for o in object_light(&scene, &set, &b) {
        for (c, &bc) in b[0].iter().enumerate() {
            let want = bc as f64 / 0.7;
            assert!((o.irradiance[c] / want - 1.0).abs() < 1e-5, "{o:?}");
            assert!((o.irradiance_patches[c] / want - 1.0).abs() < 1e-5, "{o:?}");
        }
    }
}
