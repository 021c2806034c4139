//! Every fuzz corpus seed (`fuzz/corpus/<target>/`) and every input a fuzzer once crashed or hung
//! on (`fuzz/regressions/<target>/`, each a fixed bug) goes through the same harness the AFL
//! targets use (`fuzz/src/targets.rs`), here without AFL: none may panic. An abort (an
//! allocation the input made up) ends this test binary, which fails too.

#[allow(dead_code)]
#[path = "../../fuzz/src/targets.rs"]
mod targets;

use crate::common;

use std::panic::{catch_unwind, AssertUnwindSafe};

#[test]
fn fuzz_corpora_and_found_crashes_are_handled_without_panics() {
    let mut failures = Vec::new();
    let mut count = 0;
    for (name, target) in targets::TARGETS {
        let mut inputs = Vec::new();
        for kind in ["corpus", "regressions"] {
            let dir = common::data(&format!("fuzz/{kind}/{name}"));
            if let Ok(rd) = std::fs::read_dir(&dir) {
                inputs.extend(rd.flatten().map(|e| e.path()));
            }
        }
        assert!(!inputs.is_empty(), "no corpus for fuzz target {name}");
        inputs.sort();
        for input in inputs {
            let bytes = std::fs::read(&input).unwrap();
            count += 1;
            if catch_unwind(AssertUnwindSafe(|| target(&bytes))).is_err() {
                failures.push(input.display().to_string());
            }
        }
    }
    assert!(count >= 40, "only {count} fuzz inputs");
    assert!(failures.is_empty(), "panicked on: {failures:#?}");
}
