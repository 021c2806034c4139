//! The real `relume-bake` binary end to end: load, plan, run, inspect, determinism, and the
//! bad-input corpus in tests/bad-inputs/.

mod common;

use common::{bake, data, expect_code, list_files, text};
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

/// One member of the bad-input corpus: the command, the exit code, what stderr must mention.
struct Bad {
    args: &'static [&'static str],
    code: i32,
    mentions: &'static [&'static str],
}

#[test]
fn bad_input_corpus_gives_clear_errors_and_no_output() {
    use exit::*;
    let corpus = [
        Bad {
            args: &["load", "empty.obj"],
            code: INPUT,
            mentions: &["empty.obj", "no faces"],
        },
        Bad {
            args: &["load", "truncated.obj"],
            code: INPUT,
            mentions: &["truncated.obj", "OBJ"],
        },
        Bad {
            args: &["load", "nan-vertex.obj"],
            code: INPUT,
            mentions: &["nan-vertex.obj", "non-finite"],
        },
        Bad {
            args: &["load", "face-out-of-range.obj"],
            code: INPUT,
            mentions: &["face-out-of-range.obj", "out of bounds"],
        },
        Bad {
            args: &["load", "broken-chunk.glb"],
            code: INPUT,
            mentions: &["broken-chunk.glb", "GLB"],
        },
        Bad {
            args: &["load", "missing-buffer.gltf"],
            code: INPUT,
            mentions: &["missing-buffer.gltf", "cannot be read"],
        },
        Bad {
            args: &["load", "truncated.gltf"],
            code: INPUT,
            mentions: &["truncated.gltf", "JSON"],
        },
        Bad {
            args: &["load", "not-a-png.png"],
            code: INPUT,
            mentions: &["not-a-png.png", "cannot decode png", "signature"],
        },
        Bad {
            args: &["load", "zero-size.png"],
            code: INPUT,
            mentions: &["zero-size.png"],
        },
        Bad {
            args: &["load", "colour.png"],
            code: INPUT,
            mentions: &["colour.png", "channels differ"],
        },
        Bad {
            args: &["load", "float64.tif"],
            code: UNSUPPORTED,
            mentions: &["float64.tif", "float64"],
        },
        Bad {
            args: &["load", "rgb.tif"],
            code: UNSUPPORTED,
            mentions: &["rgb.tif", "one sample per pixel"],
        },
        Bad {
            args: &["load", "nan-height.tif"],
            code: INPUT,
            mentions: &["nan-height.tif", "1 no-data", "column 1, row 2"],
        },
        Bad {
            args: &["load", "short.raw", "--raw-size", "2x2"],
            code: INPUT,
            mentions: &["short.raw", "16 bytes"],
        },
        Bad {
            args: &["load", "short.raw"],
            code: INPUT,
            mentions: &["short.raw", "--raw-size"],
        },
        Bad {
            args: &["load", "no-such-file.obj"],
            code: IO,
            mentions: &["no-such-file.obj", "cannot read"],
        },
        Bad {
            args: &["run", "unknown-stage.ron"],
            code: INPUT,
            mentions: &["unknown-stage.ron:4:", "Sharpen"],
        },
        Bad {
            args: &["run", "planned-stage.ron"],
            code: UNSUPPORTED,
            mentions: &["planned-stage.ron:4:", "not yet supported"],
        },
        Bad {
            args: &["run", "wrong-type.ron"],
            code: INPUT,
            mentions: &["wrong-type.ron:2:", "expected"],
        },
        Bad {
            args: &["run", "out-of-range.ron"],
            code: INPUT,
            mentions: &["out-of-range.ron:4:", "out of range", "-10"],
        },
        Bad {
            args: &["run", "unknown-field.ron"],
            code: INPUT,
            mentions: &["unknown-field.ron:2:", "scael", "did you mean `scale`"],
        },
        Bad {
            args: &["run", "truncated.ron"],
            code: INPUT,
            mentions: &["truncated.ron:"],
        },
        Bad {
            args: &["run", "missing-input.ron"],
            code: IO,
            mentions: &["no-such-scene.obj"],
        },
        Bad {
            args: &["inspect", "empty.obj"],
            code: INPUT,
            mentions: &["empty.obj", "not a directory"],
        },
        Bad {
            args: &["run", "--threads", "0", "unknown-stage.ron"],
            code: USAGE,
            mentions: &["--threads"],
        },
    ];
    let corpus_dir = data("tests/bad-inputs");
    for bad in &corpus {
        let work = tempfile::tempdir().unwrap();
        let mut args: Vec<String> = bad.args.iter().map(|a| a.to_string()).collect();
        // Corpus files are given by absolute path; runs write (if at all) into the work dir.
        for a in args.iter_mut() {
            if corpus_dir.join(&*a).exists() || a.starts_with("no-such") {
                *a = corpus_dir.join(&*a).display().to_string();
            }
        }
        if args[0] == "run" {
            args.push("--out".into());
            args.push(work.path().join("out").display().to_string());
        }
        let argv: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = bake(work.path(), &argv);
        let err = expect_code(&o, bad.code);
        for m in bad.mentions {
            assert!(
                err.contains(m),
                "{:?}: stderr lacks {m:?}:\n{}",
                bad.args,
                text(&o)
            );
        }
        assert!(
            list_files(work.path()).is_empty(),
            "{:?} left output behind: {:?}",
            bad.args,
            list_files(work.path())
        );
    }
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
