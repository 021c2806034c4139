//! scripts/k8s: the Indexed Job of shards and the merge job hold the fields the Kubernetes Job
//! API requires (read with PyYAML, a cross-check tool), agree with each other (shard count,
//! volume, working directory, paths), and their container commands, run here as Kubernetes would
//! run them (one process per completion index with JOB_COMPLETION_INDEX set, then the merge, per
//! round), bake door-ajar.ron byte-identically to a single `run`.

use crate::common;

use common::{bake, contents, data, expect_code, python, require_python};
use serde_json::Value;
use std::process::Command;

fn load(name: &str) -> Value {
    let path = data(&format!("scripts/k8s/{name}"));
    let json = python(
        "import json, sys, yaml; print(json.dumps(yaml.safe_load(open(sys.argv[1]))))",
        &[path.to_str().unwrap()],
    );
    serde_json::from_str(&json).unwrap()
}

/// The fields the batch/v1 Job API requires or constrains, as the API server validates them.
fn check_job(name: &str, job: &Value) {
    assert_eq!(job["apiVersion"], "batch/v1", "{name}");
    assert_eq!(job["kind"], "Job", "{name}");
    let meta = job["metadata"]["name"].as_str().expect("metadata.name");
    assert!(
        meta.len() <= 63
            && meta
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
            && !meta.starts_with('-')
            && !meta.ends_with('-'),
        "{name}: metadata.name {meta} is not a DNS-1123 label"
    );
    let spec = &job["spec"];
    let pod = &spec["template"]["spec"];
    let restart = pod["restartPolicy"].as_str().unwrap_or("Always");
    assert!(
        restart == "Never" || restart == "OnFailure",
        "{name}: a Job's pods must have restartPolicy Never or OnFailure"
    );
    let completions = spec["completions"].as_u64();
    if spec["completionMode"] == "Indexed" {
        assert!(completions.is_some(), "{name}: Indexed needs completions");
    }
    if let (Some(p), Some(c)) = (spec["parallelism"].as_u64(), completions) {
        assert!(p <= c, "{name}: parallelism over completions");
    }
    if !spec["backoffLimitPerIndex"].is_null() {
        assert_eq!(
            spec["completionMode"], "Indexed",
            "{name}: backoffLimitPerIndex needs Indexed"
        );
        assert_eq!(
            restart, "Never",
            "{name}: backoffLimitPerIndex needs restartPolicy Never"
        );
    }
    if !spec["maxFailedIndexes"].is_null() {
        assert!(
            !spec["backoffLimitPerIndex"].is_null(),
            "{name}: maxFailedIndexes needs backoffLimitPerIndex"
        );
    }
    let containers = pod["containers"].as_array().expect("containers");
    assert!(!containers.is_empty(), "{name}: no container");
    let volumes: Vec<&str> = pod["volumes"]
        .as_array()
        .map(|v| v.iter().filter_map(|v| v["name"].as_str()).collect())
        .unwrap_or_default();
    for c in containers {
        assert!(
            c["name"].is_string() && c["image"].is_string(),
            "{name}: container name and image"
        );
        for m in c["volumeMounts"].as_array().into_iter().flatten() {
            let v = m["name"].as_str().unwrap();
            assert!(
                volumes.contains(&v),
                "{name}: volumeMount {v} has no volume"
            );
            assert!(
                m["mountPath"].as_str().is_some_and(|p| p.starts_with('/')),
                "{name}: mountPath"
            );
        }
    }
}

fn command(job: &Value) -> Vec<String> {
    job["spec"]["template"]["spec"]["containers"][0]["command"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect()
}

#[test]
fn the_kubernetes_jobs_are_valid_and_their_commands_bake_what_a_single_run_bakes() {
    if !require_python(&["yaml"]) {
        return;
    }
    let shards = load("bake-indexed-job.yaml");
    let merge = load("merge-job.yaml");
    check_job("bake-indexed-job.yaml", &shards);
    check_job("merge-job.yaml", &merge);
    assert_eq!(shards["spec"]["completionMode"], "Indexed");
    let n = shards["spec"]["completions"].as_u64().unwrap() as usize;
    let pod = |j: &Value| j["spec"]["template"]["spec"].clone();
    assert_eq!(
        pod(&shards)["volumes"],
        pod(&merge)["volumes"],
        "one shared volume"
    );
    let c = |j: &Value| j["spec"]["template"]["spec"]["containers"][0].clone();
    assert_eq!(c(&shards)["workingDir"], c(&merge)["workingDir"]);
    assert_eq!(c(&shards)["volumeMounts"], c(&merge)["volumeMounts"]);
    let shard_cmd = command(&shards);
    let merge_cmd = command(&merge);
    assert_eq!(shard_cmd[0], "relume-bake");
    assert_eq!(merge_cmd[0], "relume-bake");
    let arg = |cmd: &[String], flag: &str| {
        cmd.iter()
            .position(|a| a == flag)
            .map(|i| cmd[i + 1].clone())
            .unwrap()
    };
    assert_eq!(
        arg(&shard_cmd, "--shards"),
        n.to_string(),
        "--shards equals completions"
    );
    let out = arg(&shard_cmd, "--out");
    assert_eq!(
        merge_cmd[1..],
        ["merge".to_string(), out.clone(), format!("{out}.shards")]
    );

    // Run the commands as Kubernetes would, in a stand-in for the volume.
    let tmp = tempfile::tempdir().unwrap();
    let vol = tmp.path();
    for d in ["pipelines", "scenes"] {
        std::os::unix::fs::symlink(data(d), vol.join(d)).unwrap();
    }
    let bin = env!("CARGO_BIN_EXE_relume-bake");
    for round in 1..=2 {
        let pods: Vec<_> = (0..n)
            .map(|i| {
                Command::new(bin)
                    .args(&shard_cmd[1..])
                    .arg("-q")
                    .env("JOB_COMPLETION_INDEX", i.to_string())
                    .env_remove("SLURM_ARRAY_TASK_ID")
                    .current_dir(vol)
                    .spawn()
                    .unwrap()
            })
            .collect();
        for mut p in pods {
            assert!(
                p.wait().unwrap().success(),
                "round {round}: a shard pod failed"
            );
        }
        let o = Command::new(bin)
            .args(&merge_cmd[1..])
            .current_dir(vol)
            .output()
            .unwrap();
        expect_code(&o, 0);
    }
    let pipeline = shard_cmd[2].clone();
    expect_code(
        &bake(
            vol,
            &["-q", "run", &pipeline, "--out", "single", "--no-cache"],
        ),
        0,
    );
    let (a, b) = (contents(&vol.join("single")), contents(&vol.join(&out)));
    assert!(
        !a.is_empty() && a == b,
        "the merged bake equals the single run"
    );
}
