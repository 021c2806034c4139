//! A terrain frame seen through the air (`terrain_render.wgsl` with `gpu::terrain_air`) against
//! an independent CPU rendering of the same frame: a flat 64 km square seen in perspective,
//! each pixel's ray cut with the ground plane on the CPU (not rasterised), lit as the shader
//! lights it, then the constant-density fog of Vyatkin et al. (2018) in f64
//! (`atmosphere::fog::FogParams`) or Hillaire's tables by their CPU twin (`atmosphere::lut::Luts`),
//! and the sky by the same model. This checks the wiring the kernel twins cannot: units (km), the π
//! of the shading convention, the frames of the view and sun directions, the sun lighting the
//! ground, and where the sky is drawn.

use crate::common;

use common::gpu;
use glam::{Vec3, Vec4};
use relume::atmosphere::fog::FogParams;
use relume::atmosphere::lut::Luts;
use relume::atmosphere::twin::AtmosphereGpu;
use relume::atmosphere::{Atmosphere, Model};
use relume::gpu::terrain_air::air_frame;
use relume::gpu::terrain_renderer::TerrainRenderer;
use relume::gpu::timing::PassTimer;
use relume::gpu::Gpu;
use relume::heightmap::HeightMap;
use relume::render::camera::Camera;
use relume::render::terrain_shading::{tint, TerrainSettings};
use relume::render::tonemap::{to_u8, tonemap};
use relume::terrain::{MinMaxMipmap, Sun};

const W: u32 = 160;
const H: u32 = 120;
const CELL: f64 = 1000.0;

/// (differing pixels beyond 2/255, compared pixels, worst difference) of `model`.
fn compare(gpu: &Gpu, model: Model, sun: Sun) -> (usize, usize, u8) {
    let map = HeightMap {
        width: 64,
        height: 64,
        heights: vec![0.0; 64 * 64],
        cell_size: [CELL, CELL],
        height_scale: 1.0,
    };
    let mip = MinMaxMipmap::build(&map);
    let mut r = TerrainRenderer::new(gpu, &map, &mip, W, H, Some(1)).unwrap();
    r.set_sun(gpu, sun);
    let s = TerrainSettings {
        shadows: false,
        themes: false,
        atmosphere: model,
        vertical_exaggeration: 1.0,
        exposure: 1.0,
        ..Default::default()
    };
    let camera = Camera {
        eye: Vec3::new(32_000.0, 2_500.0, 75_000.0),
        target: Vec3::new(32_000.0, 0.0, 20_000.0),
        up: Vec3::Y,
        fov_y_deg: 50.0,
        near: 10.0,
        far: 400_000.0,
    };
    let vp = camera.view_projection(W, H);
    let mut timer = PassTimer::new(gpu, 2);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    r.record(gpu, &mut enc, vp, camera.eye, &s, &mut timer)
        .unwrap();
    gpu.queue.submit([enc.finish()]);
    let img = r.target.read_image(gpu).unwrap();

    // The CPU frame.
    let atm = Atmosphere::earth();
    let eye = camera.eye.as_dvec3();
    let air = air_frame(
        &atm,
        model,
        sun.toward_y_up_f64(),
        eye.y,
        0.0,
        s.sun_strength,
    );
    let sw = sun.toward_y_up_f64();
    let fog = FogParams::new(&atm, eye.y, sw, false);
    let luts = (model == Model::Hillaire).then(|| {
        let extent = (64.0 * CELL).hypot(64.0 * CELL);
        Luts::build(&AtmosphereGpu::new(
            &atm,
            eye.y.round().max(1.0),
            sw,
            (2.0 * extent).max(50_000.0),
        ))
    });
    let inv = vp.inverse();
    let lambert = sun.direction()[2].max(0.0) as f32;
    let albedo = tint(0.0);
    let (mut off, mut n, mut worst) = (0, 0, 0u8);
    for y in 0..H {
        for x in 0..W {
            let ndc = [
                (x as f32 + 0.5) / W as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / H as f32 * 2.0,
            ];
            let unproject = |z: f32| {
                let p = inv * Vec4::new(ndc[0], ndc[1], z, 1.0);
                (p.truncate() / p.w).as_dvec3()
            };
            let dir = (unproject(1.0) - unproject(0.0)).normalize();
            let t = -eye.y / dir.y;
            let hit = eye + t * dir;
            let inside = |v: f64| (0.5 * CELL + 1.0..63.5 * CELL - 1.0).contains(&v);
            let near_edge =
                |v: f64| (v - 0.5 * CELL).abs() < 1500.0 || (v - 63.5 * CELL).abs() < 1500.0;
            let rgb: [f64; 3] = if t > 0.0 && inside(hit.x) && inside(hit.z) {
                if near_edge(hit.x) || near_edge(hit.z) {
                    continue; // a pixel the mesh's edge splits
                }
                let l0: [f64; 3] = std::array::from_fn(|c| {
                    (albedo[c] * (air.sun_light[c] * lambert + air.sun_light[3])) as f64
                });
                let s_m = t;
                match &luts {
                    None => {
                        let inscatter = fog.apply([0.0; 3], s_m, dir.dot(sw));
                        let tr: [f64; 3] =
                            std::array::from_fn(|c| (-fog.extinction[c] * s_m).exp());
                        std::array::from_fn(|c| l0[c] * tr[c] + std::f64::consts::PI * inscatter[c])
                    }
                    Some(l) => {
                        let (ins, tr) = l.aerial_perspective(dir.as_vec3(), (s_m * 1e-3) as f32);
                        let (ins, tr) = (ins.as_dvec3(), tr.as_dvec3());
                        std::array::from_fn(|c| l0[c] * tr[c] + std::f64::consts::PI * ins[c])
                    }
                }
            } else if t > 0.0 || dir.y > -1e-3 && dir.y < 0.0 {
                continue; // ground beyond the map, or grazing the horizon
            } else {
                // Sky.
                match &luts {
                    None => fog
                        .apply([0.0; 3], 1e12, dir.dot(sw))
                        .map(|v| v * std::f64::consts::PI),
                    Some(l) => {
                        let v = l.sky_radiance(dir.as_vec3()).as_dvec3() * std::f64::consts::PI;
                        [v.x, v.y, v.z]
                    }
                }
            };
            let want = tonemap(rgb.map(|v| v as f32), s.exposure).map(to_u8);
            let got = img.get_pixel(x, y);
            let d = (0..3).map(|c| want[c].abs_diff(got[c])).max().unwrap();
            worst = worst.max(d);
            off += (d > 2) as usize;
            n += 1;
        }
    }
    (off, n, worst)
}

#[test]
fn terrain_frames_through_the_air_match_a_cpu_rendering() {
    let Some(gpu) = gpu() else { return };
    for (model, sun) in [
        (Model::FogPerPixel, Sun::new(120.0, 25.0).unwrap()),
        // Per vertex against the per-pixel reference: the fog interpolated over 1 km cells.
        (Model::Fog, Sun::new(120.0, 25.0).unwrap()),
        (Model::Hillaire, Sun::new(120.0, 25.0).unwrap()),
        (Model::Hillaire, Sun::new(300.0, 3.0).unwrap()),
    ] {
        let (off, n, worst) = compare(&gpu, model, sun);
        eprintln!(
            "{model:?}, sun {}/{}: {off} of {n} pixels differ by more than 2/255, worst {worst}/255",
            sun.azimuth_deg, sun.elevation_deg
        );
        assert!(n > (W * H) as usize / 2, "only {n} pixels compared");
        // Measured on lavapipe: worst 1/255 for every row (f32 against f64 and the tables'
        // CPU twin; 8-bit rounding); 2/255 allowed.
        assert!(
            off == 0 && worst <= 2,
            "{model:?}: {off} of {n} pixels off, worst {worst}"
        );
    }
}
