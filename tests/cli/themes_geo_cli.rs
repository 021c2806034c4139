//! Georeferenced theme polygons as a user runs them: `LonLat` polygons baked by a pipeline's
//! `Themes` stage over the SRTM GeoTIFF equal the same theme set over the height map it names
//! (and a stage run alone on the bake reads the georeference back from the manifest); a vertex
//! outside the map is clipped; and what must be refused is refused with exit code 3, naming the
//! file and the problem, before anything is written.

use crate::common;

use common::{bake, data, expect_code};
use relume::heightmap::georef::{write_geotiff_f32, GeoReference};
use relume::theme::index_map::IndexMap;
use std::path::Path;

const THEMES: &str = r#"[
    Theme(name: "water", texture: Procedural(Water), border: Natural),
    Theme(name: "forest", texture: Procedural(Forest), border: Natural),
    Theme(name: "sand", texture: Procedural(Sand), border: Natural),
]"#;

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn srtm() -> String {
    data("scenes/dem/srtm_bigtujunga_30m.tif")
        .display()
        .to_string()
}

/// Inline polygons in longitude/latitude over the Big Tujunga DEM (34.32° N, 118.15° W,
/// 36 × 19 km): a quadrilateral inside, one reaching past the west edge (clipped), one 17° east
/// of the zone's central meridian and one on the far side of the Earth (both wholly outside).
const LONLAT_POLYGONS: &str = r#"[
    Polygon(theme: "forest", rings: [[(-118.25, 34.28), (-118.05, 34.30), (-118.10, 34.36), (-118.22, 34.35)]]),
    Polygon(theme: "water", rings: [[(-118.6, 34.25), (-118.28, 34.27), (-118.3, 34.33)]]),
    Polygon(theme: "water", rings: [[(-100.0, 40.0), (-99.0, 40.0), (-99.5, 41.0)]]),
    Polygon(theme: "water", rings: [[(60.0, -30.0), (61.0, -30.0), (60.5, -29.0)]]),
]"#;

fn theme_set(coordinates: &str, polygons: &str, heightmap: Option<&str>) -> String {
    let hm = heightmap.map_or(String::new(), |h| format!(", heightmap: \"{h}\""));
    format!(
        r#"Themes(themes: {THEMES}, map: Polygons(polygons: {polygons}, size: (300, 160), background: "sand", coordinates: {coordinates}{hm}))"#
    )
}

fn index_of(path: &Path) -> IndexMap {
    let set = relume::load::themes::load_themes(path, None).unwrap_or_else(|e| panic!("{e}"));
    set.index.levels[0].clone()
}

#[test]
fn lon_lat_polygons_bake_in_a_pipeline_as_over_the_height_map_the_file_names() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write(d, "t.ron", &theme_set("LonLat", LONLAT_POLYGONS, None));
    write(
        d,
        "u.ron",
        &theme_set("LonLat", LONLAT_POLYGONS, Some(&srtm())),
    );
    let pipeline = format!(
        r#"Pipeline(input: HeightMap(path: "{}"), output: "out", stages: [Themes(file: "t.ron")])"#,
        srtm()
    );
    write(d, "p.ron", &pipeline);
    expect_code(&bake(d, &["run", "p.ron", "-q"]), 0);
    let baked = relume::baked::themes::read(&d.join("out")).unwrap();
    let want = index_of(&d.join("u.ron"));
    assert_eq!(baked.index.levels[0], want);
    // The forest quadrilateral covers about its area: 0.2° × 0.07° ≈ 18.4 × 7.8 km less the
    // corners' slant, of 35.9 × 19.3 km; the clipped west polygon some texels, the far ones none.
    let hist = want.histogram();
    let forest = hist[1] as f64 / (300.0 * 160.0);
    assert!((0.12..0.22).contains(&forest), "forest covers {forest}");
    assert!(
        hist[0] > 100,
        "the clipped polygon covers {} texels",
        hist[0]
    );
    let near: Vec<&str> = LONLAT_POLYGONS.lines().take(3).collect();
    let near = format!("{}\n]", near.join("\n"));
    write(d, "v.ron", &theme_set("LonLat", &near, Some(&srtm())));
    assert_eq!(
        index_of(&d.join("v.ron")),
        want,
        "a far polygon covers texels"
    );
    // The georeference is in the manifest, and a stage run alone on the bake reads it there.
    let manifest = std::fs::read_to_string(d.join("out/manifest.ron")).unwrap();
    assert!(manifest.contains("georeference"), "{manifest}");
    let stage = relume::pipeline::Stage::Themes(relume::pipeline::knobs::ThemesKnobs {
        file: d.join("t.ron"),
    });
    let progress = relume::progress::Silent;
    relume::bake::run_stage_on(&d.join("out"), stage, &progress).unwrap();
    let again = relume::baked::themes::read(&d.join("out")).unwrap();
    assert_eq!(again.index.levels[0], want);
    // `relume-bake theme --heightmap` places them the same way.
    let o = bake(
        d,
        &[
            "theme",
            "t.ron",
            "--heightmap",
            &srtm(),
            "--size",
            "300",
            "--out",
            "a.png",
            "--json",
        ],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let texels = j["coverage"]["1:forest"].as_f64().unwrap() * (300.0 * 160.0);
    assert_eq!(texels.round() as usize, hist[1]);
}

/// A GeoTIFF of 64 × 32 texels of 100 US survey feet in NAD83 / California zone 5 (EPSG:2229),
/// a CRS relume does not convert longitude/latitude into.
fn write_state_plane(path: &Path) {
    let g = GeoReference {
        tiepoints: vec![0.0, 0.0, 0.0, 6_500_000.0, 1_900_000.0, 0.0],
        pixel_scale: vec![100.0, 100.0, 0.0],
        geo_keys: vec![1, 1, 0, 2, 1024, 0, 1, 1, 3072, 0, 1, 2229],
        ..Default::default()
    };
    write_geotiff_f32(path, 64, 32, &vec![100.0; 64 * 32], Some(&g), None).unwrap();
}

/// `relume-bake theme` of `theme` (written as t.ron) must exit 3 naming `names` and writing
/// nothing.
fn refused(d: &Path, what: &str, theme: &str, extra: &[&str], names: &[&str]) {
    write(d, "t.ron", theme);
    let mut args = vec!["theme", "t.ron", "--size", "32", "--out", "x.png"];
    args.extend(extra);
    let err = expect_code(&bake(d, &args), 3);
    for n in names {
        assert!(err.contains(n), "{what}: `{n}` not in: {err}");
    }
    eprintln!("{what}:\n{err}");
    assert!(!d.join("x.png").exists(), "{what}: wrote output");
}

#[test]
fn georeferenced_polygons_without_a_usable_georeference_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    image::RgbImage::from_pixel(16, 16, image::Rgb([9, 9, 9]))
        .save(d.join("dem.jpg"))
        .unwrap();
    write_state_plane(&d.join("spcs.tif"));
    let square =
        "[Polygon(theme: \"water\", rings: [[(-118.2, 34.3), (-118.1, 34.3), (-118.1, 34.35)]])]";
    let no_georef = "has no georeference";
    refused(
        d,
        "JPEG named in the theme file",
        &theme_set("LonLat", square, Some("dem.jpg")),
        &[],
        &[
            "t.ron",
            "dem.jpg",
            "cannot place polygons in `LonLat` coordinates",
            no_georef,
        ],
    );
    refused(
        d,
        "JPEG given as --heightmap",
        &theme_set("Map", square, None),
        &["--heightmap", "dem.jpg"],
        &["t.ron", "dem.jpg", no_georef],
    );
    refused(
        d,
        "no height map at all",
        &theme_set("LonLat", square, None),
        &[],
        &["t.ron", "need a georeferenced height map: name one"],
    );
    refused(
        d,
        "a CRS relume cannot convert longitude/latitude into",
        &theme_set("LonLat", square, Some("spcs.tif")),
        &[],
        &["t.ron", "spcs.tif", "EPSG:2229", "`Map` coordinates"],
    );
    refused(
        d,
        "a height map texel polygons do not read",
        &theme_set("Texels", square, Some("spcs.tif")),
        &[],
        &["t.ron", "read no `heightmap`"],
    );
    // `Map` coordinates need only the affine georeference, whatever the CRS: the state-plane
    // feet of texels 16..48 × 8..24.
    let feet = "[Polygon(theme: \"water\", rings: [[(6501600, 1899200), (6504800, 1899200), (6504800, 1897600), (6501600, 1897600)]])]";
    write(d, "m.ron", &theme_set("Map", feet, Some("spcs.tif")));
    let o = bake(
        d,
        &["theme", "m.ron", "--size", "64", "--out", "m.png", "--json"],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // Index texels 75..225 × 40..120 of 300 × 160: a quarter of the map.
    assert_eq!(j["coverage"]["0:water"].as_f64(), Some(0.25));
    // A pipeline over the JPEG stops before any work, naming the theme file.
    write(d, "t.ron", &theme_set("LonLat", square, None));
    write(
        d,
        "p.ron",
        r#"Pipeline(input: HeightMap(path: "dem.jpg"), output: "out", stages: [Themes(file: "t.ron")])"#,
    );
    let err = expect_code(&bake(d, &["run", "p.ron"]), 3);
    for n in ["t.ron", "the pipeline's height map", "dem.jpg", no_georef] {
        assert!(err.contains(n), "pipeline: `{n}` not in: {err}");
    }
    assert!(!d.join("out").exists(), "the refused pipeline wrote a bake");
}

#[test]
fn bad_positions_are_refused_naming_the_file_and_the_feature() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let feature = |coords: &str| {
        format!(
            r#"{{"type": "Feature", "properties": {{"theme": "water"}}, "geometry": {{"type": "Polygon", "coordinates": [{coords}]}}}}"#
        )
    };
    let good = feature("[[-118.2, 34.3], [-118.1, 34.3], [-118.1, 34.35]]");
    let theme = format!(
        r#"Themes(themes: {THEMES}, map: Polygons(geojson: "p.geojson", size: (32, 32), background: "sand", coordinates: LonLat, heightmap: "{}"))"#,
        srtm()
    );
    let cases = [
        (
            "NaN",
            feature("[[NaN, 34.3], [-118.1, 34.3], [-118.1, 34.35]]"),
            "not JSON",
        ),
        (
            "overflow",
            feature("[[1e999, 34.3], [-118.1, 34.3], [-118.1, 34.35]]"),
            "not JSON",
        ),
        (
            "a string",
            feature(r#"[["-118.2", 34.3], [-118.1, 34.3], [-118.1, 34.35]]"#),
            "feature 1: a position is not two finite numbers",
        ),
        (
            "UTM metres as LonLat",
            feature("[[394268.6, 3798272.8], [394300, 3798272.8], [394300, 3798300]]"),
            "feature 1: position [394268.6, 3798272.8] is not [longitude, latitude]",
        ),
    ];
    for (what, bad, needle) in cases {
        let text = format!(r#"{{"type": "FeatureCollection", "features": [{good}, {bad}]}}"#);
        write(d, "p.geojson", &text);
        refused(d, what, &theme, &[], &["p.geojson", needle]);
    }
    // An inline polygon names the theme file and the polygon.
    let inline =
        "[Polygon(theme: \"water\", rings: [[(-118.2, 34.3), (-118.1, 95.0), (-118.1, 34.35)]])]";
    refused(
        d,
        "latitude 95",
        &theme_set("LonLat", inline, Some(&srtm())),
        &[],
        &[
            "t.ron",
            "polygon 0 of `polygons`",
            "latitude must be within ±90°",
        ],
    );
}

#[test]
fn the_bundled_lon_lat_example_places_every_region() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bt.png");
    let o = bake(
        &data(""),
        &[
            "theme",
            "themes/bigtujunga.ron",
            "--size",
            "300",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["index_map"], serde_json::json!([600, 322]));
    let coverage = j["coverage"].as_object().unwrap();
    for theme in ["chaparral", "wash", "burn", "water"] {
        let share: f64 = coverage
            .iter()
            .filter(|(k, _)| k.ends_with(&format!(":{theme}")))
            .map(|(_, v)| v.as_f64().unwrap())
            .sum();
        assert!(share > 0.001, "{theme} covers {share}: {coverage:?}");
    }
}
