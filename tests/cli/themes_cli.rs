//! `relume-bake theme` and the theme-set loaders, run as a user runs them: the bundled set,
//! GeoJSON against the same polygons inline, key images, and bad inputs (exit code 3, the
//! file named, nothing written).

use crate::common;

use common::{bake, data, expect_code};
use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

const THEMES: &str = r#"[
    Theme(name: "water", texture: Procedural(Water), border: Natural),
    Theme(name: "forest", texture: Procedural(Forest), border: Fractal(amplitude: 3.0, scale: 16.0)),
    Theme(name: "sand", texture: Procedural(Sand), border: Blend(width: 2.0)),
]"#;

#[test]
fn the_bundled_puget_sound_themes_compose_at_any_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("albedo.png");
    let o = bake(
        &data(""),
        &[
            "theme",
            "themes/puget-sound.ron",
            "--size",
            "300",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ],
    );
    expect_code(&o, 0);
    let img = image::open(&out).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (300, 300));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // Water covers the sound: heights ≤ 8 m are 5.8 % of the 4K file's texels at 0 m
    // (Pillow: 0.0581); the 512² box-filtered map keeps about as much.
    let water = j["coverage"]["0:water"].as_f64().unwrap();
    assert!((0.04..0.08).contains(&water), "water {water}");
    // The index map compresses at least 3x (4x less the exception blocks).
    let m = &j["memory"];
    assert!(m["index_ccc"].as_f64().unwrap() * 3.0 < m["index_raw"].as_f64().unwrap());
    assert!(m["total"].as_f64().unwrap() < m["global_rgb8_index_res"].as_f64().unwrap());
}

#[test]
fn geojson_polygons_rasterise_as_the_same_polygons_inline() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let square = "[[10, 10], [50, 12], [48, 52], [12, 50], [10, 10]]";
    let hole = "[[25, 25], [35, 25], [35, 35], [25, 35], [25, 25]]";
    write(
        d,
        "regions.geojson",
        &format!(
            r#"{{"type": "FeatureCollection", "features": [
                {{"type": "Feature", "properties": {{"theme": "forest"}},
                  "geometry": {{"type": "Polygon", "coordinates": [{square}, {hole}]}}}},
                {{"type": "Feature", "properties": {{"theme": "water", "border": {{"kind": "fractal", "amplitude": 2, "scale": 8}}}},
                  "geometry": {{"type": "MultiPolygon", "coordinates": [[[[40, 40], [60, 40], [60, 60], [40, 60]]]]}}}}
            ]}}"#
        ),
    );
    write(
        d,
        "a.ron",
        &format!(
            r#"Themes(themes: {THEMES}, map: Polygons(geojson: "regions.geojson", size: (64, 64), background: "sand"))"#
        ),
    );
    // RON writes a pair as a tuple.
    let tuples = |r: &str| {
        r.replace("[[", "[(")
            .replace("]]", ")]")
            .replace("], [", "), (")
    };
    let (sq, ho) = (tuples(square), tuples(hole));
    write(
        d,
        "b.ron",
        &format!(
            r#"Themes(themes: {THEMES}, map: Polygons(size: (64, 64), background: "sand", polygons: [
                Polygon(theme: "forest", rings: [{sq}, {ho}]),
                Polygon(theme: "water", border: Fractal(amplitude: 2.0, scale: 8.0), rings: [[(40, 40), (60, 40), (60, 60), (40, 60)]]),
            ]))"#
        ),
    );
    for f in ["a", "b"] {
        let o = bake(
            d,
            &[
                "theme",
                &format!("{f}.ron"),
                "--size",
                "128",
                "--out",
                &format!("{f}.png"),
                "-q",
            ],
        );
        expect_code(&o, 0);
    }
    let (a, b) = (
        image::open(d.join("a.png")).unwrap(),
        image::open(d.join("b.png")).unwrap(),
    );
    assert_eq!(a.as_bytes(), b.as_bytes());
    // The hole shows the background, the square forest: sample their centres.
    let rgb = a.to_rgb8();
    let (hole_px, forest_px) = (rgb.get_pixel(60, 60).0, rgb.get_pixel(36, 36).0);
    assert!(
        hole_px[0] > forest_px[0] + 40,
        "sand {hole_px:?} vs forest {forest_px:?}"
    );
}

#[test]
fn a_key_image_names_themes_by_colour() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut img = image::RgbImage::from_pixel(32, 16, image::Rgb([30, 90, 160]));
    for y in 0..16 {
        for x in 16..32 {
            img.put_pixel(x, y, image::Rgb([40, 40, 40]));
        }
    }
    img.save(d.join("keys.png")).unwrap();
    write(
        d,
        "t.ron",
        &format!(
            r##"Themes(themes: {THEMES}, map: Image(path: "keys.png", keys: {{"#1e5aa0": "water", "#282828": "sand"}}))"##
        ),
    );
    let o = bake(
        d,
        &["theme", "t.ron", "--size", "64", "--out", "t.png", "--json"],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["height"], 32);
    assert_eq!(j["coverage"]["0:water"], 0.5);
    assert_eq!(j["coverage"]["2:sand"], 0.5);
    // A pixel with no key: refused, the pixel and the key file named, nothing written.
    img.put_pixel(3, 4, image::Rgb([1, 2, 3]));
    img.save(d.join("keys.png")).unwrap();
    let o = bake(d, &["theme", "t.ron", "--size", "64", "--out", "u.png"]);
    let err = expect_code(&o, 3);
    assert!(
        err.contains("keys.png") && err.contains("(3, 4)") && err.contains("#010203"),
        "{err}"
    );
    assert!(!d.join("u.png").exists());
}

#[test]
fn bad_theme_sets_are_refused_with_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: &[(&str, String, &str)] = &[
        (
            "unknown theme",
            format!(r#"Themes(themes: {THEMES}, map: Polygons(size: (8, 8), background: "lava"))"#),
            "no theme named `lava`",
        ),
        (
            "no height map",
            format!(r#"Themes(themes: {THEMES}, map: Rules(rules: [], otherwise: "water"))"#),
            "names no `heightmap`",
        ),
        (
            "negative amplitude",
            r#"Themes(themes: [Theme(name: "a", texture: Procedural(Rock), border: Fractal(amplitude: -1.0, scale: 4.0))], map: Polygons(size: (8, 8), background: "a"))"#.into(),
            "amplitude must be ≥ 0",
        ),
        (
            "texture size",
            format!(r#"Themes(themes: {THEMES}, map: Polygons(size: (8, 8), background: "sand"), texture_size: 100)"#),
            "power of two",
        ),
        ("syntax", "Themes(themes: [".into(), "bad.ron:1:"),
    ];
    for (what, text, needle) in cases {
        write(d, "bad.ron", text);
        let o = bake(d, &["theme", "bad.ron", "--size", "16", "--out", "x.png"]);
        let err = expect_code(&o, 3);
        assert!(
            err.contains("bad.ron") && err.contains(needle),
            "{what}: {err}"
        );
        assert!(!d.join("x.png").exists(), "{what}: wrote output");
    }
}

#[test]
fn the_themes_stage_bakes_themes_bin_and_reruns_when_the_theme_file_changes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    expect_code(
        &bake(
            d,
            &[
                "generate", "cone", "--size", "32", "--out", "cone.exr", "-q",
            ],
        ),
        0,
    );
    let themes = |drift: &str| {
        format!(
            r#"Themes(themes: {THEMES}, map: Rules(rules: [Rule(theme: "sand", height: (min: 4.0))], otherwise: "forest"), drift: {drift})"#
        )
    };
    write(d, "t.ron", &themes("(0.01, 0.0)"));
    write(
        d,
        "p.ron",
        r#"Pipeline(input: HeightMap(path: "cone.exr"), output: "out", stages: [Themes(file: "t.ron")])"#,
    );
    expect_code(&bake(d, &["run", "p.ron", "-q"]), 0);
    let first = std::fs::read(d.join("out/themes.bin")).unwrap();
    let set = relume::baked::themes::read(&d.join("out")).unwrap();
    // The rule over the cone (height N/4 = 8 m at the centre): sand where the cone rises above 4 m.
    let hist = set.index.levels[0].histogram();
    assert!(hist[2] > 0 && hist[1] > hist[2], "{hist:?}");
    expect_code(&bake(d, &["inspect", "out"]), 0);
    // Unchanged: nothing to do. The theme file edited: the stage runs again.
    let o = bake(d, &["run", "p.ron"]);
    assert!(expect_code(&o, 0).contains("up to date"));
    write(d, "t.ron", &themes("(0.02, 0.0)"));
    expect_code(&bake(d, &["run", "p.ron", "-q"]), 0);
    let second = std::fs::read(d.join("out/themes.bin")).unwrap();
    assert_ne!(first, second, "the edited theme file was not baked again");
    // A missing theme set stops the bake before any work, naming the file; the bake stays.
    write(
        d,
        "q.ron",
        r#"Pipeline(input: HeightMap(path: "cone.exr"), output: "out", stages: [Themes(file: "gone.ron")])"#,
    );
    let err = expect_code(&bake(d, &["run", "q.ron"]), 4);
    assert!(err.contains("gone.ron"), "{err}");
    assert_eq!(std::fs::read(d.join("out/themes.bin")).unwrap(), second);
}
