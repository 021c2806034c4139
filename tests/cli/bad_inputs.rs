//! The bad-input corpus in `tests/bad-inputs/`, discovered from the directory.
//!
//! Every `NAME.case.ron` there is one case: the command to run (`relume-bake` or
//! `relume-player`), the exit code it must end with, and fragments its stderr must contain.
//! `{input}` in the arguments is the file `NAME` beside the sidecar, `{dir}` the corpus
//! directory, `{out}` an output path in a fresh work directory, `{bake}` a bake made from one of
//! the corpus's base pipelines and then tampered with as the case says. After every run the work
//! directory must be empty (no partial output) and the process must not have panicked. Every
//! other file of the directory must be used by some case, so the corpus cannot rot.

use crate::common;

use common::{list_files, text};
use relume::error::exit;
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// The corpus must stay at least this large.
const MIN_CASES: usize = 40;

#[derive(Deserialize, Clone, Copy, Debug, Default, PartialEq)]
#[serde(rename_all = "lowercase")]
enum Tool {
    #[default]
    Bake,
    Player,
}

#[derive(Deserialize, Clone, Copy, Debug)]
#[serde(rename_all = "lowercase")]
enum Code {
    Ok,
    Usage,
    Input,
    Io,
    Limit,
    Unsupported,
    Verify,
}

impl Code {
    fn value(self) -> i32 {
        match self {
            Code::Ok => exit::OK,
            Code::Usage => exit::USAGE,
            Code::Input => exit::INPUT,
            Code::Io => exit::IO,
            Code::Limit => exit::LIMIT,
            Code::Unsupported => exit::UNSUPPORTED,
            Code::Verify => exit::VERIFY,
        }
    }
}

/// One way to damage a file of a fresh bake.
#[derive(Deserialize, Clone, Debug)]
enum Edit {
    /// Cut the file to this many bytes.
    Truncate(String, u64),
    /// Delete the file.
    Remove(String),
    /// Replace the file by a corpus file: (corpus file, bake file).
    Copy(String, String),
    /// Replace the file by the same file of another base bake: (base pipeline, bake file).
    FromBase(String, String),
    /// Rename a file of the bake over another: (from, to).
    Move(String, String),
    /// XOR one byte at this offset with 0xff.
    Flip(String, u64),
}

#[derive(Deserialize, Clone, Debug)]
struct Tamper {
    /// A pipeline in the corpus directory whose bake is damaged.
    base: String,
    edits: Vec<Edit>,
}

#[derive(Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
struct Case {
    #[serde(default)]
    tool: Tool,
    args: Vec<String>,
    code: Code,
    mentions: Vec<String>,
    #[serde(default)]
    tamper: Option<Tamper>,
}

fn corpus_dir() -> PathBuf {
    common::data("tests/bad-inputs")
}

/// All cases, by sidecar name.
fn cases() -> BTreeMap<String, Case> {
    let mut out = BTreeMap::new();
    for e in std::fs::read_dir(corpus_dir()).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if let Some(stem) = name.strip_suffix(".case.ron") {
            let text = std::fs::read_to_string(e.path()).unwrap();
            let case: Case = ron::Options::default()
                .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
                .from_str(&text)
                .unwrap_or_else(|err| panic!("{name}: bad sidecar: {err}"));
            out.insert(stem.to_string(), case);
        }
    }
    out
}

/// Bakes of the base pipelines, made once per test process (they are read-only inputs; each
/// case tampers with its own copy).
fn base_bake(base: &str) -> PathBuf {
    static BAKES: Mutex<BTreeMap<String, PathBuf>> = Mutex::new(BTreeMap::new());
    let mut bakes = BAKES.lock().unwrap();
    if let Some(p) = bakes.get(base) {
        return p.clone();
    }
    let root = std::env::temp_dir().join(format!("relume-bad-inputs-{}", std::process::id()));
    std::fs::create_dir_all(&root).unwrap();
    let out = root.join(base.trim_end_matches(".ron"));
    let _ = std::fs::remove_dir_all(&out);
    let o = common::bake(
        &root,
        &[
            "run",
            "-q",
            corpus_dir().join(base).to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    );
    common::expect_code(&o, 0);
    bakes.insert(base.to_string(), out.clone());
    out
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

/// A damaged copy of a base bake in `scratch`.
fn tampered(t: &Tamper, scratch: &Path) -> PathBuf {
    let dir = scratch.join("bake");
    copy_dir(&base_bake(&t.base), &dir);
    for e in &t.edits {
        match e {
            Edit::Truncate(f, n) => {
                let file = std::fs::OpenOptions::new()
                    .write(true)
                    .open(dir.join(f))
                    .unwrap();
                assert!(
                    file.metadata().unwrap().len() > *n,
                    "{f} is not longer than {n}"
                );
                file.set_len(*n).unwrap();
            }
            Edit::Remove(f) => std::fs::remove_file(dir.join(f)).unwrap(),
            Edit::Copy(src, f) => {
                std::fs::copy(corpus_dir().join(src), dir.join(f)).unwrap();
            }
            Edit::FromBase(base, f) => {
                std::fs::copy(base_bake(base).join(f), dir.join(f)).unwrap();
            }
            Edit::Move(from, to) => std::fs::rename(dir.join(from), dir.join(to)).unwrap(),
            Edit::Flip(f, at) => {
                let mut b = std::fs::read(dir.join(f)).unwrap();
                b[*at as usize] ^= 0xff;
                std::fs::write(dir.join(f), b).unwrap();
            }
        }
    }
    dir
}

fn run_case(name: &str, case: &Case) -> Result<(), String> {
    let corpus = corpus_dir();
    let work = tempfile::tempdir().unwrap();
    let scratch = tempfile::tempdir().unwrap();
    let bake_dir = case.tamper.as_ref().map(|t| tampered(t, scratch.path()));
    let input = corpus.join(name);
    let args: Vec<String> = case
        .args
        .iter()
        .map(|a| {
            if a.contains("{input}") {
                assert!(input.exists(), "{name}: {{input}} but no file {name}");
            }
            if a.contains("{bake}") {
                assert!(bake_dir.is_some(), "{name}: {{bake}} without `tamper`");
            }
            a.replace("{input}", input.to_str().unwrap())
                .replace("{dir}", corpus.to_str().unwrap())
                .replace("{out}", work.path().join("out").to_str().unwrap())
                .replace(
                    "{bake}",
                    bake_dir
                        .as_deref()
                        .unwrap_or(Path::new(""))
                        .to_str()
                        .unwrap(),
                )
        })
        .collect();
    let exe = match case.tool {
        Tool::Bake => env!("CARGO_BIN_EXE_relume-bake"),
        Tool::Player => env!("CARGO_BIN_EXE_relume-player"),
    };
    let o = Command::new(exe)
        .args(&args)
        .current_dir(work.path())
        .env("WGPU_BACKEND", "vulkan")
        .output()
        .expect("the binary runs");
    let stderr = String::from_utf8_lossy(&o.stderr);
    let mut problems = Vec::new();
    if o.status.code() != Some(case.code.value()) {
        problems.push(format!(
            "exit code {:?}, expected {}",
            o.status.code(),
            case.code.value()
        ));
    }
    if stderr.contains("panicked") {
        problems.push("it panicked".into());
    }
    for m in &case.mentions {
        if !stderr.contains(m.as_str()) {
            problems.push(format!("stderr lacks {m:?}"));
        }
    }
    let left = list_files(work.path());
    if !left.is_empty() {
        problems.push(format!("left output behind: {left:?}"));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{name} ({:?} {}): {}\n{}",
            case.tool,
            args.join(" "),
            problems.join("; "),
            text(&o)
        ))
    }
}

#[test]
fn every_case_of_the_corpus_gives_a_clear_error_and_no_output() {
    let cases = cases();
    assert!(
        cases.len() >= MIN_CASES,
        "the corpus has {} cases, fewer than {MIN_CASES}",
        cases.len()
    );
    if cases.values().any(|c| c.tool == Tool::Player) && common::gpu().is_none() {
        return; // common::gpu() has failed the test under CI, or said SKIP
    }
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|(name, case)| run_case(name, case).err())
        .collect();
    let root = std::env::temp_dir().join(format!("relume-bad-inputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(root);
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n\n")
    );
}

#[test]
fn every_file_of_the_corpus_is_used_by_a_case() {
    let cases = cases();
    let mut used: BTreeSet<String> = ["generate.py", "README.md"].map(String::from).into();
    for (name, case) in &cases {
        used.insert(format!("{name}.case.ron"));
        if case.args.iter().any(|a| a.contains("{input}")) {
            used.insert(name.clone());
        }
        for a in &case.args {
            if let Some(rest) = a.strip_prefix("{dir}/") {
                used.insert(rest.to_string());
            }
        }
        if let Some(t) = &case.tamper {
            used.insert(t.base.clone());
            for e in &t.edits {
                match e {
                    Edit::Copy(src, _) => {
                        used.insert(src.clone());
                    }
                    Edit::FromBase(base, _) => {
                        used.insert(base.clone());
                    }
                    _ => {}
                }
            }
        }
    }
    // An OBJ's material library and the textures it names are used with it.
    for name in used.clone() {
        if name.ends_with(".obj") {
            let obj = std::fs::read_to_string(corpus_dir().join(&name)).unwrap_or_default();
            for mtl in obj.lines().filter_map(|l| l.strip_prefix("mtllib ")) {
                used.insert(mtl.trim().to_string());
                let text =
                    std::fs::read_to_string(corpus_dir().join(mtl.trim())).unwrap_or_default();
                for l in text.lines().filter(|l| l.trim_start().starts_with("map_")) {
                    if let Some(file) = l.split_whitespace().last() {
                        used.insert(file.to_string());
                    }
                }
            }
        }
    }
    let unused: Vec<String> = list_files(&corpus_dir())
        .into_iter()
        .filter(|f| !used.contains(f))
        .collect();
    assert!(unused.is_empty(), "corpus files no case uses: {unused:?}");
}
