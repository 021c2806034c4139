//! `relume-bake reorder|encode|gather` on a baked directory; DDS/KTX2 round trips; Pillow
//! cross-check of the BC1 texture; tiling; determinism.
#![allow(clippy::needless_range_loop)]

use crate::common;
#[path = "../support/transport_box.rs"]
mod transport_box;

use common::{bake, expect_code, python, require_python, text};
use relume::baked::encoded::read as read_encoded;
use relume::baked::{manifest::hash_file, FileRecord, Manifest};
use relume::compress::{bc1, compress, gather, report, DenseEncoding, EncodeOptions};
use relume::radiosity::TransportMatrix;
use std::path::{Path, PathBuf};

/// A scene bake of the Cornell box whose `transport` stage wrote `s` (a synthetic matrix of any
/// size: the compression stages read nothing else). The manifest records a `Transport` stage
/// with `transport.npy` as its output, exactly as a real run does.
fn bake_with_transport(tmp: &Path, name: &str, s: &TransportMatrix) -> PathBuf {
    let pipe = tmp.join(format!("{name}.ron"));
    let obj = common::data("scenes/cornell-box/cornell_box.obj");
    std::fs::write(
        &pipe,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [])",
            obj
        ),
    )
    .unwrap();
    let dir = tmp.join(name);
    let o = bake(
        tmp,
        &[
            "-q",
            "run",
            pipe.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    relume::baked::transport::write_file(&dir.join("transport.npy"), s).unwrap();
    let mut m = Manifest::read(&dir).unwrap();
    let (bytes, sha256) = hash_file(&dir.join("transport.npy")).unwrap();
    m.files.push(FileRecord {
        name: "transport.npy".into(),
        bytes,
        sha256,
    });
    m.pipeline
        .stages
        .push(relume::pipeline::Stage::Transport(Default::default()));
    m.stages.push(relume::baked::StageRecord {
        stage: "transport".into(),
        outputs: vec!["transport.npy".into()],
        ..Default::default()
    });
    std::fs::write(dir.join("manifest.ron"), m.to_ron()).unwrap();
    dir
}

fn box_matrix() -> TransportMatrix {
    transport_box::transport(&transport_box::closed_box(4, 11), Some(3))
}

fn run_ok(tmp: &Path, args: &[&str]) -> String {
    let o = bake(tmp, args);
    expect_code(&o, 0);
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn reorder_encode_gather_round_trip_with_tiles() {
    let tmp = tempfile::tempdir().unwrap();
    let s = box_matrix(); // n = 96
    let dir = bake_with_transport(tmp.path(), "b", &s);
    let d = dir.to_str().unwrap();
    run_ok(tmp.path(), &["-q", "reorder", d]);
    assert!(dir.join("permutation.bin").exists());
    run_ok(
        tmp.path(),
        &[
            "-q",
            "encode",
            d,
            "--max-texture-size",
            "40",
            "--encoding",
            "bc1-log",
        ],
    );
    // 96 texels in tiles of 40: 3x3 tiles, each in both containers.
    for r in 0..3 {
        for c in 0..3 {
            for ext in ["dds", "ktx2"] {
                assert!(
                    dir.join(format!("transfer_r{r}_c{c}.{ext}")).exists(),
                    "{r} {c} {ext}"
                );
            }
        }
    }
    let m = Manifest::read(&dir).unwrap();
    let enc_rec = m.stage("encode").expect("encode record");
    for key in [
        "error_mean_abs",
        "error_max_abs",
        "error_sum_abs",
        "gather_rms_rel_uniform",
        "dense_bytes",
        "sidecar_bytes",
    ] {
        assert!(enc_rec.report.contains_key(key), "{key}");
    }
    assert_eq!(enc_rec.report["tiles"], 9.0);
    assert!(
        enc_rec.facts["tiles"].contains("transfer_r2_c2 rows 80+16 cols 80+16"),
        "{:?}",
        enc_rec.facts
    );
    // inspect shows the report and verifies every file.
    let o = bake(tmp.path(), &["inspect", d]);
    let out = expect_code(&o, 0);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("error_sum_abs"), "{stdout}{out}");

    // The gather CLI equals the library's gather from the files, and S·E within the error.
    let bnpy = tmp.path().join("b.npy");
    run_ok(
        tmp.path(),
        &[
            "-q",
            "gather",
            d,
            "--light",
            "random",
            "--out",
            bnpy.to_str().unwrap(),
        ],
    );
    let (shape, b) = relume::baked::npy::read_npy_f32(&bnpy).unwrap();
    assert_eq!(shape, vec![3, 96]);
    let enc = read_encoded(&dir).unwrap();
    let light = report::standard_lights(3, 96).remove(1).1;
    assert_eq!(b, gather(&enc, &light));
    let exact = s.mat_vec(&light);
    let rms = report::rms_relative(&b, &exact);
    assert!(
        (rms - enc_rec.report["gather_rms_rel_random"]).abs() < 1e-12,
        "{rms}"
    );
}

#[test]
fn dds_and_ktx2_round_trip_every_encoding() {
    let tmp = tempfile::tempdir().unwrap();
    let s = box_matrix();
    let dir = bake_with_transport(tmp.path(), "b", &s);
    let d = dir.to_str().unwrap();
    for (arg, enc) in [
        ("bc1-log", DenseEncoding::Bc1Log),
        ("bc4-log", DenseEncoding::Bc4Log),
        ("bc6h", DenseEncoding::Bc6h),
        ("f16", DenseEncoding::F16),
        ("f32", DenseEncoding::F32),
    ] {
        let expected = compress(
            &s,
            (0..96).collect(),
            4.0,
            &EncodeOptions {
                encoding: enc,
                ..Default::default()
            },
        )
        .unwrap();
        for container in ["dds", "ktx2"] {
            run_ok(
                tmp.path(),
                &[
                    "-q",
                    "encode",
                    d,
                    "--encoding",
                    arg,
                    "--container",
                    container,
                    "--max-texture-size",
                    "64",
                    "--split-percent",
                    "4",
                    "--fill-holes",
                    "false",
                ],
            );
            let back = read_encoded(&dir).unwrap();
            assert_eq!(back, expected, "{arg} {container}");
        }
        // The KTX2 file parses with an independent reader (the `ktx2` crate) and holds the layers.
        let bytes = std::fs::read(dir.join("transfer_r0_c0.ktx2")).unwrap();
        let reader = ktx2::Reader::new(&bytes[..]).expect("valid KTX2");
        let h = reader.header();
        assert_eq!((h.pixel_width, h.pixel_height), (64, 64));
        assert_eq!(h.level_count, 1);
        assert!(reader.basic_dfd().is_some(), "{arg}: basic DFD");
        // The spec's KTXwriter value is NUL-terminated; the reader hands it back as stored.
        let writer = reader.writer().unwrap().trim_end_matches('\0').to_string();
        assert_eq!(writer, format!("relume {}", env!("CARGO_PKG_VERSION")));
        let level = reader.levels().next().unwrap();
        let tile = relume::compress::containers::plan_tiles(96, 64, "transfer")
            .unwrap()
            .remove(0);
        assert_eq!(
            level.data,
            relume::compress::containers::tile_layers(&expected.dense, &tile)
                .concat()
                .as_slice()
        );
    }
}

#[test]
fn pillow_decodes_our_dds_exactly_like_our_decoder() {
    if !require_python(&["PIL", "numpy"]) {
        return;
    }
    let tmp = tempfile::tempdir().unwrap();
    // n = 50 → 52x52 texture; a non-trivial matrix with zeros and a wide range.
    let s = transport_box::transport(&transport_box::closed_box(3, 5), None);
    let s = TransportMatrix::new(3, 54, s.data).unwrap();
    let dir = bake_with_transport(tmp.path(), "b", &s);
    run_ok(
        tmp.path(),
        &[
            "-q",
            "encode",
            dir.to_str().unwrap(),
            "--encoding",
            "bc1-log",
            "--container",
            "dds",
        ],
    );
    let enc = read_encoded(&dir).unwrap();
    let ours = bc1::decode_image(enc.dense.padded, enc.dense.padded, &enc.dense.layers[0]);
    let ours_path = tmp.path().join("ours.rgb");
    std::fs::write(&ours_path, &ours).unwrap();
    let out = python(
        "import sys, numpy as np\nfrom PIL import Image\nim = Image.open(sys.argv[1])\nim.load()\nprint(im.format, im.mode, im.size)\na = np.asarray(im.convert('RGBA'))[:, :, :3]\nb = np.fromfile(sys.argv[2], dtype=np.uint8).reshape(a.shape)\nd = np.argwhere(a != b)\nprint('differing', len(d), d[:5].tolist())\n",
        &[dir.join("transfer.dds").to_str().unwrap(), ours_path.to_str().unwrap()],
    );
    assert!(out.contains("DDS"), "{out}");
    assert!(out.contains("(56, 56)"), "{out}");
    assert!(out.contains("differing 0 "), "{out}");
}

#[test]
fn encode_is_byte_identical_for_any_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let s = box_matrix();
    let mut hashes = Vec::new();
    for j in ["1", "2"] {
        let dir = bake_with_transport(tmp.path(), &format!("b{j}"), &s);
        let d = dir.to_str().unwrap();
        run_ok(tmp.path(), &["-q", "-j", j, "reorder", d]);
        run_ok(
            tmp.path(),
            &["-q", "-j", j, "encode", d, "--feedback", "true"],
        );
        let m = Manifest::read(&dir).unwrap();
        hashes.push((m.files.clone(), m.stage("encode").unwrap().clone()));
    }
    assert_eq!(hashes[0], hashes[1]);
}

#[test]
fn bad_encode_knobs_and_missing_transport_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let s = box_matrix();
    let dir = bake_with_transport(tmp.path(), "b", &s);
    let d = dir.to_str().unwrap();
    let o = bake(tmp.path(), &["encode", d, "--max-texture-size", "30"]);
    let err = expect_code(&o, 3);
    assert!(err.contains("multiple of 4"), "{}", text(&o));
    let o = bake(tmp.path(), &["encode", d, "--split-percent", "120"]);
    expect_code(&o, 2);
    // A bake without a transport stage.
    let o = bake(
        tmp.path(),
        &[
            "-q",
            "run",
            common::data("pipelines/gltf-room.ron").to_str().unwrap(),
            "--out",
            tmp.path().join("plain").to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    let o = bake(
        tmp.path(),
        &["encode", tmp.path().join("plain").to_str().unwrap()],
    );
    let err = expect_code(&o, 3);
    assert!(err.contains("needs `transport`"), "{}", text(&o));
}

#[test]
fn default_encode_meets_the_goal_on_the_box() {
    // The goal: ≤ 2 % RMS relative error of the gathered light at ≤ 1.5x the bytes of the
    // scheme of Shcherbakov (2017) (Bc1Log, p = 4 %), here on the small box and the standard
    // lights.
    let tmp = tempfile::tempdir().unwrap();
    let s = transport_box::transport(&transport_box::closed_box(8, 2), None); // n = 384
    let dir = bake_with_transport(tmp.path(), "b", &s);
    let d = dir.to_str().unwrap();
    run_ok(tmp.path(), &["-q", "reorder", d]);
    run_ok(tmp.path(), &["-q", "encode", d]);
    let m = Manifest::read(&dir).unwrap();
    let rec = m.stage("encode").unwrap();
    assert_eq!(rec.facts["encoding"], "bc6h");
    let enc = read_encoded(&dir).unwrap();
    let seed = compress(
        &s.permuted(&enc.perm),
        enc.perm.clone(),
        4.0,
        &EncodeOptions::default(),
    )
    .unwrap();
    assert!(
        enc.bytes() as f64 <= 1.5 * seed.bytes() as f64,
        "{} vs the thesis's scheme {}",
        enc.bytes(),
        seed.bytes()
    );
    for light in ["uniform", "random", "half"] {
        let v = rec.report[&format!("gather_rms_rel_{light}")];
        assert!(v <= 0.02, "{light}: {v}");
    }
    for (name, e) in transport_box::box_lights(&transport_box::closed_box(8, 2)) {
        let r = report::rms_relative(&gather(&enc, &e), &s.mat_vec(&e));
        assert!(r <= 0.02, "{name}: {r}");
    }
}

#[test]
fn two_reorder_passes_do_not_increase_the_summed_error_on_the_cornell_box() {
    // The real Cornell box bake (pipelines/cornell.ron: voxelize → form factors → transport),
    // then the radiosity thesis's scheme (Bc1Log, p = 4 %) after 0, 1 and 2 reorder passes.
    use relume::compress::{reorder, ReorderMetric, ReorderOptions};
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("cornell");
    run_ok(
        tmp.path(),
        &[
            "-q",
            "run",
            common::data("pipelines/cornell.ron").to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    let s = relume::baked::transport::read_file(&dir.join("transport.npy")).unwrap();
    let mut sums = Vec::new();
    for passes in 0..=2 {
        let perm = reorder(
            &mut s.clone(),
            ReorderOptions {
                passes,
                metric: ReorderMetric::Linear,
                ..Default::default()
            },
        );
        let sp = s.permuted(&perm);
        let opts = EncodeOptions {
            encoding: DenseEncoding::Bc1Log,
            ..Default::default()
        };
        let e = compress(&sp, perm, 4.0, &opts).unwrap();
        sums.push(report::entry_errors(&sp, &e).sum);
    }
    eprintln!(
        "Cornell box (n = {}), summed error after 0/1/2 passes: {sums:?}",
        s.n
    );
    assert!(sums[2] <= sums[0], "{sums:?}");
    assert!(sums[1] <= sums[0], "{sums:?}");
}
