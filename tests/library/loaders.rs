//! Every loader on good inputs, with exact expected counts and values.

use crate::common;

use common::data;
use relume::heightmap::{load_heightmap, HeightMapOptions, NoDataPolicy};
use relume::scene::{load_scene, LightKind, SceneOptions};
use std::path::Path;

#[test]
fn cornell_box_loads_exactly() {
    let (scene, warnings) = load_scene(
        &data("scenes/cornell-box/cornell_box.obj"),
        SceneOptions::default(),
    )
    .unwrap();
    assert!(warnings.messages.is_empty(), "{warnings:?}");
    assert_eq!(
        scene.triangles.len(),
        32,
        "16 quads triangulate to 32 triangles"
    );
    assert_eq!(scene.objects.len(), 16);
    assert_eq!(scene.materials.len(), 4);
    let m = |name: &str| {
        scene
            .materials
            .iter()
            .find(|m| m.name == name)
            .unwrap_or_else(|| panic!("material {name}"))
    };
    assert_eq!(m("white").albedo, [0.885809, 0.698859, 0.666422]);
    assert_eq!(m("red").albedo, [0.570068, 0.0430135, 0.0443706]);
    assert_eq!(m("green").albedo, [0.105421, 0.37798, 0.076425]);
    assert_eq!(m("light").emission, [18.387, 10.9873, 2.75357]);
    assert!(!m("white").is_emissive());
    // The light quad: two triangles of the "light" material, 130 mm x 105 mm, in the ceiling plane.
    let light = scene
        .materials
        .iter()
        .position(|x| x.name == "light")
        .unwrap() as u32;
    let light_tris: Vec<usize> = (0..32)
        .filter(|&t| scene.triangle_material[t] == light)
        .collect();
    assert_eq!(light_tris.len(), 2);
    let area: f32 = light_tris.iter().map(|&t| scene.triangle_area(t)).sum();
    assert!((area - 130.0 * 105.0).abs() < 1e-2, "light area {area}");
    for &t in &light_tris {
        for p in scene.corners(t) {
            assert_eq!(p.y, 548.8);
        }
    }
    let (lo, hi) = scene.bounds();
    assert_eq!(lo.to_array(), [0.0, 0.0, 0.0]);
    assert_eq!(hi.to_array(), [556.0, 548.8, 559.2]);
    assert!(!scene.is_grey());
    assert_eq!(scene.degenerate_triangles().count(), 0);
}

#[test]
fn scale_knob_scales_positions() {
    let (scene, _) = load_scene(
        &data("scenes/cornell-box/cornell_box.obj"),
        SceneOptions { scale: 0.001 },
    )
    .unwrap();
    let (_, hi) = scene.bounds();
    assert!((hi.x - 0.556).abs() < 1e-6 && (hi.y - 0.5488).abs() < 1e-6);
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn check_gltf_room(path: &Path) {
    let (scene, warnings) = load_scene(path, SceneOptions::default()).unwrap();
    assert!(warnings.messages.is_empty(), "{warnings:?}");
    assert_eq!(scene.triangles.len(), 2 + 12 + 2);
    assert_eq!(scene.objects, vec!["floor", "box", "lamp"]);
    // Texture: four sRGB texels (255,255,255) (0,0,0) (188,188,188) (128,64,32), factor 0.8.
    let texels = [
        [255.0, 255.0, 255.0],
        [0.0, 0.0, 0.0],
        [188.0, 188.0, 188.0],
        [128.0, 64.0, 32.0],
    ];
    let checker = scene
        .materials
        .iter()
        .find(|m| m.name == "checker")
        .unwrap();
    assert_eq!(checker.albedo, [0.8; 3], "baseColorFactor stays the factor");
    let texture = checker.albedo_texture.as_ref().expect("baseColorTexture");
    let image = &scene.textures[texture.texture as usize];
    assert_eq!((image.width, image.height), (2, 2));
    assert_eq!(scene.uvs.len(), scene.positions.len());
    let mean_albedo = scene.mean_albedo(checker);
    for c in 0..3 {
        let mean: f32 = texels
            .iter()
            .map(|t| srgb_to_linear(t[c] / 255.0))
            .sum::<f32>()
            / 4.0;
        assert!(
            (mean_albedo[c] - 0.8 * mean).abs() < 1e-6,
            "channel {c}: {mean_albedo:?}"
        );
    }
    let red = scene.materials.iter().find(|m| m.name == "red").unwrap();
    assert_eq!(red.albedo, [0.8, 0.1, 0.1]);
    let lamp = scene.materials.iter().find(|m| m.name == "lamp").unwrap();
    assert_eq!(
        lamp.emission,
        [5.0, 4.5, 4.0],
        "emissiveFactor x KHR_materials_emissive_strength"
    );
    // The box: group (translate (0,0.5,0), scale 2) ∘ box (translate (0.25,0,0), rotate 90° about y).
    let box_obj = scene.objects.iter().position(|o| o == "box").unwrap() as u32;
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for t in (0..scene.triangles.len()).filter(|&t| scene.triangle_object[t] == box_obj) {
        for p in scene.corners(t) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        // Rotation keeps the winding outward: the normal points away from the box centre.
        let [a, b, c] = scene.corners(t);
        let n = (b - a).cross(c - a);
        let centre = glam::Vec3::new(0.5, 0.5, 0.0);
        assert!(
            n.dot((a + b + c) / 3.0 - centre) > 0.0,
            "triangle {t} faces inward"
        );
    }
    assert!(
        (lo - glam::Vec3::new(0.3, 0.3, -0.2)).abs().max_element() < 1e-6,
        "{lo}"
    );
    assert!(
        (hi - glam::Vec3::new(0.7, 0.7, 0.2)).abs().max_element() < 1e-6,
        "{hi}"
    );
    // Lights: the sun points down; the bulb sits at group ∘ (0,0.5,0) = (0,1.5,0).
    assert_eq!(scene.lights.len(), 2);
    let sun = scene.lights.iter().find(|l| l.name == "sun").unwrap();
    assert_eq!(sun.kind, LightKind::Directional);
    assert!(
        (glam::Vec3::from(sun.direction) - glam::Vec3::NEG_Y).length() < 1e-6,
        "{:?}",
        sun.direction
    );
    assert_eq!(sun.intensity, 3.0);
    let bulb = scene.lights.iter().find(|l| l.name == "bulb").unwrap();
    assert_eq!(bulb.kind, LightKind::Point);
    assert!((glam::Vec3::from(bulb.position) - glam::Vec3::new(0.0, 1.5, 0.0)).length() < 1e-6);
    assert_eq!(bulb.color, [1.0, 0.5, 0.25]);
    assert_eq!(bulb.range, Some(10.0));
}

#[test]
fn gltf_with_external_buffer_loads_exactly() {
    check_gltf_room(&data("scenes/gltf-room/room.gltf"));
}

#[test]
fn glb_with_embedded_buffer_and_image_loads_exactly() {
    check_gltf_room(&data("scenes/gltf-room/room.glb"));
}

#[test]
fn puget_sound_jpeg_loads() {
    let opts = HeightMapOptions {
        cell_size: Some([40.0, 40.0]),
        height_scale: Some(10.0),
        ..Default::default()
    };
    let (map, info) = load_heightmap(&data("scenes/dem/puget_sound_4k.jpg"), &opts).unwrap();
    assert_eq!((map.width, map.height), (4096, 4096));
    assert_eq!(map.min_max(), (0.0, 1710.0));
    assert_eq!(info.format, "jpeg");
    assert_eq!(info.nodata_count, 0);
    assert_eq!(map.cell_size, [40.0, 40.0]);
}

#[test]
fn srtm_geotiff_loads_with_world_file() {
    let (map, info) = load_heightmap(
        &data("scenes/dem/srtm_bigtujunga_30m.tif"),
        &HeightMapOptions::default(),
    )
    .unwrap();
    assert_eq!((map.width, map.height), (1197, 643));
    assert_eq!(map.min_max(), (315.0, 2295.0));
    assert_eq!(map.cell_size, [30.0, 30.0]);
    assert_eq!(info.cell_size_source, "world-file");
    assert_eq!(info.sample, "i16");
}

#[test]
fn png16_exr_raw_and_tiff_round_trip_exact_values() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h) = (5usize, 3usize);
    let values: Vec<u16> = (0..(w * h) as u16).map(|i| i * 4000 + 7).collect();
    // 16-bit grayscale PNG
    let png = dir.path().join("h.png");
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w as u32, h as u32, values.clone())
        .unwrap()
        .save(&png)
        .unwrap();
    let opts = HeightMapOptions {
        height_scale: Some(0.5),
        ..Default::default()
    };
    let (map, info) = load_heightmap(&png, &opts).unwrap();
    assert_eq!(info.sample, "u16");
    assert_eq!(
        map.heights,
        values.iter().map(|&v| v as f32 * 0.5).collect::<Vec<_>>()
    );
    // single-channel EXR
    let exr = dir.path().join("h.exr");
    let f: Vec<f32> = values.iter().map(|&v| v as f32 - 20000.5).collect();
    relume::baked::exr_io::write_f32_channels(&exr, w, h, &[("Y", &f)]).unwrap();
    let (map, _) = load_heightmap(&exr, &HeightMapOptions::default()).unwrap();
    assert_eq!(map.heights, f);
    // raw little-endian f32
    let raw = dir.path().join("h.raw");
    std::fs::write(
        &raw,
        f.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>(),
    )
    .unwrap();
    let opts = HeightMapOptions {
        raw_size: Some([w, h]),
        ..Default::default()
    };
    let (map, _) = load_heightmap(&raw, &opts).unwrap();
    assert_eq!(map.heights, f);
    // GeoTIFF float32 and uint16 (written with the tiff crate's encoder)
    use tiff::encoder::{colortype, TiffEncoder};
    let tif = dir.path().join("f.tif");
    TiffEncoder::new(std::fs::File::create(&tif).unwrap())
        .unwrap()
        .write_image::<colortype::Gray32Float>(w as u32, h as u32, &f)
        .unwrap();
    let (map, info) = load_heightmap(&tif, &HeightMapOptions::default()).unwrap();
    assert_eq!(
        (
            map.heights.clone(),
            info.sample.as_str(),
            info.cell_size_source.as_str()
        ),
        (f.clone(), "f32", "default")
    );
    let tif16 = dir.path().join("u.tif");
    TiffEncoder::new(std::fs::File::create(&tif16).unwrap())
        .unwrap()
        .write_image::<colortype::Gray16>(w as u32, h as u32, &values)
        .unwrap();
    std::fs::write(tif16.with_extension("tfw"), "2.5\n0\n0\n-4.0\n100\n200\n").unwrap();
    let (map, info) = load_heightmap(&tif16, &HeightMapOptions::default()).unwrap();
    assert_eq!(
        map.heights,
        values.iter().map(|&v| v as f32).collect::<Vec<_>>()
    );
    assert_eq!(
        (map.cell_size, info.cell_size_source.as_str()),
        ([2.5, 4.0], "world-file")
    );
}

#[test]
fn nodata_policies() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("holes.f32");
    let v = [5.0f32, f32::NAN, 3.0, -9999.0, 8.0, 9.0];
    std::fs::write(
        &raw,
        v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>(),
    )
    .unwrap();
    let base = HeightMapOptions {
        raw_size: Some([3, 2]),
        nodata_value: Some(-9999.0),
        ..Default::default()
    };
    let err = load_heightmap(&raw, &base).unwrap_err().to_string();
    assert!(
        err.contains("holes.f32") && err.contains("2 no-data") && err.contains("column 1, row 0"),
        "{err}"
    );
    let (m, info) = load_heightmap(
        &raw,
        &HeightMapOptions {
            nodata: NoDataPolicy::FillMin,
            ..base.clone()
        },
    )
    .unwrap();
    assert_eq!(info.nodata_count, 2);
    assert_eq!(m.heights, vec![5.0, 3.0, 3.0, 3.0, 8.0, 9.0]);
    let (m, _) = load_heightmap(
        &raw,
        &HeightMapOptions {
            nodata: NoDataPolicy::FillNearest,
            ..base
        },
    )
    .unwrap();
    assert_eq!(m.heights, vec![5.0, 5.0, 3.0, 5.0, 8.0, 9.0]);
}

#[test]
fn gltf_cameras_become_viewpoints_in_world_space() {
    let tmp = tempfile::tempdir().unwrap();
    let path = crate::gltf_cameras::room_with_cameras(tmp.path());
    let (scene, warnings) = load_scene(&path, SceneOptions { scale: 10.0 }).unwrap();
    assert_eq!(scene.viewpoints.len(), 1, "{:?}", scene.viewpoints);
    let v = &scene.viewpoints[0];
    assert_eq!(v.name, "view");
    // World = group (translate (0, 0.5, 0), scale 2) · view (translate (0.5, 0.25, 1), turn
    // +90° about y): eye (1, 1, 2); −z turned +90° about y is −x. Then the scene scale ×10
    // moves the eye, not the unit direction.
    let close = |a: [f32; 3], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-4);
    assert!(close(v.eye, [10.0, 10.0, 20.0]), "{:?}", v.eye);
    assert!(close(v.target, [9.0, 10.0, 20.0]), "{:?}", v.target);
    assert!(close(v.up, [0.0, 1.0, 0.0]), "{:?}", v.up);
    assert!((v.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4);
    assert!(
        warnings
            .messages
            .iter()
            .any(|m| m.contains("`plan`") && m.contains("orthographic")),
        "{:?}",
        warnings.messages
    );
}
