//! Textured materials: MTL texture statements as found in the wild, the loaders on the two
//! Sponzas, and the texture-space integral behind per-patch albedo against a brute-force
//! texel-by-texel one.

use crate::common::data;
use glam::DVec2;
use proptest::prelude::*;
use relume::radiosity::patches::albedo::Table;
use relume::radiosity::patches::voxelize::{voxelize, Resolution, VoxelizeParams};
use relume::scene::texture::{Channel, Texture, Wrap};
use relume::scene::{load_scene, SceneOptions};
use std::path::{Path, PathBuf};

fn srgb(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A texture of `w × h` texels from a seed (all four channels vary).
fn noise_texture(w: u32, h: u32, seed: u64) -> Texture {
    let mut x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let texels = (0..4 * w * h)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 32) as u8
        })
        .collect();
    Texture::from_rgba8("noise".into(), w, h, texels).unwrap()
}

fn wrap_of(k: u8) -> Wrap {
    [Wrap::Repeat, Wrap::ClampToEdge, Wrap::MirroredRepeat][k as usize % 3]
}

/// The area of `poly` inside the unit texel at (x, y): an independent clipper (one half-plane at
/// a time, written out here) — the brute force the quadtree is checked against.
fn area_in_texel(poly: &[DVec2], x: f64, y: f64) -> f64 {
    let mut p = poly.to_vec();
    let edges = [
        (DVec2::X, x),
        (-DVec2::X, -(x + 1.0)),
        (DVec2::Y, y),
        (-DVec2::Y, -(y + 1.0)),
    ];
    for (n, d) in edges {
        let mut out = Vec::new();
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            let (da, db) = (n.dot(a) - d, n.dot(b) - d);
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                out.push(a + (b - a) * (da / (da - db)));
            }
        }
        p = out;
    }
    let n = p.len();
    (0.5 * (0..n).map(|i| p[i].perp_dot(p[(i + 1) % n])).sum::<f64>()).abs()
}

/// Σ over every texel of (area of `poly` in it) × (linear red of the wrapped texel).
fn brute_force_red(tex: &Texture, wrap: [Wrap; 2], poly: &[DVec2]) -> f64 {
    let lo = poly.iter().fold(DVec2::INFINITY, |a, &p| a.min(p)).floor();
    let hi = poly
        .iter()
        .fold(DVec2::NEG_INFINITY, |a, &p| a.max(p))
        .ceil();
    let mut sum = 0.0;
    for y in lo.y as i64..hi.y as i64 {
        for x in lo.x as i64..hi.x as i64 {
            let a = area_in_texel(poly, x as f64, y as f64);
            if a > 0.0 {
                sum += a * srgb(tex.texel(x, y, wrap)[0]);
            }
        }
    }
    sum
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Below the boundary-cell cap the texture-space integral is exact: the same as clipping
    /// the polygon against every texel, for every wrap mode, far outside the image too.
    #[test]
    fn integral_matches_texel_by_texel_clipping(
        w in 1u32..9, h in 1u32..9, seed in any::<u64>(), wu in 0u8..3, wv in 0u8..3,
        corners in prop::array::uniform3((-40.0f64..40.0, -40.0f64..40.0)),
    ) {
        let tex = noise_texture(w, h, seed);
        let wrap = [wrap_of(wu), wrap_of(wv)];
        let poly: Vec<DVec2> = corners.iter().map(|&(x, y)| DVec2::new(x, y)).collect();
        let area = (poly[1] - poly[0]).perp_dot(poly[2] - poly[0]).abs() / 2.0;
        prop_assume!(area > 1e-3);
        let table = Table::new(&tex, |t| [srgb(t[0]), 0.0, 0.0, 1.0]).with_wrap(wrap);
        let got = table.integrate(&poly);
        let want = brute_force_red(&tex, wrap, &poly);
        prop_assert!(got.bound == 0.0, "small polygons stay exact");
        // f64 sums over at most 80² texels: 1e-9 relative is ~10⁴ ulps of margin.
        prop_assert!((got.sum[0] - want).abs() <= 1e-9 * area.max(1.0), "{} vs {want}", got.sum[0]);
        prop_assert!((got.sum[3] - area).abs() <= 1e-9 * area.max(1.0), "coverage {} vs {area}", got.sum[3]);
    }
}

/// Above a cap on boundary cells the integral is approximate, and within its stated bound.
#[test]
fn capped_polygons_stay_within_the_stated_bound() {
    let tex = noise_texture(13, 11, 7);
    let table = Table::new(&tex, |t| [srgb(t[0]), 0.0, 0.0, 1.0]);
    let poly = [
        DVec2::new(-300.3, -250.7),
        DVec2::new(410.9, -90.2),
        DVec2::new(-20.4, 380.6),
    ];
    let got = table.integrate_with(&poly, 512.0);
    let want = brute_force_red(&tex, [Wrap::Repeat; 2], &poly);
    assert!(got.bound > 0.0, "the cap was reached");
    let exact = table.integrate(&poly);
    assert!(
        exact.bound == 0.0 && (exact.sum[0] - want).abs() < 1e-9 * want,
        "the default cap is exact here"
    );
    let range = 1.0; // linear red lies in [0, 1]
    let err = (got.sum[0] - want).abs();
    assert!(
        err <= got.bound * range,
        "error {err} above the bound {}",
        got.bound
    );
    // The bound is a small share of the area (the boundary band of cells).
    assert!(
        got.bound < 0.05 * got.area,
        "bound {} of area {}",
        got.bound,
        got.area
    );
    eprintln!(
        "relative error {:.2e}, bound {:.2e}",
        err / want,
        got.bound / got.area
    );
}

/// Write `files` (name → bytes) and an OBJ quad into a fresh folder; returns the OBJ path.
fn obj_folder(dir: &Path, mtl: &str, files: &[(&str, Vec<u8>)]) -> PathBuf {
    for (name, bytes) in files {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    std::fs::write(dir.join("quad.mtl"), mtl).unwrap();
    // A 2 × 2 quad on the floor (y = 0), facing up, with texture coordinates over [0, 1]².
    let obj = "mtllib quad.mtl\no quad\nv 0 0 0\nv 0 0 2\nv 2 0 2\nv 2 0 0\n\
               vt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl m\nf 1/1 2/2 3/3 4/4\n";
    let path = dir.join("quad.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

fn png(w: u32, h: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(texels[(y * w + x) as usize]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// The 2 × 2 texture of the quad tests: distinct colours per quadrant, left column cut out.
const QUADRANTS: [[u8; 4]; 4] = [
    [200, 40, 40, 0],
    [40, 200, 40, 255],
    [40, 40, 200, 0],
    [230, 230, 30, 255],
];

#[test]
fn obj_textures_as_found_in_the_wild() {
    let tmp = tempfile::tempdir().unwrap();
    let mtl = "newmtl m\nKd 0.5 1.0 1.0\nmap_Kd -s 1 1 -bm 0.4 Tex\\Colour.PNG\nmap_d -imfchan m tex\\colour.png\n";
    let path = obj_folder(
        tmp.path(),
        mtl,
        &[("tex/colour.png", png(2, 2, &QUADRANTS))],
    );
    let (scene, warnings) = load_scene(&path, SceneOptions::default()).unwrap();
    assert_eq!(scene.textures.len(), 1, "one file, named twice");
    let m = &scene.materials[0];
    assert_eq!(m.albedo, [0.5, 1.0, 1.0], "Kd stays the factor");
    assert!(m.albedo_texture.is_some());
    let alpha = m.alpha.as_ref().unwrap();
    assert_eq!(alpha.texture.as_ref().unwrap().1, Channel::Alpha);
    assert_eq!(warnings.messages.len(), 1, "{warnings:?}");
    assert!(
        warnings.messages[0].contains("Colour.PNG") && warnings.messages[0].contains("colour.png"),
        "the case warning names both: {warnings:?}"
    );
    // OBJ v is flipped into glTF's frame: vt (0, 1) is the image's top-left corner.
    assert_eq!(scene.uvs[0], [0.0, 0.0]);
    assert_eq!(scene.uvs[1], [0.0, 1.0]);

    // Voxels of 1 × 1: four patches, one per texel quadrant; the left column is cut out.
    let params = VoxelizeParams {
        resolution: Resolution::VoxelSize(1.0),
        samples_per_patch: 4,
    };
    let set = voxelize(&scene, &params).unwrap();
    assert_eq!(set.patches.len(), 2, "the cut-out half makes no patch");
    for p in &set.patches {
        assert!((p.area - 1.0).abs() < 1e-6, "{}", p.area);
        // x ∈ [1, 2] is the image's right column (u ∈ [0.5, 1]); z ∈ [0, 1] its top row.
        let texel = if p.centroid[2] < 1.0 {
            QUADRANTS[1]
        } else {
            QUADRANTS[3]
        };
        let want = [0.5 * srgb(texel[0]), srgb(texel[1]), srgb(texel[2])];
        for c in 0..3 {
            assert!(
                (p.albedo[c] as f64 - want[c]).abs() < 1e-6,
                "patch at {:?}: albedo {:?}, want {want:?}",
                p.centroid,
                p.albedo
            );
        }
    }
}

#[test]
fn a_missing_texture_is_a_warning_and_a_corrupt_one_an_error() {
    let tmp = tempfile::tempdir().unwrap();
    let path = obj_folder(
        tmp.path(),
        "newmtl m\nKd 0.3 0.3 0.3\nmap_Kd gone.png\n",
        &[],
    );
    let (scene, warnings) = load_scene(&path, SceneOptions::default()).unwrap();
    assert!(scene.materials[0].albedo_texture.is_none());
    assert_eq!(scene.materials[0].albedo, [0.3; 3]);
    assert!(
        warnings.messages.iter().any(|w| w.contains("gone.png")),
        "{warnings:?}"
    );

    let tmp = tempfile::tempdir().unwrap();
    let path = obj_folder(
        tmp.path(),
        "newmtl m\nmap_Kd bad.png\n",
        &[("bad.png", b"\x89PNG\r\n\x1a\nnot really".to_vec())],
    );
    let err = load_scene(&path, SceneOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("bad.png") && err.contains("decode"), "{err}");

    let tmp = tempfile::tempdir().unwrap();
    let path = obj_folder(tmp.path(), "newmtl m\nmap_Kd -s\n", &[]);
    let err = load_scene(&path, SceneOptions::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("quad.obj") && err.contains("map_Kd"), "{err}");
}

fn sponza(path: &str) -> PathBuf {
    let p = data(&format!("../shared/data/scenes/{path}"));
    assert!(
        p.exists(),
        "{} is missing: the Sponza scenes live in ../shared/data/scenes",
        p.display()
    );
    p
}

/// Linear means measured with Pillow and numpy on the files (decoders differ by ±1 level per
/// JPEG sample, so 1e-3).
#[test]
fn dabrovic_sponza_loads_its_textures_whatever_their_case() {
    let (scene, warnings) =
        load_scene(&sponza("sponza/sponza.obj"), SceneOptions::default()).unwrap();
    assert_eq!(scene.textures.len(), 12, "12 distinct map_Kd files");
    let textured = scene
        .materials
        .iter()
        .filter(|m| m.albedo_texture.is_some())
        .count();
    assert_eq!(textured, 19, "19 materials have map_Kd");
    let case = warnings
        .messages
        .iter()
        .filter(|w| w.contains("differ in case"))
        .count();
    assert_eq!(
        case, 9,
        "the MTL names 9 of its 12 diffuse maps in another case: {warnings:?}"
    );
    let mean = |file: &str| {
        let t = scene
            .textures
            .iter()
            .find(|t| t.name.ends_with(file))
            .unwrap();
        t.mean_linear_rgb()
    };
    let kamen = mean("/KAMEN.JPG");
    for (c, want) in [0.628_846_7, 0.562_357_3, 0.500_446_1].iter().enumerate() {
        assert!((kamen[c] as f64 - want).abs() < 1e-3, "KAMEN.JPG {kamen:?}");
    }
    assert_eq!(scene.uvs.len(), scene.positions.len());
}

/// Opaque shares of the three masks measured with Pillow (L ≥ 128).
#[test]
fn crytek_sponza_reads_backslash_paths_and_masks() {
    let (scene, _) =
        load_scene(&sponza("crytek-sponza/sponza.obj"), SceneOptions::default()).unwrap();
    let masked: Vec<_> = scene
        .materials
        .iter()
        .filter(|m| m.alpha.is_some())
        .collect();
    assert_eq!(masked.len(), 3, "leaf, vase plants, chain");
    for (file, share) in [
        ("sponza_thorn_mask.png", 0.409_667_97),
        ("vase_plant_mask.png", 0.379_635_8),
        ("chain_texture_mask.png", 0.483_921_05),
    ] {
        let m = masked
            .iter()
            .find(|m| {
                let r = &m.alpha.as_ref().unwrap().texture.as_ref().unwrap().0;
                scene.textures[r.texture as usize].name.ends_with(file)
            })
            .unwrap_or_else(|| panic!("{file}"));
        let (r, ch) = m.alpha.as_ref().unwrap().texture.clone().unwrap();
        let t = &scene.textures[r.texture as usize];
        let opaque = t
            .texels
            .chunks_exact(4)
            .filter(|x| relume::scene::texture::channel_value([x[0], x[1], x[2], x[3]], ch) >= 0.5)
            .count() as f64
            / (t.width * t.height) as f64;
        assert!((opaque - share).abs() < 1e-6, "{file}: {opaque} vs {share}");
    }
    let textured = scene
        .materials
        .iter()
        .filter(|m| m.albedo_texture.is_some())
        .count();
    assert_eq!(textured, 24, "every material but Material__47 has map_Kd");
}

/// The boundary-cell cap against the exact integral on the Dabrovic Sponza's own pieces (every
/// 7th textured piece of a 1,000-patch voxelization): the error the default cap makes on a
/// piece's albedo, in linear units, next to the cap's time.
#[test]
fn the_boundary_cap_costs_little_albedo_on_the_dabrovic_sponza() {
    use relume::radiosity::geometry::Frame;
    use relume::radiosity::patches::albedo::{piece_surfaces_with, MAX_BOUNDARY_CELLS};
    let (scene, _) = load_scene(&sponza("sponza/sponza.obj"), SceneOptions::default()).unwrap();
    let params = VoxelizeParams {
        resolution: Resolution::TargetPatches(1000),
        samples_per_patch: 1,
    };
    let set = voxelize(&scene, &params).unwrap();
    let frame = Frame {
        origin: glam::DVec3::from(set.origin),
        scale: set.voxel_size,
    };
    let pieces: Vec<(u64, relume::radiosity::Piece)> = set
        .pieces
        .iter()
        .step_by(7)
        .map(|p| (0, p.clone()))
        .collect();
    let timed = |cap: f64| {
        let t = std::time::Instant::now();
        let s = piece_surfaces_with(&scene, &frame, &pieces, cap);
        (s, t.elapsed().as_secs_f64())
    };
    let (exact, t_exact) = timed(f64::INFINITY);
    let mut report = Vec::new();
    for cap in [512.0, 4096.0, MAX_BOUNDARY_CELLS] {
        let (got, t) = timed(cap);
        let mut worst = 0.0f64;
        for (a, b) in got.iter().zip(&exact) {
            if let (Some(a), Some(b)) = (a, b) {
                worst = worst.max((a.albedo - b.albedo).abs().max_element());
            }
        }
        report.push(format!(
            "cap {cap}: worst |Δ albedo| {worst:.2e}, {:.2}x the exact time",
            t / t_exact
        ));
        if cap == MAX_BOUNDARY_CELLS {
            // Measured: 0 (every piece's boundary is below the cap, so the integral is exact);
            // the 1e-9 margin is rounding of the f64 table sums.
            assert!(worst < 1e-9, "{report:?}");
        }
    }
    eprintln!(
        "{} pieces, exact {t_exact:.2} s\n{}",
        pieces.len(),
        report.join("\n")
    );
}

/// Per-patch albedo from the textures against each material's mean (what a loader that reduces a
/// texture to one colour would give), on the Dabrovic Sponza at 1,000 patches: the textures
/// change patches by a measurable amount, and every patch's albedo is a weighted mean of its
/// texels, so it lies within the range of its materials' texels.
#[test]
fn textured_patch_albedo_against_the_material_mean_on_the_dabrovic_sponza() {
    let (mean_rel, worst_rel) =
        albedo_against_material_mean("sponza/sponza.obj", 1.0, Resolution::TargetPatches(1000));
    // Measured 0.8 % mean, 211 % worst (docs/radiosity.md): most of the area averages out over
    // tiled textures, single patches do not.
    assert!(
        mean_rel > 0.002 && worst_rel > 0.5,
        "textures made no difference"
    );
}

/// Area-weighted mean and worst relative difference of patch luminance, textured against the
/// material means.
fn albedo_against_material_mean(file: &str, scale: f32, resolution: Resolution) -> (f64, f64) {
    let (scene, _) = load_scene(&sponza(file), SceneOptions { scale }).unwrap();
    let params = VoxelizeParams {
        resolution,
        samples_per_patch: 1,
    };
    let set = voxelize(&scene, &params).unwrap();
    let means = scene.mean_albedos();
    let (mut sum_rel, mut worst_rel, mut weight) = (0.0f64, 0.0f64, 0.0f64);
    for p in &set.patches {
        let pieces = set.patch_pieces(p);
        let mut mean = [0.0f64; 3];
        let mut area = 0.0;
        for piece in pieces {
            let m = scene.triangle_material[piece.triangle as usize] as usize;
            for c in 0..3 {
                mean[c] += piece.area * means[m][c] as f64;
            }
            area += piece.area;
        }
        let lum = |a: [f64; 3]| 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2];
        let by_mean = lum(mean.map(|c| c / area));
        let textured = lum(p.albedo.map(f64::from));
        assert!(textured > 0.0 && textured < 1.0, "{:?}", p.albedo);
        let rel = (textured - by_mean).abs() / by_mean;
        sum_rel += rel * p.area as f64;
        weight += p.area as f64;
        worst_rel = worst_rel.max(rel);
    }
    let mean_rel = sum_rel / weight;
    eprintln!(
        "{file}: {} patches: luminance of textured albedo vs material mean: area-weighted mean |Δ| {:.1} %, worst {:.1} %",
        set.patches.len(),
        100.0 * mean_rel,
        100.0 * worst_rel
    );
    (mean_rel, worst_rel)
}

/// glTF: `baseColorTexture` with `texCoord` 1, a sampler's wrap modes, `KHR_texture_transform`
/// (offset, rotation, scale; T·R·S as the extension defines it), `alphaMode` `MASK` with its
/// cutoff and `BLEND` read as a mask at 0.5, with the factor's alpha.
#[test]
fn gltf_texture_coordinates_samplers_transforms_and_alpha_modes() {
    let tmp = tempfile::tempdir().unwrap();
    // One triangle per material; TEXCOORD_0 is zero, TEXCOORD_1 carries the coordinates.
    let pos: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]];
    let uv1: [[f32; 2]; 3] = [[0.1, 0.2], [0.9, 0.2], [0.1, 0.7]];
    let mut bin = Vec::new();
    for p in pos
        .iter()
        .flatten()
        .chain(&[0.0f32; 6])
        .chain(uv1.iter().flatten())
    {
        bin.extend(p.to_le_bytes());
    }
    std::fs::write(tmp.path().join("t.bin"), &bin).unwrap();
    std::fs::write(
        tmp.path().join("t.png"),
        png(2, 1, &[[10, 20, 30, 40], [200, 100, 50, 250]]),
    )
    .unwrap();
    let (a, b) = (std::f32::consts::FRAC_PI_2, 0.5f32);
    let doc = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_texture_transform"],
        "buffers": [{"uri": "t.bin", "byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24},
            {"buffer": 0, "byteOffset": 60, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, -1], "max": [1, 0, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"}],
        "images": [{"uri": "t.png"}],
        "samplers": [{"wrapS": 33071, "wrapT": 33648}],
        "textures": [{"source": 0, "sampler": 0}],
        "materials": [
            {"name": "masked", "alphaMode": "MASK", "alphaCutoff": 0.3,
             "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 0.9],
               "baseColorTexture": {"index": 0, "texCoord": 0, "extensions": {"KHR_texture_transform":
                 {"offset": [0.25, 0.0], "rotation": a, "scale": [2.0, b], "texCoord": 1}}}}},
            {"name": "blend", "alphaMode": "BLEND",
             "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8]}}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "TEXCOORD_1": 2}, "material": 0},
            {"attributes": {"POSITION": 0}, "material": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let path = tmp.path().join("t.gltf");
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    let (scene, warnings) = load_scene(&path, SceneOptions::default()).unwrap();
    assert!(warnings.messages.is_empty(), "{warnings:?}");
    let masked = scene.materials.iter().find(|m| m.name == "masked").unwrap();
    let r = masked.albedo_texture.as_ref().unwrap();
    assert_eq!(r.wrap, [Wrap::ClampToEdge, Wrap::MirroredRepeat]);
    // T·R·S: rotation by a = π/2 (cos 0, sin 1), scale (2, 0.5), offset (0.25, 0).
    let want = [[0.0, 0.5, 0.25], [-2.0, 0.0, 0.0]];
    for (row, w) in r.transform.iter().zip(want) {
        for (x, y) in row.iter().zip(w) {
            assert!((x - y).abs() < 1e-6, "{:?}", r.transform);
        }
    }
    let alpha = masked.alpha.as_ref().unwrap();
    assert_eq!((alpha.factor, alpha.cutoff), (0.9, 0.3));
    assert_eq!(alpha.texture.as_ref().unwrap().1, Channel::Alpha);
    // The texture coordinates are TEXCOORD_1's, as the transform asks.
    assert_eq!(&scene.uvs[..3], &uv1);
    let blend = scene.materials.iter().find(|m| m.name == "blend").unwrap();
    let alpha = blend.alpha.as_ref().unwrap();
    assert_eq!(
        (alpha.factor, alpha.cutoff, alpha.texture.is_none()),
        (0.8, 0.5, true)
    );
    // The texture stays as stored: RGB sRGB-encoded, alpha linear.
    assert_eq!(
        scene.textures[0].texels,
        vec![10, 20, 30, 40, 200, 100, 50, 250]
    );
}
