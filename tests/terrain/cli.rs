//! The terrain commands of the real `relume-bake` binary: `generate`, `shadow`, and the
//! `minmax_mipmap` stage in a pipeline (with OpenEXR's Python bindings as an independent reader
//! of the mipmap file), bad inputs and atomic output.

use crate::common;

use common::{bake, data, expect_code, list_files, python, require_python};
use relume::error::exit;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn generate_writes_every_shape_as_exr_and_16_bit_png() {
    let dir = tempfile::tempdir().unwrap();
    for shape in [
        "spikes",
        "steps",
        "flat",
        "wall",
        "cone",
        "hemisphere",
        "crater",
    ] {
        let exr = dir.path().join(format!("{shape}.exr"));
        expect_code(
            &bake(
                dir.path(),
                &["generate", shape, "--size", "64", "--out", s(&exr), "-q"],
            ),
            0,
        );
        let (map, _) = relume::heightmap::load_heightmap(&exr, &Default::default()).unwrap();
        assert_eq!((map.width, map.height), (64, 64));
        assert_eq!(
            map,
            relume::terrain::generate::generate(
                relume::terrain::generate::Shape::ALL
                    .iter()
                    .copied()
                    .find(|s| s.name() == shape)
                    .unwrap(),
                64
            )
        );
        let png = dir.path().join(format!("{shape}.png"));
        let o = bake(
            dir.path(),
            &[
                "generate",
                shape,
                "--size",
                "64",
                "--out",
                s(&png),
                "--json",
            ],
        );
        expect_code(&o, 0);
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let img = image::open(&png).unwrap();
        assert_eq!(img.color(), image::ColorType::L16, "{shape}");
        // Loading with the reported height scale restores the relief up to 16-bit rounding.
        let scale = j["height_scale"].as_f64().unwrap();
        let opts = relume::heightmap::HeightMapOptions {
            height_scale: Some(scale),
            ..Default::default()
        };
        let (back, _) = relume::heightmap::load_heightmap(&png, &opts).unwrap();
        let offset = j["height_offset"].as_f64().unwrap();
        for (a, b) in back.heights.iter().zip(&map.heights) {
            assert!(
                (*a as f64 + offset - *b as f64).abs() <= scale,
                "{shape}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn shadow_writes_mask_and_relief_and_both_methods_agree() {
    let dir = tempfile::tempdir().unwrap();
    let spikes = dir.path().join("spikes.exr");
    expect_code(
        &bake(
            dir.path(),
            &[
                "generate",
                "spikes",
                "--size",
                "200",
                "--out",
                s(&spikes),
                "-q",
            ],
        ),
        0,
    );
    let mut masks = Vec::new();
    for method in ["exact", "accelerated"] {
        let mask = dir.path().join(format!("{method}.png"));
        let relief = dir.path().join(format!("{method}-relief.png"));
        let o = bake(
            dir.path(),
            &[
                "shadow",
                s(&spikes),
                "--sun-azimuth",
                "300",
                "--sun-elevation",
                "12",
                "--method",
                method,
                "--out",
                s(&mask),
                "--shaded",
                s(&relief),
                "--json",
            ],
        );
        expect_code(&o, 0);
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let f = j["shadowed_fraction"].as_f64().unwrap();
        assert!(f > 0.01 && f < 0.5, "{f}");
        let m = image::open(&mask).unwrap().to_luma8();
        assert_eq!(m.dimensions(), (200, 200));
        assert!(m.pixels().all(|p| p.0[0] == 0 || p.0[0] == 255));
        let r = image::open(&relief).unwrap().to_luma8();
        // Shadowed pixels are darker than lit flat ground.
        let lit_flat = r.get_pixel(100, 5).0[0];
        let (x, y) = m
            .enumerate_pixels()
            .find(|(_, _, p)| p.0[0] == 0)
            .map(|(x, y, _)| (x, y))
            .unwrap();
        assert!(r.get_pixel(x, y).0[0] < lit_flat);
        masks.push(std::fs::read(&mask).unwrap());
    }
    assert_eq!(masks[0], masks[1], "exact and accelerated masks differ");
    assert_eq!(
        list_files(dir.path()).len(),
        5,
        "no temporary files left: {:?}",
        list_files(dir.path())
    );
}

#[test]
fn shadow_reads_a_pipeline_and_honours_overrides() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("m.png");
    let o = bake(
        dir.path(),
        &[
            "shadow",
            s(&data("pipelines/bigtujunga.ron")),
            "--sun-azimuth",
            "135",
            "--sun-elevation",
            "20",
            "--cell-size",
            "60",
            "--out",
            s(&out),
            "--json",
        ],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(1197), Some(643))
    );
    assert_eq!(j["cell_size"][0].as_f64(), Some(60.0));
}

#[test]
fn shadow_refuses_bad_inputs_without_writing_anything() {
    let dir = tempfile::tempdir().unwrap();
    let flat = dir.path().join("flat.exr");
    expect_code(
        &bake(
            dir.path(),
            &["generate", "flat", "--size", "8", "--out", s(&flat), "-q"],
        ),
        0,
    );
    let out = dir.path().join("out").join("m.png");
    let cases: &[(&[&str], i32, &str)] = &[
        (&["--sun-elevation", "95"], exit::INPUT, "elevation"),
        (
            &["--sun-elevation", "10", "--k-dark", "2"],
            exit::INPUT,
            "k-dark",
        ),
        (
            &["--sun-elevation", "10", "--cell-size", "0"],
            exit::INPUT,
            "cell size",
        ),
        (
            &["--sun-elevation", "-10", "--sun-azimuth", "x"],
            exit::USAGE,
            "azimuth",
        ),
    ];
    for (extra, code, mention) in cases {
        let mut args = vec!["shadow", s(&flat), "--out", "m.png"];
        if !extra.contains(&"--sun-azimuth") {
            args.extend_from_slice(&["--sun-azimuth", "0"]);
        }
        args.extend_from_slice(extra);
        let err = expect_code(&bake(dir.path(), &args), *code);
        assert!(err.contains(mention), "{err}");
    }
    // A NaN height is refused at load, naming the file.
    let nan = data("tests/bad-inputs/nan-height.tif");
    let err = expect_code(
        &bake(
            dir.path(),
            &[
                "shadow",
                s(&nan),
                "--sun-azimuth",
                "0",
                "--sun-elevation",
                "10",
                "--out",
                "m.png",
            ],
        ),
        exit::INPUT,
    );
    assert!(err.contains("nan-height.tif"), "{err}");
    // A missing output directory and an unknown image type.
    let err = expect_code(
        &bake(
            dir.path(),
            &[
                "shadow",
                s(&flat),
                "--sun-azimuth",
                "0",
                "--sun-elevation",
                "10",
                "--out",
                s(&out),
            ],
        ),
        exit::INPUT,
    );
    assert!(err.contains("does not exist"), "{err}");
    expect_code(
        &bake(
            dir.path(),
            &[
                "shadow",
                s(&flat),
                "--sun-azimuth",
                "0",
                "--sun-elevation",
                "10",
                "--out",
                "m.bmp",
            ],
        ),
        exit::UNSUPPORTED,
    );
    // A scene pipeline is not a height map.
    let err = expect_code(
        &bake(
            dir.path(),
            &[
                "shadow",
                s(&data("pipelines/cornell.ron")),
                "--sun-azimuth",
                "0",
                "--sun-elevation",
                "10",
                "--out",
                "m.png",
            ],
        ),
        exit::INPUT,
    );
    assert!(err.contains("scene"), "{err}");
    assert_eq!(list_files(dir.path()), vec!["flat.exr"]);
}

#[test]
fn pipeline_bakes_the_mipmap_deterministically_and_openexr_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    for (threads, name) in [("1", "a"), ("2", "b")] {
        let out = dir.path().join(name);
        expect_code(
            &bake(
                dir.path(),
                &[
                    "run",
                    "-q",
                    "-j",
                    threads,
                    s(&data("pipelines/bigtujunga.ron")),
                    "--out",
                    s(&out),
                ],
            ),
            0,
        );
    }
    let a = dir.path().join("a");
    assert_eq!(
        list_files(&a),
        vec!["heightmap.exr", "manifest.ron", "minmax_mipmap.exr"]
    );
    for f in list_files(&a) {
        assert_eq!(
            std::fs::read(a.join(&f)).unwrap(),
            std::fs::read(dir.path().join("b").join(&f)).unwrap(),
            "{f} differs"
        );
    }
    // The library reads back what it built.
    let m = relume::baked::Manifest::read(&a).unwrap();
    let map = relume::baked::heightmap::read(&a, &m).unwrap();
    let mip = relume::baked::mipmap::read_file(&a.join("minmax_mipmap.exr")).unwrap();
    assert_eq!(mip, relume::terrain::MinMaxMipmap::build(&map));
    let rec = m.stage("minmax_mipmap").unwrap();
    assert_eq!(rec.report["levels"], 10.0);

    if !require_python(&["OpenEXR", "numpy"]) {
        return;
    }
    // OpenEXR reads every part; level 0 equals the bordered 4x4 max/min of the height map
    // computed by numpy, and each level is the 2x2 reduction of the one below.
    let out = python(
        r#"
import sys, numpy as np, OpenEXR
d = sys.argv[1]
with OpenEXR.File(d + "/heightmap.exr") as f:
    h = f.channels()["Y"].pixels.astype(np.float64)
H, W = h.shape
with OpenEXR.File(d + "/minmax_mipmap.exr", separate_channels=True) as f:
    parts = f.parts
    names = [p.name() for p in parts]
    assert names == ["level%d" % i for i in range(len(parts))], names
    levels = [(p.channels["max"].pixels, p.channels["min"].pixels) for p in parts]
w0, h0 = (W + 1) // 2, (H + 1) // 2
pad = np.pad(h, 1, mode="edge")
mx = np.full((h0, w0), -np.inf); mn = np.full((h0, w0), np.inf)
for dy in range(4):
    for dx in range(4):
        # texel (2bx - 1 + dx, 2by - 1 + dy), edge-clamped (padding by one replicates the border)
        ys = np.clip(2 * np.arange(h0) - 1 + dy, -1, H) + 1
        xs = np.clip(2 * np.arange(w0) - 1 + dx, -1, W) + 1
        block = pad[np.ix_(ys, xs)]
        mx = np.maximum(mx, block); mn = np.minimum(mn, block)
assert levels[0][0].shape == (h0, w0)
assert np.array_equal(levels[0][0], mx) and np.array_equal(levels[0][1], mn)
for (amax, amin), (bmax, bmin) in zip(levels, levels[1:]):
    hh, ww = bmax.shape
    pm = np.pad(amax, ((0, 2 * hh - amax.shape[0]), (0, 2 * ww - amax.shape[1])), mode="edge")
    pn = np.pad(amin, ((0, 2 * hh - amin.shape[0]), (0, 2 * ww - amin.shape[1])), mode="edge")
    assert np.array_equal(bmax, pm.reshape(hh, 2, ww, 2).max(axis=(1, 3)))
    assert np.array_equal(bmin, pn.reshape(hh, 2, ww, 2).min(axis=(1, 3)))
assert (bmax.shape[0], bmax.shape[1]) != (1, 1)
print(len(levels))
"#,
        &[s(&a)],
    );
    assert_eq!(out.trim(), "10");
}

#[test]
fn softshadow_writes_16_bit_png_and_exr_and_methods_agree() {
    let dir = tempfile::tempdir().unwrap();
    let wall = dir.path().join("cone.exr");
    expect_code(
        &bake(
            dir.path(),
            &["generate", "cone", "--size", "96", "--out", s(&wall), "-q"],
        ),
        0,
    );
    let mut exrs = Vec::new();
    for method in [
        "exhaustive",
        "branch-and-bound",
        "uniform",
        "dynamic-programming",
    ] {
        let png = dir.path().join(format!("{method}.png"));
        let exr = dir.path().join(format!("{method}.exr"));
        let relief = dir.path().join(format!("{method}-relief.png"));
        for (out, extra) in [(&png, Some(&relief)), (&exr, None)] {
            let mut args = vec![
                "softshadow",
                s(&wall),
                "--sun-azimuth",
                "250",
                "--sun-elevation",
                "8",
                "--sun-radius",
                "1.5",
                "--method",
                method,
                "--out",
                s(out),
                "--json",
            ];
            if let Some(r) = extra {
                args.extend_from_slice(&["--shaded", s(r)]);
            }
            let o = bake(dir.path(), &args);
            expect_code(&o, 0);
            let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            assert!(j["penumbra_fraction"].as_f64().unwrap() > 0.0, "{method}");
        }
        let img = image::open(&png).unwrap();
        assert_eq!(img.color(), image::ColorType::L16);
        assert_eq!(
            image::open(&relief).unwrap().to_luma8().dimensions(),
            (96, 96)
        );
        let (w, h, ch) = relume::baked::exr_io::read_f32_channels(&exr).unwrap();
        assert_eq!((w, h), (96, 96));
        // The PNG holds the same values, quantised to 16 bits.
        let px = img.to_luma16();
        for (p, v) in px.pixels().zip(&ch[0].1) {
            assert!((p.0[0] as f32 / 65535.0 - v).abs() <= 1.0 / 65535.0);
        }
        exrs.push(ch[0].1.clone());
    }
    // Branch-and-bound equals the exhaustive reference.
    for (a, b) in exrs[0].iter().zip(&exrs[1]) {
        assert!((a - b).abs() <= 1e-6);
    }
    // A curved planet and bad knobs.
    let out = dir.path().join("moon.exr");
    expect_code(
        &bake(
            dir.path(),
            &[
                "softshadow",
                s(&wall),
                "--sun-azimuth",
                "90",
                "--sun-elevation",
                "2",
                "--planet-radius",
                "1737400",
                "--out",
                s(&out),
                "-q",
            ],
        ),
        0,
    );
    for (args, code) in [
        (vec!["--sun-radius", "0"], exit::INPUT),
        (vec!["--planet-radius", "0"], exit::INPUT),
        (vec!["--method", "uniform", "--steps", "0"], exit::USAGE),
    ] {
        let mut all = vec![
            "softshadow",
            s(&wall),
            "--sun-azimuth",
            "90",
            "--sun-elevation",
            "2",
            "--out",
            "x.exr",
        ];
        all.extend_from_slice(&args);
        expect_code(&bake(dir.path(), &all), code);
    }
    assert!(!dir.path().join("x.exr").exists());
}
