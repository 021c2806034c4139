//! Terrain on the GPU (lavapipe in CI) against the CPU: the hard-shadow kernels of
//! `shaders/terrain_shadow.wgsl` against the f32 twins (`terrain::hard::hard_f32`, same arithmetic)
//! and the f64 reference (`terrain::hard::relief::shadow_mask`), and the terrain shading against
//! `render::terrain_shading` in the top-down map view.

use crate::common;

use common::gpu;

use relume::gpu::terrain_renderer::TerrainRenderer;
use relume::gpu::{timing::PassTimer, Gpu};
use relume::heightmap::{load_heightmap, HeightMap, HeightMapOptions};
use relume::render::terrain_shading::{map_view, TerrainSettings};
use relume::terrain::hard::hard_f32::{shadowed_accelerated_f32, shadowed_exact_f32, TrackF32};
use relume::terrain::hard::relief::{shadow_mask, HardMethod};
use relume::terrain::sun::{Sun, Track};
use relume::terrain::MinMaxMipmap;
use relume::theme::ThemeSet;

fn srtm_half() -> HeightMap {
    let (m, _) = load_heightmap(
        &common::data("scenes/dem/srtm_bigtujunga_30m.tif"),
        &HeightMapOptions::default(),
    )
    .unwrap();
    m.downsample(2)
}

fn puget_512() -> HeightMap {
    let opts = HeightMapOptions {
        cell_size: Some([40.0, 40.0]),
        height_scale: Some(10.0),
        ..Default::default()
    };
    let (m, _) = load_heightmap(&common::data("scenes/dem/puget_sound_4k.jpg"), &opts).unwrap();
    m.downsample(8)
}

/// GPU masks (exact and accelerated) against the CPU for several suns on a real DEM. Returns
/// (pixels compared, pixels differing from the f64 reference).
fn compare_masks(gpu: &Gpu, map: &HeightMap, suns: &[Sun]) -> (usize, usize) {
    let mip = MinMaxMipmap::build(map);
    let mut r = TerrainRenderer::new(gpu, map, &mip, 8, 8, None).unwrap();
    let (mut total, mut off_f64) = (0usize, 0usize);
    let (_, max_height) = map.min_max();
    for sun in suns {
        r.set_sun(gpu, *sun);
        let gpu_acc = r.shadow_mask(gpu, true).unwrap();
        let gpu_exact = r.shadow_mask(gpu, false).unwrap();
        // The f32 twins do the same arithmetic: equal on every pixel.
        let t32 = TrackF32::from(&Track::new(sun, map.cell_size));
        for row in 0..map.height {
            for col in 0..map.width {
                let i = row * map.width + col;
                let want = shadowed_accelerated_f32(map, &mip, &t32, col, row);
                assert_eq!(
                    gpu_acc[i], want,
                    "accelerated, sun {sun:?}, pixel ({col}, {row})"
                );
                let want = shadowed_exact_f32(map, &t32, col, row, max_height);
                assert_eq!(
                    gpu_exact[i], want,
                    "exact, sun {sun:?}, pixel ({col}, {row})"
                );
            }
        }
        assert_eq!(
            gpu_acc, gpu_exact,
            "GPU accelerated != GPU exact for sun {sun:?}"
        );
        let cpu = shadow_mask(map, sun, HardMethod::Exact, None, &relume::progress::Silent);
        total += cpu.len();
        off_f64 += cpu.iter().zip(&gpu_acc).filter(|(a, b)| a != b).count();
    }
    (total, off_f64)
}

fn suns() -> Vec<Sun> {
    let mut v = Vec::new();
    for (az, el) in [
        (0.0, 10.0),
        (45.0, 5.0),
        (90.0, 30.0),
        (135.0, 2.0),
        (200.0, 15.0),
        (300.0, 8.0),
        (300.0, 60.0),
        (270.0, 1.0),
    ] {
        v.push(Sun::new(az, el).unwrap());
    }
    v
}

#[test]
fn gpu_hard_shadow_masks_match_the_cpu_on_real_dems() {
    let Some(gpu) = gpu() else { return };
    for (name, map) in [
        ("SRTM Big Tujunga 599x322", srtm_half()),
        ("Puget Sound 512x512", puget_512()),
    ] {
        let (total, off) = compare_masks(&gpu, &map, &suns());
        let frac = off as f64 / total as f64;
        eprintln!("{name}: GPU (f32) vs CPU (f64) exact mask: {off} of {total} pixel-sun cases differ ({:.1e})", frac);
        // Only pixels whose deciding sample lies within f32 rounding of the sun ray may flip
        // (docs/terrain.md "Precision and the GPU port"); the f32 twins measured 3e-4 on SRTM.
        assert!(frac <= 1e-3, "{name}: {off} of {total} differ");
    }
}

/// The top-down map view of `r` (one pixel per texel of `map`, no fog, true scale) under
/// `sun` against `render::terrain_shading::map_view` with the per-texel `shadow` the GPU is
/// expected to use: (mean, max) absolute difference per 8-bit channel over interior pixels
/// (the mesh's vertices sit at texel centres, so the outer half texel is not covered).
fn map_view_difference(
    gpu: &Gpu,
    r: &mut TerrainRenderer,
    map: &HeightMap,
    sun: Sun,
    shadow: impl Fn(&TerrainRenderer) -> Vec<bool>,
    themes: Option<(&ThemeSet, u32)>,
) -> (f64, u8) {
    r.set_sun(gpu, sun);
    if let Some((set, frame)) = themes {
        r.set_themes(gpu, set);
        r.set_theme_shift(gpu, set.shift(frame));
    }
    let s = TerrainSettings {
        atmosphere: relume::atmosphere::Model::None,
        vertical_exaggeration: 1.0,
        ..Default::default()
    };
    let (view_proj, eye) = r.map_view();
    let mut timer = PassTimer::new(gpu, 2);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    r.record(gpu, &mut enc, view_proj, eye, &s, &mut timer)
        .unwrap();
    gpu.queue.submit([enc.finish()]);
    let img = r.target.read_image(gpu).unwrap();
    let shadow: Vec<f32> = shadow(r).iter().map(|&b| b as u8 as f32).collect();
    let want = map_view(map, &sun, &shadow, &s, themes);
    let (w, h) = (map.width as u32, map.height as u32);
    let (mut sum, mut n, mut worst) = (0u64, 0u64, 0u8);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let (a, b) = (img.get_pixel(x, y), want.get_pixel(x, y));
            for c in 0..3 {
                let d = a[c].abs_diff(b[c]);
                sum += d as u64;
                worst = worst.max(d);
            }
            n += 3;
        }
    }
    (sum as f64 / n as f64, worst)
}

/// The map view of `map` (traversal shadows, sun 300°/12°, themes when given) against the CPU
/// shading: same formulas in f32 on both sides; the GPU's pow/exp differ by ulps, so 8-bit
/// values may differ by one step at rounding boundaries (measured: max 1/255, mean 0.0000).
fn assert_map_view_matches(gpu: &Gpu, map: &HeightMap, themes: Option<(&ThemeSet, u32)>) {
    let mip = MinMaxMipmap::build(map);
    let (w, h) = (map.width as u32, map.height as u32);
    let mut r = TerrainRenderer::new(gpu, map, &mip, w, h, Some(1)).unwrap();
    let sun = Sun::new(300.0, 12.0).unwrap();
    let (mean, worst) = map_view_difference(
        gpu,
        &mut r,
        map,
        sun,
        |r| r.shadow_mask(gpu, true).unwrap(),
        themes,
    );
    let what = if themes.is_some() { "themed" } else { "plain" };
    eprintln!("{what} terrain map view: mean |GPU − CPU| = {mean:.4}/255, max {worst}/255");
    assert!(worst <= 1, "{what}: max difference {worst}/255");
    assert!(mean < 0.05, "{what}: mean difference {mean}");
}

#[test]
fn map_view_matches_the_cpu_shading() {
    let Some(gpu) = gpu() else { return };
    assert_map_view_matches(&gpu, &srtm_half(), None);
}

#[test]
fn themed_map_view_matches_the_cpu_shading() {
    // The bundled Puget Sound themes over their height map, animation frame 3: the terrain
    // frame's theme lookup (theme.wgsl, footprint from screen derivatives) against
    // render::terrain_shading::map_view with theme::compose.
    let Some(gpu) = gpu() else { return };
    let map = puget_512();
    let given = relume::load::themes::GivenHeightMap {
        map: &map,
        georef: None,
        name: "the Puget Sound height map",
    };
    let set =
        relume::load::themes::load_themes(&common::data("themes/puget-sound.ron"), Some(given))
            .unwrap();
    assert_map_view_matches(&gpu, &map, Some((&set, 3)));
}

#[test]
fn gpu_soft_lit_fraction_matches_the_cpu_within_1e_3() {
    use relume::terrain::soft::{soft_shadow_map, SoftMethod, SoftShadowParams};
    let Some(gpu) = gpu() else { return };
    // Low suns, flat ground and the Earth's curvature, a wide disc: a real DEM.
    let map = puget_512();
    let mip = MinMaxMipmap::build(&map);
    let mut r = TerrainRenderer::new(&gpu, &map, &mip, 8, 8, None).unwrap();
    let mut worst = 0.0f32;
    for (az, el, radius_deg, planet) in [
        (300.0, 3.0, 0.2666, None),
        (45.0, 1.0, 0.2666, Some(6.371e6)),
        (135.0, 8.0, 2.0, None),
        (270.0, -0.1, 0.2666, None),
    ] {
        let sun = Sun::new(az, el).unwrap();
        r.set_sun(&gpu, sun);
        r.set_soft(&gpu, radius_deg, planet);
        let gpu_lit = r.lit_fraction(&gpu).unwrap();
        let params = SoftShadowParams {
            sun_radius_deg: radius_deg,
            planet_radius_m: planet,
            method: SoftMethod::BranchAndBound,
        };
        let cpu =
            soft_shadow_map(&map, &sun, &params, Some(&mip), &relume::progress::Silent).unwrap();
        let mut partial = 0;
        for (i, (g, c)) in gpu_lit.iter().zip(&cpu).enumerate() {
            assert!(g.is_finite() && (0.0..=1.0).contains(g), "lit[{i}] = {g}");
            worst = worst.max((g - c).abs());
            partial += (*c > 0.0 && *c < 1.0) as usize;
        }
        eprintln!("soft sun {az}/{el}° α {radius_deg}° planet {planet:?}: max |GPU − CPU| = {worst:.2e}, {partial} penumbra texels");
    }
    // Measured on lavapipe: 6.2e-6 (f32 with sample positions relative to P, see
    // shaders/terrain_shadow.wgsl); the issue asks for 1e-3.
    assert!(
        worst <= 1e-3,
        "GPU soft lit fraction differs from the CPU by {worst}"
    );
}

#[test]
fn player_renders_a_height_map_bake_headless() {
    if gpu().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let bake_dir = tmp.path().join("bt");
    let o = common::bake(
        tmp.path(),
        &[
            "-q",
            "run",
            common::data("pipelines/bigtujunga.ron").to_str().unwrap(),
            "--out",
            bake_dir.to_str().unwrap(),
        ],
    );
    common::expect_code(&o, 0);
    for (name, extra) in [
        ("hard", vec![]),
        ("soft", vec!["--soft"]),
        ("noshadow", vec!["--no-shadows", "--no-fog"]),
    ] {
        let out = tmp.path().join(name);
        let mut args = vec![
            bake_dir.to_str().unwrap(),
            "--headless",
            "--size",
            "160x120",
            "--sun",
            "250,8",
            "--frames",
            "2",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_relume-player"))
            .args(&args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", common::text(&o));
        let img = image::open(out.join("frame_0001.png")).unwrap().to_rgba8();
        assert_eq!(img.dimensions(), (160, 120));
        let distinct: std::collections::BTreeSet<[u8; 4]> = img.pixels().map(|p| p.0).collect();
        assert!(
            distinct.len() > 100,
            "{name}: a flat image ({} colours)",
            distinct.len()
        );
        let j: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join("frames.json")).unwrap()).unwrap();
        assert_eq!(j["frames"].as_array().unwrap().len(), 2);
        assert!(j["adapter"]["name"].as_str().is_some());
    }
    // Hard and soft shadows differ; both differ from no shadows.
    let load = |n: &str| {
        image::open(tmp.path().join(n).join("frame_0000.png"))
            .unwrap()
            .to_rgba8()
    };
    let (hard, soft) = (load("hard"), load("soft"));
    assert!(
        hard.pixels().zip(soft.pixels()).any(|(a, b)| a != b),
        "soft shadows look exactly like hard ones"
    );
}

/// The horizon-map mask on the GPU (`shadowed_horizon`) against its f32 twin
/// (`HorizonMap::shadow_mask_f32`) and the f64 test (`HorizonMap::shadow_mask`); at a stored
/// azimuth, against the exact traversal. Returns nothing; asserts.
#[test]
fn gpu_horizon_masks_match_the_twin_and_the_exact_mask() {
    use relume::terrain::horizon::map::{decode, HorizonMap, HorizonSettings};
    let Some(gpu) = gpu() else { return };
    let map = srtm_half();
    let mip = MinMaxMipmap::build(&map);
    let hm = HorizonMap::build(&map, &HorizonSettings::flat(32));
    let mut r = TerrainRenderer::new(&gpu, &map, &mip, 8, 8, None).unwrap();
    // Before horizon maps are set, method 3 falls back to the accelerated traversal.
    let sun0 = Sun::new(123.0, 7.0).unwrap();
    r.set_sun(&gpu, sun0);
    assert_eq!(
        r.shadow_mask_horizon(&gpu).unwrap(),
        r.shadow_mask(&gpu, true).unwrap()
    );
    r.set_horizon(&gpu, hm.clone()).unwrap();
    let stored = hm.directions[5].azimuth_deg;
    let mut all = suns();
    all.extend([
        Sun::new(stored, 12.0).unwrap(),
        Sun::new(stored + 1.3, 12.0).unwrap(),
        Sun::new(10.0, 90.0).unwrap(),
        Sun::new(10.0, -1.0).unwrap(),
        Sun::new(10.0, 0.0).unwrap(),
    ]);
    let (mut total, mut off_twin, mut off_f64) = (0usize, 0usize, 0usize);
    for sun in &all {
        r.set_sun(&gpu, *sun);
        let g = r.shadow_mask_horizon(&gpu).unwrap();
        let twin = hm.shadow_mask_f32(sun);
        let f64_mask = hm.shadow_mask(sun);
        let (k0, k1, w) = hm.bracket(sun.azimuth_deg);
        for i in 0..g.len() {
            if g[i] != twin[i] {
                // Only a fused multiply-add on the GPU can move the test, and only for an
                // elevation within f32 rounding of the interpolated horizon.
                let h = decode(hm.angles[k0][i]) * (1.0 - w) + decode(hm.angles[k1][i]) * w;
                assert!(
                    (h - sun.elevation_deg).abs() < 1e-4,
                    "sun {sun:?} texel {i}: GPU {} twin {} (horizon {h}°)",
                    g[i],
                    twin[i]
                );
                off_twin += 1;
            }
        }
        off_f64 += g.iter().zip(&f64_mask).filter(|(a, b)| a != b).count();
        total += g.len();
    }
    eprintln!(
        "horizon masks: GPU vs f32 twin {off_twin}, vs f64 {off_f64} of {total} texel-sun cases"
    );
    assert!(off_twin * 10_000 <= total, "{off_twin} of {total}");
    // At a stored azimuth the interpolation weight is 0 or 1: the horizon map is the exact
    // traversal's shadow test for every elevation, up to the u16 quantisation (≤ 0.0014°).
    let sun = Sun::new(stored, 12.0).unwrap();
    r.set_sun(&gpu, sun);
    let g = r.shadow_mask_horizon(&gpu).unwrap();
    let exact = shadow_mask(
        &map,
        &sun,
        HardMethod::Exact,
        None,
        &relume::progress::Silent,
    );
    let off = g.iter().zip(&exact).filter(|(a, b)| a != b).count();
    eprintln!(
        "horizon mask at stored azimuth {stored:.4}°/12°: {off} of {} pixels differ from the exact mask",
        g.len()
    );
    // Measured on lavapipe: see docs/terrain.md; each such pixel has its horizon within the
    // quantisation step of 12°.
    let (k0, k1, w) = hm.bracket(stored);
    let k = if w < 0.5 { k0 } else { k1 };
    for i in 0..g.len() {
        if g[i] != exact[i] {
            let h = decode(hm.angles[k][i]);
            assert!(
                (h - 12.0).abs() <= relume::terrain::horizon::map::STEP_DEG,
                "texel {i}: horizon {h}° vs sun 12°"
            );
        }
    }
}

#[test]
fn map_view_with_horizon_shadows_matches_the_cpu_shading() {
    use relume::terrain::horizon::map::{HorizonMap, HorizonSettings};
    let Some(gpu) = gpu() else { return };
    let map = srtm_half();
    let mip = MinMaxMipmap::build(&map);
    let (w, h) = (map.width as u32, map.height as u32);
    let mut r = TerrainRenderer::new(&gpu, &map, &mip, w, h, Some(1)).unwrap();
    let hm = HorizonMap::build(&map, &HorizonSettings::flat(16));
    r.set_horizon(&gpu, hm.clone()).unwrap();
    assert!(
        TerrainSettings::default().horizon,
        "horizon shadows are the default when a bake has them"
    );
    let sun = Sun::new(205.0, 9.0).unwrap();
    let (mean, worst) =
        map_view_difference(&gpu, &mut r, &map, sun, |_| hm.shadow_mask_f32(&sun), None);
    eprintln!("terrain map view with horizon shadows: mean {mean:.4}/255, max {worst}/255");
    // As in the traversal's map view: one 8-bit step at rounding boundaries.
    assert!(worst <= 1, "max difference {worst}/255");
}
