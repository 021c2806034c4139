//! The radiosity stages through the real `relume-bake` binary: the Cornell pipeline, stages run
//! alone, exports cross-checked with numpy, determinism across thread counts, refusals.

use crate::common;

use crate::fixtures;
use common::{bake, data, expect_code, list_files, python, require_python};
use relume::error::exit;
use relume::scene::Scene;
use std::path::Path;

/// Write a scene as OBJ + MTL (one material per `usemtl`).
fn write_obj(scene: &Scene, dir: &Path, name: &str) -> std::path::PathBuf {
    let mut mtl = String::new();
    for m in &scene.materials {
        mtl += &format!(
            "newmtl {}\nKd {} {} {}\nKe {} {} {}\n",
            m.name,
            m.albedo[0],
            m.albedo[1],
            m.albedo[2],
            m.emission[0],
            m.emission[1],
            m.emission[2]
        );
    }
    std::fs::write(dir.join(format!("{name}.mtl")), mtl).unwrap();
    let mut obj = format!("mtllib {name}.mtl\n");
    for p in &scene.positions {
        obj += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for (t, tri) in scene.triangles.iter().enumerate() {
        obj += &format!(
            "o {}\nusemtl {}\nf {} {} {}\n",
            scene.objects[scene.triangle_object[t] as usize],
            scene.materials[scene.triangle_material[t] as usize].name,
            tri[0] + 1,
            tri[1] + 1,
            tri[2] + 1
        );
    }
    let path = dir.join(format!("{name}.obj"));
    std::fs::write(&path, obj).unwrap();
    path
}

fn pipeline(dir: &Path, name: &str, input: &Path, stages: &str) -> std::path::PathBuf {
    let p = dir.join(format!("{name}.ron"));
    std::fs::write(
        &p,
        format!(
            "Pipeline(\n    input: Scene(path: {:?}),\n    stages: [\n{stages}\n    ],\n)\n",
            input
        ),
    )
    .unwrap();
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn cornell_pipeline_exports_match_numpy() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cornell");
    let o = bake(
        dir.path(),
        &[
            "run",
            "-q",
            s(&data("pipelines/cornell.ron")),
            "--out",
            s(&out),
        ],
    );
    expect_code(&o, 0);
    expect_code(&bake(dir.path(), &["inspect", s(&out)]), 0);
    let json = dir.path().join("patches.json");
    let ff = dir.path().join("F.npy");
    let st = dir.path().join("S.npy");
    for (what, file) in [
        ("patches", &json),
        ("form-factors", &ff),
        ("transport", &st),
    ] {
        expect_code(
            &bake(dir.path(), &["export", s(&out), what, "--out", s(file)]),
            0,
        );
    }
    let doc: serde_json::Value = serde_json::from_slice(&std::fs::read(&json).unwrap()).unwrap();
    let patches = doc["patches"].as_array().unwrap();
    let manifest = std::fs::read_to_string(out.join("manifest.ron")).unwrap();
    assert!(
        manifest.contains(&format!("\"patches\": {}.0", patches.len())),
        "patch count in the manifest"
    );
    let names: std::collections::BTreeSet<&str> = patches
        .iter()
        .flat_map(|p| {
            p["objects"]
                .as_array()
                .unwrap()
                .iter()
                .map(|o| o.as_str().unwrap())
        })
        .collect();
    for n in [
        "floor",
        "ceiling",
        "light",
        "left_wall",
        "short_block_4",
        "tall_block_0",
    ] {
        assert!(names.contains(n), "{n} missing from {names:?}");
    }
    if !require_python(&["numpy"]) {
        return;
    }
    // numpy recomputes S_∞ = M (I − M)^{-1} per channel from F and the exported albedo.
    let out = python(
        r#"
import json, sys, numpy as np
F = np.load(sys.argv[1]); S = np.load(sys.argv[2]); P = json.load(open(sys.argv[3]))["patches"]
n = len(P)
assert F.dtype == np.float32 and F.shape == (n, n), F.shape
assert S.dtype == np.float32 and S.shape == (3, n, n), S.shape
assert (F >= 0).all() and (F.sum(1) <= 1 + 1e-5).all() and (np.diag(F) == 0).all()
A = np.array([p["area"] for p in P], dtype=np.float64)
for c in range(3):
    rho = np.array([p["albedo"][c] for p in P], dtype=np.float64)
    M = rho[:, None] * F.astype(np.float64)
    ref = M @ np.linalg.inv(np.eye(n) - M)
    err = np.abs(ref - S[c]).max() / np.abs(ref).max()
    assert err < 1e-5, (c, err)
print("ok", n)
"#,
        &[s(&ff), s(&st), s(&json)],
    );
    assert!(out.starts_with("ok"), "{out}");
}

#[test]
fn stages_run_alone_and_bakes_are_identical_across_threads() {
    let dir = tempfile::tempdir().unwrap();
    let scene_path = data("scenes/cornell-box/cornell_box.obj");
    let p = dir.path().join("small.ron");
    std::fs::write(
        &p,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [\n\
             Voxelize(resolution: TargetPatches(150)),\n\
             FormFactors(estimator: Pairwise, samples: 16, seed: 3),\n\
             Transport(bounces: Auto(0.001)),\n])",
            scene_path
        ),
    )
    .unwrap();
    for j in ["1", "2"] {
        let o = bake(
            dir.path(),
            &["run", "-q", "-j", j, s(&p), "--out", s(&dir.path().join(j))],
        );
        expect_code(&o, 0);
    }
    let files = list_files(&dir.path().join("1"));
    assert!(files.contains(&"transport.npy".to_string()));
    for f in &files {
        assert_eq!(
            std::fs::read(dir.path().join("1").join(f)).unwrap(),
            std::fs::read(dir.path().join("2").join(f)).unwrap(),
            "{f} differs between -j1 and -j2"
        );
    }
    // Re-run form factors alone (hemisphere, both thread counts): transport is dropped.
    let b = dir.path().join("1");
    for j in ["1", "2"] {
        let c = dir.path().join(format!("copy{j}"));
        std::fs::create_dir(&c).unwrap();
        for f in &files {
            std::fs::copy(b.join(f), c.join(f)).unwrap();
        }
        let o = bake(
            dir.path(),
            &["-q", "-j", j, "form-factors", s(&c), "--samples", "256"],
        );
        expect_code(&o, 0);
        assert!(
            !c.join("transport.npy").exists(),
            "later stages are dropped"
        );
        let o = bake(
            dir.path(),
            &[
                "-q",
                "-j",
                j,
                "transport",
                s(&c),
                "--bounces",
                "3",
                "--power",
                "doubling",
            ],
        );
        expect_code(&o, 0);
        expect_code(&bake(dir.path(), &["inspect", s(&c)]), 0);
    }
    for f in ["form_factors.npy", "transport.npy", "manifest.ron"] {
        assert_eq!(
            std::fs::read(dir.path().join("copy1").join(f)).unwrap(),
            std::fs::read(dir.path().join("copy2").join(f)).unwrap(),
            "{f} differs"
        );
    }
    let manifest = std::fs::read_to_string(dir.path().join("copy1/manifest.ron")).unwrap();
    assert!(
        manifest.contains("Finite(3)") && manifest.contains("samples: 256"),
        "{manifest}"
    );
    // A budget too small is refused before allocating, and the bake is left as it was.
    let before = std::fs::read(dir.path().join("copy1/transport.npy")).unwrap();
    let o = bake(
        dir.path(),
        &[
            "transport",
            s(&dir.path().join("copy1")),
            "--max-memory",
            "1K",
        ],
    );
    let err = expect_code(&o, exit::LIMIT);
    assert!(err.contains("over the budget"), "{err}");
    assert_eq!(
        std::fs::read(dir.path().join("copy1/transport.npy")).unwrap(),
        before
    );
    // Voxelize alone drops the form factors too.
    let o = bake(
        dir.path(),
        &[
            "-q",
            "voxelize",
            s(&dir.path().join("copy1")),
            "--voxel-size",
            "0.1",
        ],
    );
    expect_code(&o, 0);
    assert_eq!(
        list_files(&dir.path().join("copy1")),
        vec!["manifest.ron", "patches.bin", "scene.bin"]
    );
    let o = bake(dir.path(), &["transport", s(&dir.path().join("copy1"))]);
    let err = expect_code(&o, exit::INPUT);
    assert!(err.contains("needs `form_factors`"), "{err}");
    let o = bake(
        dir.path(),
        &[
            "export",
            s(&dir.path().join("copy1")),
            "transport",
            "--out",
            "x.npy",
        ],
    );
    let err = expect_code(&o, exit::INPUT);
    assert!(err.contains("no `transport.npy`"), "{err}");
}

#[test]
fn albedo_one_closed_box_is_refused_with_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let scene = fixtures::closed_box([1.0, 1.0, 1.0], 1.0, 1.0);
    let obj = write_obj(&scene, dir.path(), "white_box");
    let p = pipeline(
        dir.path(),
        "furnace",
        &obj,
        "Voxelize(resolution: VoxelSize(0.25)), FormFactors(samples: 256), Transport(bounces: Infinite),",
    );
    let out = dir.path().join("furnace_out");
    let o = bake(dir.path(), &["run", s(&p), "--out", s(&out)]);
    let err = expect_code(&o, exit::INPUT);
    assert!(
        err.contains("spectral radius") && err.contains("Finite(k)"),
        "{err}"
    );
    assert!(!out.exists(), "no partial output");
    // Finite bounces are fine.
    let p = pipeline(
        dir.path(),
        "finite",
        &obj,
        "Voxelize(resolution: VoxelSize(0.25)), FormFactors(samples: 256), Transport(bounces: Finite(4)),",
    );
    expect_code(
        &bake(dir.path(), &["run", "-q", s(&p), "--out", s(&out)]),
        0,
    );
}

#[test]
fn degenerate_triangles_are_reported_and_bad_knobs_located() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tri.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 1\n",
    )
    .unwrap();
    let p = pipeline(
        dir.path(),
        "deg",
        &obj,
        "Voxelize(resolution: VoxelSize(0.5)),",
    );
    let o = bake(
        dir.path(),
        &["run", s(&p), "--out", s(&dir.path().join("deg_out"))],
    );
    let err = expect_code(&o, 0);
    assert!(err.contains("voxelize: skipped 2 degenerate"), "{err}");
    for (stage, mentions) in [
        (
            "Voxelize(resolution: TargetPatches(0)),",
            "TargetPatches(0)",
        ),
        ("Voxelize(resolution: VoxelSize(-1.0)),", "VoxelSize(-1)"),
        (
            "Voxelize(resolution: Adaptive(target: 600, albedo_tolerance: -1.0)),",
            "albedo_tolerance -1",
        ),
        (
            "Voxelize(resolution: Adaptive(target: 600, base_share: 0.0)),",
            "base_share 0",
        ),
        ("Voxelize(), FormFactors(samples: 0),", "at least 1"),
        (
            "Voxelize(), FormFactors(), Transport(bounces: Finite(0)),",
            "Finite(0)",
        ),
        (
            "Voxelize(), FormFactors(), Transport(bounces: Auto(-0.1)),",
            "Auto(-0.1)",
        ),
        (
            "Voxelize(), FormFactors(estimator: Hemisfere),",
            "Hemisfere",
        ),
        ("Transport(),", "needs `voxelize`"),
    ] {
        let p = pipeline(dir.path(), "bad", &obj, stage);
        let o = bake(dir.path(), &["run", s(&p)]);
        let err = expect_code(&o, exit::INPUT);
        assert!(err.contains(mentions), "{stage}: {err}");
        if !stage.starts_with("Transport") {
            assert!(err.contains("bad.ron:4:"), "{stage}: {err}");
        }
    }
}

/// `Adaptive(target: n)` from a pipeline file and `voxelize --adaptive N` from the command line
/// both land within ±20 % of n, and say so in the manifest.
#[test]
fn adaptive_resolution_from_pipeline_and_flag() {
    let dir = tempfile::tempdir().unwrap();
    let obj = data("scenes/cornell-box/cornell_box.obj");
    let p = pipeline(
        dir.path(),
        "adaptive",
        &obj,
        "Voxelize(resolution: Adaptive(target: 300, max_level: 1)),",
    );
    let out = dir.path().join("adaptive_out");
    expect_code(
        &bake(dir.path(), &["-q", "run", s(&p), "--out", s(&out)]),
        0,
    );
    let count = |dir: &Path| -> f64 {
        let m = std::fs::read_to_string(dir.join("manifest.ron")).unwrap();
        let at = m.find("\"patches\": ").unwrap() + "\"patches\": ".len();
        m[at..]
            .split(|c: char| c != '.' && !c.is_ascii_digit())
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let n = count(&out);
    assert!(
        (n / 300.0 - 1.0).abs() <= 0.2,
        "{n} patches for Adaptive(target: 300)"
    );
    let o = bake(
        dir.path(),
        &["-q", "voxelize", s(&out), "--adaptive", "500"],
    );
    expect_code(&o, 0);
    let n = count(&out);
    assert!(
        (n / 500.0 - 1.0).abs() <= 0.2,
        "{n} patches for --adaptive 500"
    );
}
