//! `relume-bake horizon` and `sunlight` on the real binary: a flat map's hours of sun are the
//! day length (against pvlib's SPA sunrise and sunset); a wall's shadow costs the texels north
//! of it hours; the horizon-map hours agree with hours summed from exact masks; outputs are
//! GeoTIFFs read back with their values.

use crate::common;

use common::{bake, expect_code};
use relume::heightmap::HeightMap;
use relume::terrain::hard::relief::{shadow_mask, HardMethod};
use relume::terrain::horizon::map::{HorizonMap, HorizonSettings};
use relume::terrain::horizon::sunlight::{day_steps, sunlight};
use relume::terrain::sun::solar::{Instant, Place};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn write_exr(path: &Path, map: &HeightMap) {
    relume::baked::images::write_exr_gray(path, map.width, map.height, &map.heights).unwrap();
}

#[test]
fn a_flat_map_sees_the_whole_day() {
    let dir = tempfile::tempdir().unwrap();
    let flat = dir.path().join("flat.exr");
    write_exr(
        &flat,
        &HeightMap::new(24, 16, vec![0.0; 24 * 16], [30.0, 30.0]),
    );
    let (hours, wh) = (dir.path().join("hours.tif"), dir.path().join("wh.tif"));
    let o = bake(
        dir.path(),
        &[
            "sunlight",
            s(&flat),
            "--date",
            "2026-06-21",
            "--lat",
            "47.6",
            "--lon",
            "-122.3",
            "--step",
            "5m",
            "--directions",
            "16",
            "--out",
            s(&hours),
            "--insolation",
            s(&wh),
            "--json",
        ],
    );
    expect_code(&o, 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let daylight = v["daylight_hours"].as_f64().unwrap();
    // pvlib 0.16.1 `sun_rise_set_transit_spa` for Seattle, 2026-06-21: sunrise 04:11:28,
    // sunset 20:10:29 (UTC−8), 15.9836 h. Sampling at 5-minute midpoints: within one step.
    assert!((daylight - 15.9836).abs() <= 5.0 / 60.0, "{daylight}");
    let (read, _) = relume::heightmap::load_heightmap(&hours, &Default::default()).unwrap();
    assert!(read
        .heights
        .iter()
        .all(|&h| (h as f64 - daylight).abs() < 1e-4));
    // Flat ground at 47.6° N on the solstice: noon sun 65.8° up, DNI 920 W/m²; a whole clear
    // day of direct beam on the ground is several kWh/m² (about 7.4 from this model).
    let (e, _) = relume::heightmap::load_heightmap(&wh, &Default::default()).unwrap();
    assert!(
        e.heights.iter().all(|&x| (5000.0..9000.0).contains(&x)),
        "{}",
        e.heights[0]
    );
    // Bad knobs: a step without a unit we know, a date that is not one.
    let o = bake(
        dir.path(),
        &[
            "sunlight",
            s(&flat),
            "--date",
            "2026-06-21",
            "--lat",
            "1",
            "--lon",
            "1",
            "--step",
            "10x",
            "--out",
            s(&hours),
        ],
    );
    assert!(expect_code(&o, relume::error::exit::INPUT).contains("unknown unit"));
    let o = bake(
        dir.path(),
        &[
            "sunlight",
            s(&flat),
            "--date",
            "2026-13-21",
            "--lat",
            "1",
            "--lon",
            "1",
            "--out",
            s(&hours),
        ],
    );
    assert!(expect_code(&o, relume::error::exit::INPUT).contains("month 13"));
}

#[test]
fn horizon_hours_agree_with_exact_masks_and_a_wall_casts_its_shadow() {
    // An east–west wall 40 m high across a flat 32×32 map of 10 m cells, at row 20: at 47.6° N
    // in December the noon sun is 19° up, so the wall's shadow reaches 116 m (11 rows) north.
    let (w, h) = (32usize, 32usize);
    let mut hs = vec![0.0f32; w * h];
    for c in 0..w {
        hs[20 * w + c] = 40.0;
    }
    let map = HeightMap::new(w, h, hs, [10.0, 10.0]);
    let date = Instant::parse("2026-12-21T00:00:00Z").unwrap();
    let place = Place::new(47.6, -122.3, 0.0).unwrap();
    let steps = day_steps(&date, &place, 600.0, 0.0).unwrap();
    let hm = HorizonMap::build(&map, &HorizonSettings::flat(64));
    let (hours, _) = sunlight(&map, &hm, &steps, false);
    let daylight: f64 = steps
        .iter()
        .filter(|s| s.sun.elevation_deg > 0.0)
        .map(|s| s.hours)
        .sum();
    let at = |c: usize, r: usize| hours[r * w + c] as f64;
    assert!(
        (at(16, 28) - daylight).abs() < 1e-5,
        "south of the wall: the whole day (f32 hours), {} vs {daylight}",
        at(16, 28)
    );
    assert!(
        at(16, 18) < 0.5 * daylight,
        "just north of the wall: mostly in shadow"
    );
    // The same day from exact masks (the certified sweep) at every step.
    let mut exact = vec![0.0f64; w * h];
    for st in steps.iter().filter(|s| s.sun.elevation_deg > 0.0) {
        let m = shadow_mask(
            &map,
            &st.sun,
            HardMethod::Sweep,
            None,
            &relume::progress::Silent,
        );
        for (e, sh) in exact.iter_mut().zip(m) {
            *e += if sh { 0.0 } else { st.hours };
        }
    }
    let off = exact
        .iter()
        .zip(&hours)
        .filter(|(e, h)| (**e - **h as f64).abs() > 2.0 / 6.0)
        .count();
    let worst = exact
        .iter()
        .zip(&hours)
        .map(|(e, h)| (e - *h as f64).abs())
        .fold(0.0, f64::max);
    let mean = exact
        .iter()
        .zip(&hours)
        .map(|(e, h)| (e - *h as f64).abs())
        .sum::<f64>()
        / (w * h) as f64;
    let signed = exact
        .iter()
        .zip(&hours)
        .map(|(e, h)| e - *h as f64)
        .sum::<f64>()
        / (w * h) as f64;
    println!(
        "off {off} of {}, worst {worst} h, mean {mean} h signed {signed}",
        w * h
    );
    // Interpolating the horizon between azimuths moves a shadow's edge, most where a track
    // toward one stored azimuth meets the wall and toward the next leaves the map first
    // (measured: 121 of 1,024 texels more than 20 min off, worst 1.33 h, mean |error| 0.128 h, signed mean +0.020 h: no bias).
    assert!(
        off * 100 <= 15 * w * h,
        "{off} texels more than 20 min off (worst {worst} h)"
    );
    assert!(mean < 0.2, "mean {mean} h");
}

#[test]
fn horizon_writes_the_sky_view_factor() {
    let dir = tempfile::tempdir().unwrap();
    let srtm = common::data("scenes/dem/srtm_bigtujunga_30m.tif");
    let svf = dir.path().join("svf.tif");
    let hdir = dir.path().join("h");
    let o = bake(
        dir.path(),
        &[
            "horizon",
            s(&srtm),
            "--directions",
            "8",
            "--sky-view",
            s(&svf),
            "--out",
            s(&hdir),
            "--json",
        ],
    );
    expect_code(&o, 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["directions"].as_array().unwrap().len(), 8);
    let (m, info) = relume::heightmap::load_heightmap(&svf, &Default::default()).unwrap();
    assert_eq!((m.width, m.height), (1197, 643));
    assert!(info.georef.is_some());
    // In a mountain catchment the sky is partly hidden everywhere but never wholly.
    assert!(m.heights.iter().all(|&x| x > 0.0 && x <= 1.0));
    let mean = m.heights.iter().map(|&x| x as f64).sum::<f64>() / m.heights.len() as f64;
    assert!((0.6..0.99).contains(&mean), "{mean}");
    assert_eq!(std::fs::read_dir(&hdir).unwrap().count(), 8);
    let o = bake(dir.path(), &["horizon", s(&srtm)]);
    assert!(expect_code(&o, relume::error::exit::INPUT).contains("nothing to write"));
}
