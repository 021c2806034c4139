//! Textured and alpha-masked materials in the mesh shader and the shadow pass (lavapipe in CI)
//! against the CPU reference frame (`render::raycast`, which reads the textures through
//! `render::material_maps` and traces masked shadow rays): a textured quad magnified and four
//! texels to a pixel, a masked quad over a floor in the sun, and the Dabrovic Sponza.

use crate::common::{self, gpu};
use glam::Vec3;
use relume::gpu::mesh_renderer::MeshRenderer;
use relume::gpu::timing::PassTimer;
use relume::gpu::Gpu;
use relume::render::camera::Camera;
use relume::render::lights::GpuLight;
use relume::render::mesh_reference::FrameSettings;
use relume::render::raycast::RaycastScene;
use relume::scene::texture::{Texture, TextureRef};
use relume::scene::{Light, LightKind, Material, Scene};

fn sun(direction: Vec3, lux: f32) -> GpuLight {
    let l = Light {
        name: "sun".into(),
        kind: LightKind::Directional,
        position: [0.0; 3],
        direction: direction.normalize().to_array(),
        color: [1.0; 3],
        intensity: lux,
        range: None,
    };
    GpuLight::from_light(&l, 1.0, 0)
}

/// One GPU frame of `scene` and the CPU reference frame of the same view.
fn frames(
    gpu: &Gpu,
    scene: &Scene,
    camera: &Camera,
    lights: &[GpuLight],
    s: &FrameSettings,
    size: (u32, u32),
) -> (image::RgbaImage, image::RgbaImage) {
    frames_with_indirect(gpu, scene, camera, lights, s, size, &[])
}

/// [`frames`] with per-corner indirect exitance (3 floats per corner; empty for none).
fn frames_with_indirect(
    gpu: &Gpu,
    scene: &Scene,
    camera: &Camera,
    lights: &[GpuLight],
    s: &FrameSettings,
    (w, h): (u32, u32),
    indirect: &[f32],
) -> (image::RgbaImage, image::RgbaImage) {
    let mut r = MeshRenderer::new(gpu, scene, w, h, 2048).unwrap();
    r.set_lights(gpu, lights).unwrap();
    if !indirect.is_empty() {
        r.set_indirect(gpu, indirect);
    }
    let mut timer = PassTimer::new(gpu, 48);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    r.record_shadows(&mut enc, &mut timer);
    r.record_shade(gpu, &mut enc, camera, s, &mut timer);
    gpu.queue.submit([enc.finish()]);
    let got = r.target.read_image(gpu).unwrap();
    let u = r.lights_uniform();
    let lights = &u.lights[..u.count as usize];
    let want = RaycastScene::new(scene).render(camera, lights, s, indirect, w, h);
    (got, want)
}

/// Mean absolute difference per 8-bit channel, the fraction of pixels differing by more than
/// `big` in any channel, and the largest difference.
fn compare(a: &image::RgbaImage, b: &image::RgbaImage, big: u8) -> (f64, f64, u8) {
    let (mut sum, mut outliers, mut worst) = (0u64, 0usize, 0u8);
    for (pa, pb) in a.pixels().zip(b.pixels()) {
        let d = [0, 1, 2].map(|c| pa[c].abs_diff(pb[c]));
        sum += d.iter().map(|&x| x as u64).sum::<u64>();
        outliers += d.iter().any(|&x| x > big) as usize;
        worst = worst.max(*d.iter().max().unwrap());
    }
    let n = (a.width() * a.height()) as f64;
    (sum as f64 / (3.0 * n), outliers as f64 / n, worst)
}

/// A 2 m × 2 m quad in the plane z = 0 facing +z, its `n`×`n` texture of random colours tiled
/// twice each way.
fn textured_quad(n: u32) -> Scene {
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let texels = (0..n * n * 4)
        .map(|i| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            if i % 4 == 3 {
                255
            } else {
                (s >> 56) as u8
            }
        })
        .collect();
    let mut m = Material::plain("tiles", [0.9, 0.8, 1.0], [0.0; 3]);
    m.albedo_texture = Some(TextureRef::new(0));
    Scene {
        positions: vec![
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        triangle_material: vec![0, 0],
        triangle_object: vec![0, 0],
        objects: vec!["quad".into()],
        materials: vec![m],
        uvs: vec![[0.0, 2.0], [2.0, 2.0], [2.0, 0.0], [0.0, 0.0]],
        textures: vec![Texture::from_rgba8("noise".into(), n, n, texels).unwrap()],
        ..Default::default()
    }
}

#[test]
fn albedo_textures_match_the_cpu_twin_magnified_and_minified() {
    let Some(gpu) = gpu() else { return };
    // Light straight on at π/2 lux and indirect exitance 0.4 at every corner, which the texel's
    // ratio to the material's mean albedo modulates; no shadows to compare.
    let lights = [sun(Vec3::NEG_Z, std::f32::consts::FRAC_PI_2)];
    let indirect = vec![0.4f32; 3 * 6];
    let s = FrameSettings {
        shadows: false,
        ..Default::default()
    };
    let look = |distance: f32| Camera {
        eye: Vec3::new(0.0, 0.0, distance),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 60.0,
        near: 0.01,
        far: 100.0,
    };
    // (texture size, camera distance, what it tests, how much the clay view must differ): 16²
    // at 2 m, about 3.5 pixels per texel (the magnification filter, level 0; clay differs by
    // 19.6/255 on average); 64² at 3.46 m, 4 texels per pixel (levels 2 and 3, which average the
    // noise toward its mean: clay differs by 4.6/255).
    for (n, distance, what, clay_diff) in
        [(16, 2.0, "magnified", 10.0), (64, 3.46, "minified", 2.0)]
    {
        let scene = textured_quad(n);
        let (got, want) = frames_with_indirect(
            &gpu,
            &scene,
            &look(distance),
            &lights,
            &s,
            (128, 128),
            &indirect,
        );
        let (mean, outliers, worst) = compare(&got, &want, 6);
        eprintln!(
            "{what}: mean abs error {mean:.3}/255, {:.2} % pixels off by > 6, worst {worst}",
            outliers * 100.0
        );
        // Measured on lavapipe (Mesa 22.3.6, trilinear, anisotropy 1 on a CPU adapter):
        // magnified 0.050/255 mean, minified 0.035/255, both at most 1/255 (the filter's
        // weight precision); bounds 4x the mean, 2/255 anywhere.
        assert!(mean < 0.2, "{what}: mean error {mean}");
        assert!(worst <= 2, "{what}: worst {worst}");
        // The texture is really there: the clay view (the material's mean) differs.
        let (clay, _) = frames_with_indirect(
            &gpu,
            &scene,
            &look(distance),
            &lights,
            &FrameSettings {
                textures: false,
                ..s
            },
            (128, 128),
            &indirect,
        );
        let (diff, _, _) = compare(&got, &clay, 6);
        eprintln!("{what}: the clay view differs by {diff:.2}/255");
        assert!(
            diff > clay_diff,
            "{what}: textures change the frame by only {diff}"
        );
    }
}

/// A 4 m × 4 m floor at y = 0 and, at y = 1, a 2 m × 2 m quad cut by an 8×8 checker mask with
/// three opaque texels in four.
fn masked_leaf() -> Scene {
    let texels = (0..64u32)
        .flat_map(|i| {
            let (x, y) = (i % 8, i / 8);
            let cut = x % 2 == 1 && y % 2 == 1;
            [40, 160, 40, if cut { 0 } else { 255 }]
        })
        .collect();
    crate::fixtures::masked_leaf_over_floor((-2.0, 4.0), 0.7, (-1.0, 2.0), 8, texels)
}

#[test]
fn alpha_masks_cut_the_surface_and_its_shadow() {
    let Some(gpu) = gpu() else { return };
    let scene = masked_leaf();
    let lights = [sun(Vec3::new(0.3, -1.0, 0.2), 3.0)];
    let camera = Camera::orbit(Vec3::ZERO, 6.0, 20.0, 55.0, 50.0);
    let s = FrameSettings::default();
    let (got, want) = frames(&gpu, &scene, &camera, &lights, &s, (160, 120));
    let (mean, outliers, worst) = compare(&got, &want, 24);
    eprintln!(
        "masked leaf: mean abs error {mean:.3}/255, {:.2} % pixels off by > 24, worst {worst}",
        outliers * 100.0
    );
    // Differences lie on the holes' outlines and their shadows': the GPU alpha-tests the mask
    // filtered bilinearly (a one-texel hole becomes a rounded square inside the texel) and
    // its shadow map has 2×2 PCF; the reference reads nearest texels and traces exact rays.
    // Measured on lavapipe: 2.10/255 mean, 1.78 % of pixels off by > 24; bounds 1.5x.
    assert!(mean < 3.2, "mean error {mean}");
    assert!(outliers < 0.027, "outliers {outliers}");
    // The same frame with the leaf opaque is much further from the reference: the holes and
    // their light on the floor are what the masked frame gets right.
    let mut solid = scene.clone();
    solid.materials[1].alpha = None;
    let (opaque, _) = frames(&gpu, &solid, &camera, &lights, &s, (160, 120));
    let (solid_mean, holes, _) = compare(&opaque, &want, 24);
    eprintln!(
        "opaque leaf against the masked reference: {solid_mean:.3}/255, {:.2} % of pixels off by > 24",
        holes * 100.0
    );
    assert!(
        solid_mean > 2.0 * mean,
        "the mask changes the frame by only {solid_mean}"
    );
}

#[test]
fn the_dabrovic_sponza_frame_matches_the_cpu_twin() {
    let Some(gpu) = gpu() else { return };
    let path = common::data("../shared/data/scenes/sponza/sponza.obj");
    assert!(path.exists(), "{} is missing", path.display());
    let (scene, _) = relume::scene::load_scene(&path, Default::default()).unwrap();
    // Inside the atrium, looking down its length: the sun through the open roof, a lamp in the
    // middle of the floor.
    let camera = Camera {
        eye: Vec3::new(-10.0, 2.0, -0.5),
        target: Vec3::new(8.0, 4.0, 0.5),
        up: Vec3::Y,
        fov_y_deg: 60.0,
        near: 0.05,
        far: 100.0,
    };
    let lamp = Light {
        name: "lamp".into(),
        kind: LightKind::Point,
        position: [0.0, 3.0, 0.0],
        direction: [0.0, -1.0, 0.0],
        color: [1.0, 0.9, 0.8],
        intensity: 40.0,
        range: None,
    };
    let lights = [
        sun(Vec3::new(0.25, -1.0, 0.35), 3.0),
        GpuLight::from_light(&lamp, 1.0, 0),
    ];
    let s = FrameSettings {
        exposure: 2.0,
        ..Default::default()
    };
    let (got, want) = frames(&gpu, &scene, &camera, &lights, &s, (240, 160));
    let (mean, outliers, worst) = compare(&got, &want, 24);
    eprintln!(
        "Dabrovic Sponza: mean abs error {mean:.3}/255, {:.2} % pixels off by > 24, worst {worst}",
        outliers * 100.0
    );
    // Shadow maps (sun and the lamp's six faces, 2×2 PCF) against exact shadow rays differ
    // on shadow edges, filtered against nearest alpha on the few masked texels. Measured on
    // lavapipe: 2.47/255 mean, 3.64 % of pixels off by > 24; bounds 1.6x and 1.4x.
    assert!(mean < 4.0, "mean error {mean}");
    assert!(outliers < 0.05, "outliers {outliers}");
    let (clay, _) = frames(
        &gpu,
        &scene,
        &camera,
        &lights,
        &FrameSettings {
            textures: false,
            ..s
        },
        (240, 160),
    );
    // On the lit pixels (luma over 16 in either frame) the textures change the picture.
    let (mut sum, mut lit) = (0u64, 0u64);
    for (a, b) in got.pixels().zip(clay.pixels()) {
        if a[1].max(b[1]) > 16 {
            lit += 1;
            sum += (0..3).map(|c| a[c].abs_diff(b[c]) as u64).sum::<u64>();
        }
    }
    let diff = sum as f64 / (3.0 * lit.max(1) as f64);
    eprintln!(
        "the clay view differs by {diff:.2}/255 on {:.1} % lit pixels",
        100.0 * lit as f64 / (240.0 * 160.0)
    );
    assert!(lit > 240 * 160 / 5, "only {lit} lit pixels");
    // Measured 3.47/255 (the Dabrovic stone is low in contrast); bound 2.
    assert!(
        diff > 2.0,
        "the textures change the lit pixels by only {diff}/255"
    );
}
