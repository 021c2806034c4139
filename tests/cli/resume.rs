//! The stage cache: a killed bake resumes from its finished stages, a changed `Encode` reruns only
//! encode, an unchanged pipeline does nothing, and every such bake is byte-identical to an
//! uninterrupted one made without the cache.

use crate::common;

use common::{bake, bake_killed_after, contents, data, expect_code, list_files};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A Cornell bake of a few seconds with the given `Encode` knobs.
fn pipeline(dir: &Path, name: &str, encode: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            "Pipeline(input: Scene(path: {:?}, scale: 0.001), stages: [Voxelize(resolution: TargetPatches(1500)), FormFactors(samples: 2048), Transport(), Reorder(), Encode({encode})])",
            data("scenes/cornell-box/cornell_box.obj")
        ),
    )
    .unwrap();
    p
}

/// `run --json`: the report's stages that came from the cache, and whether it was up to date.
fn run_json(cwd: &Path, args: &[&str]) -> (Vec<String>, Vec<String>, bool) {
    let mut all = vec!["-q", "--json", "run"];
    all.extend_from_slice(args);
    let o = bake(cwd, &all);
    expect_code(&o, 0);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (mut cached, mut ran) = (Vec::new(), Vec::new());
    for s in v["stages"].as_array().unwrap() {
        let name = s["stage"].as_str().unwrap().to_string();
        if s["cached"].as_bool().unwrap() {
            cached.push(name);
        } else {
            ran.push(name);
        }
    }
    (cached, ran, v["up_to_date"].as_bool().unwrap())
}

/// Bake `pipeline` into `dir/name` without the stage cache.
fn uncached_bake(dir: &Path, pipeline: &Path, name: &str) -> PathBuf {
    let out = dir.join(name);
    let args = [
        "-q",
        "run",
        pipeline.to_str().unwrap(),
        "--no-cache",
        "--out",
        out.to_str().unwrap(),
    ];
    expect_code(&bake(dir, &args), 0);
    out
}

fn same_bake(a: &Path, b: &Path) {
    let (ca, cb) = (contents(a), contents(b));
    let names = |c: &[(String, Vec<u8>)]| c.iter().map(|x| x.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&ca), names(&cb));
    for ((n, x), (_, y)) in ca.iter().zip(&cb) {
        assert!(
            x == y,
            "{n} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn a_killed_bake_resumes_from_its_finished_stages_and_equals_an_uninterrupted_one() {
    let tmp = tempfile::tempdir().unwrap();
    let p = pipeline(tmp.path(), "box.ron", "");
    let ps = p.to_str().unwrap();
    let t0 = Instant::now();
    let reference = uncached_bake(tmp.path(), &p, "reference");
    let full = t0.elapsed().as_secs_f64();
    let out = tmp.path().join("out");
    let os = out.to_str().unwrap();
    let cache = tmp.path().join("cache");
    let cs = cache.to_str().unwrap();
    // Kill moments over the second half of the bake (the first stages are quick), each time from
    // an empty output and cache; resume and compare.
    let mut resumed_stages = 0;
    for k in 0..6 {
        let _ = std::fs::remove_dir_all(&out);
        let _ = std::fs::remove_dir_all(&cache);
        let at = full * (0.35 + 0.6 * k as f64 / 5.0);
        bake_killed_after(
            tmp.path(),
            &["-q", "run", ps, "--out", os, "--cache", cs],
            at,
        );
        let (cached, _, up_to_date) = run_json(tmp.path(), &[ps, "--out", os, "--cache", cs]);
        if !up_to_date {
            resumed_stages += cached.len();
        }
        same_bake(&out, &reference);
        // The cache holds only what belongs to the bake made, and no process's leftovers.
        let leftovers: Vec<String> = list_files(&cache)
            .into_iter()
            .filter(|n| n.contains(".tmp-"))
            .collect();
        assert_eq!(leftovers, Vec::<String>::new());
    }
    eprintln!("6 kills: {resumed_stages} stages reused on resume ({full:.2} s per bake)");
    assert!(
        resumed_stages > 0,
        "no kill landed after a finished stage ({full:.2} s per bake)"
    );
}

#[test]
fn only_the_stages_whose_inputs_changed_run_again() {
    let tmp = tempfile::tempdir().unwrap();
    let a = pipeline(tmp.path(), "a.ron", "");
    let b = pipeline(tmp.path(), "b.ron", "split_percent: 2.0");
    let out = tmp.path().join("out");
    let os = out.to_str().unwrap();
    let (cached, ran, up) = run_json(tmp.path(), &[a.to_str().unwrap(), "--out", os]);
    assert!(cached.is_empty() && !up);
    assert_eq!(
        ran,
        [
            "load",
            "voxelize",
            "form_factors",
            "transport",
            "reorder",
            "encode"
        ]
    );

    // Unchanged: nothing runs, nothing is rewritten.
    let manifest = out.join("manifest.ron");
    let before = std::fs::metadata(&manifest).unwrap().modified().unwrap();
    let o = bake(tmp.path(), &["run", a.to_str().unwrap(), "--out", os]);
    assert!(expect_code(&o, 0).contains("up to date"));
    assert_eq!(
        std::fs::metadata(&manifest).unwrap().modified().unwrap(),
        before
    );

    // Only `Encode` changed: only encode runs, and the bake equals one made from scratch.
    let (cached, ran, _) = run_json(tmp.path(), &[b.to_str().unwrap(), "--out", os]);
    assert_eq!(cached, ["voxelize", "form_factors", "transport", "reorder"]);
    assert_eq!(ran, ["load", "encode"]);
    same_bake(&out, &uncached_bake(tmp.path(), &b, "fresh"));

    // The cache keeps only the stages of the bake just made: going back to `a` reruns encode.
    let (cached, ran, _) = run_json(tmp.path(), &[a.to_str().unwrap(), "--out", os]);
    assert_eq!(cached.len(), 4);
    assert_eq!(ran, ["load", "encode"]);
}

#[test]
fn a_damaged_cache_entry_is_not_used() {
    let tmp = tempfile::tempdir().unwrap();
    let a = pipeline(tmp.path(), "a.ron", "");
    let b = pipeline(tmp.path(), "b.ron", "split_percent: 2.0");
    let out = tmp.path().join("out");
    let os = out.to_str().unwrap();
    run_json(tmp.path(), &[a.to_str().unwrap(), "--out", os]);
    // Flip a byte of the cached transport (a hard link of the bake's file: break the link first
    // so that the bake itself stays intact).
    let cache = tmp.path().join(".relume-cache");
    let file = list_files(&cache)
        .into_iter()
        .find(|n| n.ends_with("transport.npy"))
        .expect("transport is cached");
    let path = cache.join(file);
    let mut bytes = std::fs::read(&path).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 1;
    std::fs::remove_file(&path).unwrap();
    std::fs::write(&path, bytes).unwrap();
    expect_code(&bake(tmp.path(), &["inspect", os]), 0);
    let (cached, ran, _) = run_json(tmp.path(), &[b.to_str().unwrap(), "--out", os]);
    // Transport runs again and writes the same bytes as before, so reorder (keyed on the content
    // of its inputs, not on which stages ran) is reused; encode's knobs changed.
    assert_eq!(cached, ["voxelize", "form_factors", "reorder"]);
    assert_eq!(ran, ["load", "transport", "encode"]);
    same_bake(&out, &uncached_bake(tmp.path(), &b, "fresh"));
}

#[test]
fn a_changed_material_file_invalidates_every_stage() {
    // The scene file is unchanged; only its .mtl differs. The cache keys on the canonical
    // scene, so nothing is reused.
    let tmp = tempfile::tempdir().unwrap();
    for f in ["cornell_box.obj", "cornell_box.mtl"] {
        std::fs::copy(data(&format!("scenes/cornell-box/{f}")), tmp.path().join(f)).unwrap();
    }
    let p = tmp.path().join("p.ron");
    std::fs::write(
        &p,
        "Pipeline(input: Scene(path: \"cornell_box.obj\", scale: 0.001), stages: [Voxelize(resolution: TargetPatches(300)), FormFactors(samples: 256), Transport()])",
    )
    .unwrap();
    let args = [p.to_str().unwrap(), "--out", "out"];
    run_json(tmp.path(), &args);
    let mtl = tmp.path().join("cornell_box.mtl");
    let text = std::fs::read_to_string(&mtl).unwrap();
    let changed = text.replacen("Kd ", "Kd 0.5 0.5 0.5\n#Kd ", 1);
    assert_ne!(text, changed);
    std::fs::write(&mtl, changed).unwrap();
    let (cached, _, up) = run_json(tmp.path(), &args);
    assert!(!up);
    assert_eq!(cached, Vec::<String>::new());
}
