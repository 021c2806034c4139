//! The real `relume-bake` binary end to end: load, plan, run, inspect, determinism, and the
//! missing-MTL warning (the bad-input corpus is tests/cli/bad_inputs.rs).

use crate::common;

use common::{bake, data, expect_code, list_files};
use relume::error::exit;
use std::path::Path;

#[test]
fn load_reports_scene_and_heightmap_as_json() {
    let dir = tempfile::tempdir().unwrap();
    let o = bake(
        dir.path(),
        &[
            "load",
            "--json",
            data("scenes/cornell-box/cornell_box.obj").to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["triangles"], 32);
    assert_eq!(j["materials"].as_array().unwrap().len(), 4);
    assert_eq!(j["bounds_max"][1].as_f64().unwrap() as f32, 548.8f32);

    let o = bake(
        dir.path(),
        &[
            "load",
            "--json",
            data("scenes/dem/srtm_bigtujunga_30m.tif").to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (j["width"].as_u64(), j["height"].as_u64()),
        (Some(1197), Some(643))
    );
    assert_eq!(j["cell_size"][0], 30.0);
    assert_eq!(
        (
            j["min"].as_f64(),
            j["max"].as_f64(),
            j["nodata_count"].as_u64()
        ),
        (Some(315.0), Some(2295.0), Some(0))
    );
    // Overrides from the command line win over the world file.
    let o = bake(
        dir.path(),
        &[
            "load",
            "--json",
            "--cell-size",
            "10",
            "--height-scale",
            "2",
            data("scenes/dem/srtm_bigtujunga_30m.tif").to_str().unwrap(),
        ],
    );
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (j["cell_size"][0].as_f64(), j["max"].as_f64()),
        (Some(10.0), Some(4590.0))
    );
}

#[test]
fn run_writes_a_verified_bake_and_inspect_detects_damage() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bt");
    let o = bake(
        dir.path(),
        &[
            "run",
            "--quiet",
            "--no-cache",
            data("pipelines/bigtujunga.ron").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    assert_eq!(
        list_files(&out),
        vec!["heightmap.exr", "manifest.ron", "minmax_mipmap.exr"]
    );
    assert_eq!(
        list_files(dir.path()).len(),
        3,
        "no temporary files left: {:?}",
        list_files(dir.path())
    );
    let o = bake(dir.path(), &["inspect", "--json", out.to_str().unwrap()]);
    expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["ok"], true);

    // Manifest round trip through the library.
    let m = relume::baked::Manifest::read(&out).unwrap();
    let again = relume::baked::Manifest::from_ron(Path::new("m"), &m.to_ron()).unwrap();
    assert_eq!(m, again);
    let map = relume::baked::heightmap::read(&out, &m).unwrap();
    assert_eq!(
        (map.width, map.height, map.cell_size),
        (1197, 643, [30.0, 30.0])
    );

    // Flip one byte: inspect fails with the verification exit code and names the file.
    let exr = out.join("heightmap.exr");
    let mut bytes = std::fs::read(&exr).unwrap();
    let mid = bytes.len() / 2;
    bytes[mid] ^= 0x40;
    std::fs::write(&exr, &bytes).unwrap();
    let err = expect_code(
        &bake(dir.path(), &["inspect", out.to_str().unwrap()]),
        exit::VERIFY,
    );
    assert!(
        err.contains("heightmap.exr") && err.contains("altered"),
        "{err}"
    );
    // Truncate it.
    std::fs::write(&exr, &bytes[..mid]).unwrap();
    let err = expect_code(
        &bake(dir.path(), &["inspect", out.to_str().unwrap()]),
        exit::VERIFY,
    );
    assert!(err.contains("truncated"), "{err}");
    // Remove it.
    std::fs::remove_file(&exr).unwrap();
    let err = expect_code(
        &bake(dir.path(), &["inspect", out.to_str().unwrap()]),
        exit::VERIFY,
    );
    assert!(
        err.contains("heightmap.exr") && err.contains("missing"),
        "{err}"
    );
}

#[test]
fn bakes_are_byte_identical_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    for (threads, name) in [("1", "a"), ("2", "b")] {
        let out = dir.path().join(name);
        let o = bake(
            dir.path(),
            &[
                "run",
                "-q",
                "-j",
                threads,
                data("pipelines/cornell.ron").to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ],
        );
        expect_code(&o, 0);
    }
    let a = list_files(&dir.path().join("a"));
    assert_eq!(a, list_files(&dir.path().join("b")));
    for f in a {
        assert_eq!(
            std::fs::read(dir.path().join("a").join(&f)).unwrap(),
            std::fs::read(dir.path().join("b").join(&f)).unwrap(),
            "{f} differs"
        );
    }
}

#[test]
fn plan_writes_nothing_and_run_respects_the_memory_budget() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("p");
    let o = bake(
        dir.path(),
        &[
            "plan",
            data("pipelines/puget-sound.ron").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    expect_code(&o, 0);
    assert!(
        stdout.contains("load") && stdout.contains("peak"),
        "{stdout}"
    );
    assert!(list_files(dir.path()).is_empty());

    // A first bake, then a second one that fails on the budget: the first survives untouched.
    let o = bake(
        dir.path(),
        &[
            "run",
            "-q",
            "--no-cache",
            data("pipelines/puget-sound.ron").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    expect_code(&o, 0);
    let before = std::fs::read(out.join("manifest.ron")).unwrap();
    let o = bake(
        dir.path(),
        &[
            "run",
            "-q",
            "--no-cache",
            "--max-memory",
            "1M",
            data("pipelines/puget-sound.ron").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    let err = expect_code(&o, exit::LIMIT);
    assert!(err.contains("--max-memory") && err.contains("MiB"), "{err}");
    assert_eq!(std::fs::read(out.join("manifest.ron")).unwrap(), before);
    assert_eq!(list_files(dir.path()).len(), 3); // heightmap, mipmap, manifest
}

#[test]
fn missing_mtl_is_a_warning_with_a_grey_default() {
    let dir = tempfile::tempdir().unwrap();
    let o = bake(
        dir.path(),
        &[
            "load",
            "--json",
            data("tests/bad-inputs/missing-mtl.obj").to_str().unwrap(),
        ],
    );
    let err = expect_code(&o, 0);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["materials"][0]["name"], "default");
    assert_eq!(j["materials"][0]["albedo"][0], 0.5);
    assert!(
        j["warnings"][0]
            .as_str()
            .unwrap()
            .contains("material library"),
        "{j}"
    );
    let _ = err;
}

#[test]
fn output_path_that_is_a_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("taken");
    std::fs::write(&file, "precious").unwrap();
    let o = bake(
        dir.path(),
        &[
            "run",
            data("pipelines/cornell.ron").to_str().unwrap(),
            "--out",
            file.to_str().unwrap(),
        ],
    );
    let err = expect_code(&o, exit::IO);
    assert!(err.contains("taken") && err.contains("is a file"), "{err}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "precious");
    assert_eq!(list_files(dir.path()), vec!["taken"]);
    // A non-empty directory that is not a bake is not replaced either.
    let notbake = dir.path().join("docs");
    std::fs::create_dir(&notbake).unwrap();
    std::fs::write(notbake.join("keep.txt"), "x").unwrap();
    let o = bake(
        dir.path(),
        &[
            "run",
            data("pipelines/cornell.ron").to_str().unwrap(),
            "--out",
            notbake.to_str().unwrap(),
        ],
    );
    let err = expect_code(&o, exit::IO);
    assert!(err.contains("not a relume bake"), "{err}");
    assert_eq!(list_files(&notbake), vec!["keep.txt"]);
}

#[test]
fn help_lists_exit_codes() {
    let dir = tempfile::tempdir().unwrap();
    let o = bake(dir.path(), &["--help"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("Exit codes") && out.contains("5  over a resource limit"),
        "{out}"
    );
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_relume-player"))
        .arg("--version")
        .output()
        .unwrap();
    assert!(o.status.success());
}
