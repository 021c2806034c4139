//! Helpers of the `relume-bake study` tests: run a quick study with the real binary and read
//! its report (sweeps, settings, errors), checking the files it writes on the way.

use super::{bake, expect_code};
use serde_json::Value;
use std::path::Path;

/// Run a quick study into `dir/out` with `--json`; returns the parsed stdout, after checking
/// that it equals `study.json`.
pub fn study(dir: &Path, args: &[&str]) -> Value {
    let out = dir.join("out");
    let mut all = vec!["study"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--quick", "--json", "--out", out.to_str().unwrap()]);
    let o = bake(dir, &all);
    expect_code(&o, 0);
    let printed: Value = serde_json::from_slice(&o.stdout).expect("stdout is JSON");
    let file: Value =
        serde_json::from_slice(&std::fs::read(out.join("study.json")).unwrap()).unwrap();
    assert_eq!(printed, file);
    check_files(&out, &file);
    file
}

pub fn sweep<'a>(j: &'a Value, name: &str) -> &'a Value {
    j["sweeps"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no sweep {name}"))
}

pub fn settings(s: &Value) -> &Vec<Value> {
    s["settings"].as_array().unwrap()
}

pub fn labels(s: &Value) -> Vec<&str> {
    settings(s)
        .iter()
        .map(|x| x["label"].as_str().unwrap())
        .collect()
}

pub fn setting<'a>(s: &'a Value, label: &str) -> &'a Value {
    settings(s)
        .iter()
        .find(|x| x["label"] == label)
        .unwrap_or_else(|| panic!("no setting {label} in {}", s["name"]))
}

pub fn err(s: &Value, quantity: &str, metric: &str) -> f64 {
    s["errors"][quantity][metric]
        .as_f64()
        .unwrap_or_else(|| panic!("{quantity}.{metric} of {}", s["label"]))
}

/// Every error number and byte count is finite and non-negative and every setting took
/// measurable time. (A reference's error against itself is 0 by construction and not checked:
/// each sweep's test checks its reference against an independent value instead.)
pub fn check_numbers(j: &Value) {
    for sw in j["sweeps"].as_array().unwrap() {
        for s in settings(sw) {
            let t = s["seconds"].as_f64().unwrap();
            assert!(t > 0.0 && t.is_finite(), "{} took {t} s", s["label"]);
            assert!(s["bytes"].as_u64().is_some());
            for (q, e) in s["errors"].as_object().unwrap() {
                for (m, v) in e.as_object().unwrap() {
                    let v = v
                        .as_f64()
                        .unwrap_or_else(|| panic!("{q}.{m} of {} is not a number", s["label"]));
                    assert!(v.is_finite() && v >= 0.0, "{q}.{m} of {} = {v}", s["label"]);
                }
            }
        }
    }
}

/// study.md has a table per sweep with one row per setting; every listed plot decodes to a
/// 960x600 image that is not blank.
pub fn check_files(out: &Path, j: &Value) {
    let md = std::fs::read_to_string(out.join("study.md")).unwrap();
    for sw in j["sweeps"].as_array().unwrap() {
        let title = format!("## {}", sw["title"].as_str().unwrap());
        let at = md
            .find(&title)
            .unwrap_or_else(|| panic!("no {title} in study.md"));
        let rows = md[at..]
            .lines()
            .skip_while(|l| !l.starts_with("| setting |"))
            .skip(2)
            .take_while(|l| l.starts_with('|'))
            .count();
        assert_eq!(rows, settings(sw).len(), "table rows of {title}");
        for p in sw["plots"].as_array().unwrap() {
            let file = p["file"].as_str().unwrap();
            assert!(md.contains(&format!("]({file})")), "study.md links {file}");
            let img = image::open(out.join(file)).unwrap().to_rgb8();
            assert_eq!(img.dimensions(), (960, 600), "{file}");
            let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
            let ink = img.pixels().filter(|p| p.0 != [255, 255, 255]).count();
            assert!(colours.len() >= 4 && ink > 5_000, "{file} looks blank");
        }
    }
    let listed: Vec<&str> = j["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    for f in &listed {
        assert!(out.join(f).is_file(), "{f} listed but missing");
    }
    assert!(listed.contains(&"study.md") && listed.contains(&"study.json"));
}
