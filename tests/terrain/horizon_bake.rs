//! The `horizon_maps` stage end to end: the bundled `puget-sound-512` pipeline bakes horizon
//! maps that numpy reads with the documented layout and that equal the library's sweep; the
//! player renders them headless (`terrain_shadows: horizon_maps` in frames.json) and, at a
//! stored azimuth, shows the same frame as the traversal.

use crate::common;

use common::{bake, data, expect_code, gpu, python, require_python};
use relume::heightmap::HeightMap;
use relume::terrain::horizon::map::{decode, HorizonMap, HorizonSettings};
use std::path::Path;
use std::process::Command;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn bake_512(dir: &Path) -> std::path::PathBuf {
    let out = dir.join("ps512");
    let o = bake(
        dir,
        &[
            "-q",
            "run",
            s(&data("pipelines/puget-sound-512.ron")),
            "--out",
            s(&out),
        ],
    );
    expect_code(&o, 0);
    out
}

fn baked_map(dir: &Path) -> HeightMap {
    let m = relume::baked::Manifest::read(dir).unwrap();
    relume::baked::heightmap::read(dir, &m).unwrap()
}

#[test]
fn the_stage_writes_what_numpy_reads_and_the_sweep_computes() {
    let tmp = tempfile::tempdir().unwrap();
    let out = bake_512(tmp.path());
    let map = baked_map(&out);
    let want = HorizonMap::build(&map, &HorizonSettings::flat(64));
    let m = relume::baked::Manifest::read(&out).unwrap();
    let got =
        relume::baked::horizon::read(&out, &m, (map.width, map.height), map.cell_size).unwrap();
    assert_eq!(got, want, "the baked horizon map is the library's");
    let rec = m.stage("horizon_maps").unwrap();
    assert_eq!(rec.report["directions"], 64.0);
    assert_eq!(rec.report["planet_radius_m"], 0.0);
    if !require_python(&["numpy"]) {
        return;
    }
    // numpy, independently: dtype, shape, the steps and a few decoded angles.
    let py = python(
        "import sys, numpy as np
h = np.load(sys.argv[1] + '/horizon_maps.npy')
d = np.load(sys.argv[1] + '/horizon_directions.npy')
print(h.dtype, h.shape, d.dtype, d.shape)
print(d[16][0], d[16][1], d[0][0], d[0][1])
ang = -90.0 + h.astype(np.float64) * (180.0 / 65535.0)
print(repr(float(ang[16, 300, 200])), repr(float(ang[40, 10, 500])), repr(float(ang.max())))",
        &[s(&out)],
    );
    let lines: Vec<&str> = py.lines().collect();
    assert_eq!(lines[0], "uint16 (64, 512, 512) int32 (64, 2)", "{py}");
    // Direction 16 of 64 is due east (one column per step), 0 due north (one row up).
    assert_eq!(lines[1], "1 0 0 -1", "{py}");
    let v: Vec<f64> = lines[2].split(' ').map(|x| x.parse().unwrap()).collect();
    let w = map.width;
    let max = want
        .angles
        .iter()
        .flatten()
        .map(|&q| decode(q))
        .fold(-90.0, f64::max);
    for (a, b) in v.iter().zip([
        decode(want.angles[16][300 * w + 200]),
        decode(want.angles[40][10 * w + 500]),
        max,
    ]) {
        assert!((a - b).abs() < 1e-12, "numpy {a} vs relume {b}");
    }
}

fn player(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_relume-player"))
        .args(args)
        .output()
        .expect("relume-player runs")
}

#[test]
fn the_player_shadows_from_horizon_maps_and_matches_the_traversal_at_a_stored_azimuth() {
    if gpu().is_none() {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    let out = bake_512(tmp.path());
    let frames = |name: &str, extra: &[&str]| {
        let dir = tmp.path().join(name);
        let mut args = vec![
            s(&out),
            "--headless",
            "-q",
            "--size",
            "160x120",
            "--sun",
            "90,6",
            "--exposure",
            "1",
            "--out",
            s(&dir),
        ];
        args.extend_from_slice(extra);
        let o = player(&args);
        expect_code(&o, 0);
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("frames.json")).unwrap())
                .unwrap();
        let img = image::open(dir.join("frame_0000.png")).unwrap().to_rgba8();
        (report["terrain_shadows"].as_str().unwrap().to_string(), img)
    };
    let (how_h, img_h) = frames("horizon", &[]);
    let (how_t, img_t) = frames("traversal", &["--no-horizon"]);
    assert_eq!(
        (how_h.as_str(), how_t.as_str()),
        ("horizon_maps", "traversal")
    );
    // Due east is a stored direction: the horizon test there is the exact traversal's up to the
    // u16 step (0.0014°), against the GPU traversal's f32 (docs/terrain.md). Measured on
    // lavapipe: 0 pixels; 0.1 % allowed for another driver's f32 rounding.
    let differing = img_h
        .pixels()
        .zip(img_t.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0.iter()).any(|(x, y)| x.abs_diff(*y) > 1))
        .count();
    eprintln!("horizon vs traversal frame at 90°/6°: {differing} of 19200 pixels differ");
    assert!(differing <= 19, "{differing} pixels differ");
    // And shadows are there at all: a frame without them differs.
    let (_, img_none) = frames("none", &["--no-shadows"]);
    let shadowed = img_h
        .pixels()
        .zip(img_none.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(shadowed > 500, "only {shadowed} pixels show shadows");
}
