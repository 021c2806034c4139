//! Twin test of `direct_light.wgsl` with punctual lights and real shadow maps against the CPU
//! twin with analytic occlusion.

use crate::common;
use crate::twins;

use common::gpu;
use glam::{DVec3, Vec3};
use relume::gpu::mesh_renderer::MeshRenderer;
use relume::gpu::radiosity_runtime::{RadiosityRuntime, TransportSource};
use relume::gpu::readback;
use relume::render::lights::{GpuLight, KIND_DIRECTIONAL};
use relume::render::mesh_reference::FrameSettings;
use relume::scene::LightKind;
use twins::*;

// 4. direct_light.wgsl with punctual lights and shadow maps

/// The square occluder of the direct-light scene: centre, half size (horizontal, facing up).
const OCCLUDER: (Vec3, f32) = (Vec3::new(0.3, 0.6, 0.2), 0.4);

/// Does the occluder cut the segment from `p` to `end`? (Exact, independent of any BVH.)
fn occluded(p: Vec3, end: Vec3) -> bool {
    let (c, h) = OCCLUDER;
    let dy = end.y - p.y;
    if dy.abs() < 1e-12 {
        return false;
    }
    let t = (c.y - p.y) / dy;
    if !(1e-4..1.0).contains(&t) {
        return false;
    }
    let q = p + (end - p) * t;
    (q.x - c.x).abs() <= h && (q.z - c.z).abs() <= h
}

fn light_end(l: &GpuLight, p: Vec3) -> Vec3 {
    if l.kind() == KIND_DIRECTIONAL {
        p - Vec3::from_slice(&l.direction[..3]) * 100.0
    } else {
        Vec3::from_slice(&l.position[..3])
    }
}

#[test]
fn direct_light_kernel_with_punctual_lights_and_shadow_maps_matches_its_twin() {
    use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
    use relume::render::direct::patch_exitance;
    use relume::scene::builder::SceneBuilder;
    let Some(gpu) = gpu() else { return };
    // A floor and a floating square above it.
    let mut b = SceneBuilder::new();
    let m = b.material("grey", [0.8, 0.6, 0.4], [0.0; 3]);
    b.rectangle("floor", DVec3::ZERO, DVec3::Z * 1.5, DVec3::X * 1.5, m);
    let (c, h) = OCCLUDER;
    b.rectangle(
        "occluder",
        c.as_dvec3(),
        DVec3::Z * h as f64,
        DVec3::X * h as f64,
        m,
    );
    let scene = b.build();
    let set = voxelize(
        &scene,
        &VoxelizeParams {
            resolution: Resolution::TargetPatches(300),
            samples_per_patch: 16,
        },
    )
    .unwrap();
    let n = set.patches.len();
    let mut renderer = MeshRenderer::new(&gpu, &scene, 8, 8, 1024).unwrap();
    let zeros = relume::radiosity::TransportMatrix::zeros(1, n);
    let rt = RadiosityRuntime::new(&gpu, &set, TransportSource::Dense(&zeros), &renderer).unwrap();
    let mut point = light(
        LightKind::Point,
        Vec3::new(0.0, 1.4, 0.0),
        Vec3::NEG_Y,
        Vec3::new(1.0, 0.8, 0.6),
        2.0,
    );
    point.range = Some(4.0);
    let spot = light(
        LightKind::Spot {
            inner_cone: 0.35,
            outer_cone: 0.6,
        },
        Vec3::new(-0.8, 1.5, 0.4),
        Vec3::new(1.1, -0.9, -0.2),
        Vec3::new(0.7, 0.9, 1.0),
        3.0,
    );
    let sun = light(
        LightKind::Directional,
        Vec3::ZERO,
        Vec3::new(0.35, -1.0, -0.25),
        Vec3::new(1.0, 0.95, 0.9),
        1.5,
    );
    let s = FrameSettings::default();
    let mut timer = relume::gpu::timing::PassTimer::new(&gpu, 48);
    // Sample points whose shadow is the same within DELTA in the surface plane all around
    // (about 10 shadow-map texels for every light here): far from shadow edges, where the
    // shadow map's PCF, its normal offset and its depth bias change nothing.
    const DELTA: f32 = 0.04;
    let clear = |l: &GpuLight, p: Vec3| {
        let o = occluded(p, light_end(l, p));
        (0..8).all(|k| {
            let a = k as f32 * std::f32::consts::FRAC_PI_4;
            let q = p + Vec3::new(a.cos(), 0.0, a.sin()) * DELTA;
            occluded(q, light_end(l, q)) == o
        })
    };
    let mut overall = 0.0f32;
    for (name, scene_lights) in [
        ("point", vec![point.clone()]),
        ("spot", vec![spot.clone()]),
        ("directional", vec![sun.clone()]),
        ("all three", vec![point, spot, sun]),
    ] {
        let gl: Vec<GpuLight> = scene_lights
            .iter()
            .map(|l| GpuLight::from_light(l, 1.0, 0))
            .collect();
        renderer.set_lights(&gpu, &gl).unwrap();
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        renderer.record_shadows(&mut enc, &mut timer);
        rt.record(
            &gpu,
            &mut enc,
            &renderer,
            &s,
            set.samples_per_patch,
            &mut timer,
        );
        gpu.queue.submit([enc.finish()]);
        gpu.wait();
        let got = readback::read_f32(&gpu, &rt.exitance).unwrap();
        let u = renderer.lights_uniform();
        let lights = &u.lights[..u.count as usize];
        let exact = |l: usize, p: Vec3, _n: Vec3, _to: Vec3, _d: f32| {
            !occluded(p, light_end(&lights[l], p))
        };
        let want = patch_exitance(&set, lights, &s, &exact);
        let unshadowed = patch_exitance(&set, lights, &s, &|_, _, _, _, _| true);
        let spp = set.samples_per_patch as usize;
        let (mut compared, mut shadowed, mut lit) = (0, 0, 0);
        let mut max_err = 0.0f32;
        for i in 0..n {
            let samples = &set.samples[i * spp..(i + 1) * spp];
            if !samples
                .iter()
                .all(|sp| lights.iter().all(|l| clear(l, Vec3::from(sp.position))))
            {
                continue;
            }
            compared += 1;
            let un = Vec3::from(unshadowed[i]);
            let (w, g) = (
                Vec3::from(want[i]),
                Vec3::from_slice(&got[4 * i..4 * i + 3]),
            );
            if un.max_element() > 0.0 {
                if w.max_element() < 0.5 * un.max_element() {
                    shadowed += 1;
                } else {
                    lit += 1;
                }
            }
            // Relative to the patch's unshadowed exitance (0 where no light reaches it).
            // Measured on lavapipe: 1.6e-7 (the point light; spot and sun bit-identical),
            // tolerance 5e-7 (3.2x).
            let e = (g - w).abs().max_element() / un.max_element().max(1e-20);
            max_err = max_err.max(e);
            assert!(
                e <= 5e-7,
                "{name}: patch {i} at {:?}: gpu {g} cpu {w} (unshadowed {un})",
                set.patches[i].centroid
            );
        }
        eprintln!(
            "direct light, {name}: {compared}/{n} patches away from shadow edges compared \
             ({shadowed} mostly shadowed, {lit} mostly lit), max relative error {max_err:.3e}"
        );
        assert!(
            compared * 2 > n,
            "{name}: only {compared} of {n} patches compared"
        );
        assert!(
            shadowed >= 3 && lit >= 3,
            "{name}: {shadowed} shadowed, {lit} lit"
        );
        overall = overall.max(max_err);
    }
    eprintln!("direct light: max relative error {overall:.3e}");
}

// ---------------------------------------------------------------------------------------------
