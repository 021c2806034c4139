//! Keeps docs/architecture.md true: every module of the library belongs to a layer listed there,
//! imports only from layers below its own (or from itself), and no two files import each other
//! through a cycle.
//!
//! The checker reads the sources as text: `use` trees (`use crate::a::{b, c::D}`, `use super::x`)
//! and inline paths (`crate::a::f(..)`, `super::g(..)`) outside comments. A path is resolved to
//! the file that defines its item, following `pub use` re-exports; re-exports themselves are not
//! edges of the cycle check (a `mod.rs` that re-exports its children does not depend on them in
//! the way its children depend on it).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A source tree: module path (`["radiosity", "voxelize"]`) → source text.
type Tree = BTreeMap<Vec<String>, String>;

/// The layers of docs/architecture.md, top to bottom: lines `layer N  name  module module …`.
fn layers_from_doc(doc: &str) -> BTreeMap<String, (u32, String)> {
    let mut out = BTreeMap::new();
    for line in doc.lines() {
        let mut words = line.split_whitespace();
        if words.next() != Some("layer") {
            continue;
        }
        let Some(rank) = words.next().and_then(|r| r.parse::<u32>().ok()) else {
            continue;
        };
        let name = words.next().expect("a layer has a name").to_string();
        for m in words {
            assert!(
                out.insert(m.to_string(), (rank, name.clone())).is_none(),
                "module `{m}` is listed in two layers of docs/architecture.md"
            );
        }
    }
    out
}

fn load_tree(src: &Path) -> Tree {
    let mut tree = Tree::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let p = entry.unwrap().path();
            let rel = p.strip_prefix(src).unwrap();
            if rel.starts_with("bin") {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let mut segs: Vec<String> = rel
                    .iter()
                    .map(|s| s.to_string_lossy().into_owned())
                    .collect();
                let last = segs.pop().unwrap();
                let stem = last.trim_end_matches(".rs");
                if !(stem == "mod" || (segs.is_empty() && stem == "lib")) {
                    segs.push(stem.to_string());
                }
                tree.insert(segs, std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    tree
}

/// Remove `//` comments (line, doc and inner doc) and the contents of string literals.
fn strip(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    let mut in_str = false;
    while i < b.len() {
        let c = b[i] as char;
        if in_str {
            if c == '\\' {
                i += 2;
                continue;
            }
            if c == '"' {
                in_str = false;
                out.push('"');
            } else if c == '\n' {
                out.push('\n');
            }
            i += 1;
            continue;
        }
        if c == '/' && i + 1 < b.len() && b[i + 1] == b'/' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        if c == '\'' {
            // A char literal ('"' or '\'') must not open a string; lifetimes pass through.
            if i + 2 < b.len() && b[i + 2] == b'\'' {
                i += 3;
                continue;
            }
            if i + 3 < b.len() && b[i + 1] == b'\\' && b[i + 3] == b'\'' {
                i += 4;
                continue;
            }
        }
        if c == '"' {
            in_str = true;
        }
        out.push(c);
        i += 1;
    }
    out
}

/// Expand a use tree (`crate::a::{b, c::{D, E as F}, self}`) into paths.
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    fn rec(s: &str, prefix: &[String], out: &mut Vec<Vec<String>>) {
        let s = s.trim();
        if s.is_empty() {
            return;
        }
        if let Some(open) = s.find('{') {
            let head: Vec<String> = s[..open]
                .split("::")
                .map(|x| x.trim().to_string())
                .filter(|x| !x.is_empty())
                .collect();
            let inner = &s[open + 1..s.rfind('}').expect("balanced braces")];
            let mut p = prefix.to_vec();
            p.extend(head);
            let mut depth = 0;
            let mut start = 0;
            for (k, ch) in inner.char_indices() {
                match ch {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        rec(&inner[start..k], &p, out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            rec(&inner[start..], &p, out);
        } else {
            let s = s.split(" as ").next().unwrap();
            let mut p = prefix.to_vec();
            for seg in s.split("::").map(str::trim).filter(|x| !x.is_empty()) {
                if seg != "self" {
                    p.push(seg.to_string());
                }
            }
            out.push(p);
        }
    }
    let mut out = Vec::new();
    rec(tree, &[], &mut out);
    out
}

/// An import found in a file.
struct Import {
    path: Vec<String>,
    reexport: bool,
}

fn imports_of(code: &str) -> Vec<Import> {
    let mut out = Vec::new();
    // `use` statements (possibly spanning lines).
    let mut rest = code;
    while let Some(k) = find_word(rest, "use") {
        let before = rest[..k].trim_end();
        let reexport = before.ends_with("pub") || before.ends_with(')') && before.contains("pub(");
        let end = rest[k..].find(';').map(|e| k + e).unwrap_or(rest.len());
        for path in expand_use(&rest[k + 3..end]) {
            out.push(Import { path, reexport });
        }
        rest = &rest[end..];
    }
    // Inline paths: `crate::a::b(..)`, `super::c`.
    let stmts = strip_use_statements(code);
    for root in ["crate::", "super::"] {
        let mut s = stmts.as_str();
        while let Some(k) = s.find(root) {
            let prev = s[..k].chars().last();
            let tail = &s[k..];
            let len = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            if !prev.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                let path = tail[..len]
                    .split("::")
                    .filter(|x| !x.is_empty())
                    .map(str::to_string)
                    .collect();
                out.push(Import {
                    path,
                    reexport: false,
                });
            }
            s = &tail[len.max(1)..];
        }
    }
    out
}

fn find_word(s: &str, w: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(k) = s[from..].find(w) {
        let k = from + k;
        let before = s[..k].chars().last();
        let after = s[k + w.len()..].chars().next();
        let ident = |c: char| c.is_alphanumeric() || c == '_';
        if !before.is_some_and(ident) && after.is_some_and(|c| c.is_whitespace()) {
            return Some(k);
        }
        from = k + w.len();
    }
    None
}

fn strip_use_statements(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some(k) = find_word(rest, "use") {
        out.push_str(&rest[..k]);
        let end = rest[k..].find(';').map(|e| k + e).unwrap_or(rest.len());
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// Resolve an import of file `from` to (target module file, whether it was absolute).
fn resolve(tree: &Tree, from: &[String], path: &[String]) -> Option<Vec<String>> {
    // `use super::*` is what an inline `mod tests` says of its own file, not an import of the
    // parent module.
    if path.len() == 2 && path[0] == "super" && path[1] == "*" {
        return None;
    }
    let mut module: Vec<String> = match path.first().map(String::as_str) {
        Some("crate") => Vec::new(),
        Some("super") | Some("self") => from.to_vec(),
        _ => return None,
    };
    let mut segs = path;
    // Leading `super::super::…`: a file's `super` is its parent module.
    while let Some(first) = segs.first() {
        match first.as_str() {
            "crate" | "self" => segs = &segs[1..],
            "super" => {
                module.pop()?;
                segs = &segs[1..];
            }
            _ => break,
        }
    }
    follow(tree, module, segs, 0)
}

fn follow(
    tree: &Tree,
    mut module: Vec<String>,
    segs: &[String],
    depth: u32,
) -> Option<Vec<String>> {
    if depth > 16 {
        return Some(module);
    }
    for (k, seg) in segs.iter().enumerate() {
        let mut child = module.clone();
        child.push(seg.clone());
        if tree.contains_key(&child) {
            module = child;
            continue;
        }
        // An item of `module`: follow a `pub use` that names it.
        let code = strip(tree.get(&module)?);
        for imp in imports_of(&code).into_iter().filter(|i| i.reexport) {
            if imp.path.last() == Some(seg) || imp.path.last().is_some_and(|l| l == "*") {
                let mut p = imp.path.clone();
                if p.last().is_some_and(|l| l == "*") {
                    p.pop();
                    p.push(seg.clone());
                }
                let base: Vec<String> = match p.first().map(String::as_str) {
                    Some("crate") | Some("super") | Some("self") => {
                        if let Some(target) = resolve(tree, &module, &p) {
                            return follow(tree, target, &segs[k + 1..], depth + 1);
                        }
                        continue;
                    }
                    // `pub use child::Item` is relative to the module itself.
                    _ => module.clone(),
                };
                if let Some(target) = follow(tree, base, &p, depth + 1) {
                    return Some(target);
                }
            }
        }
        return Some(module);
    }
    Some(module)
}

struct Findings {
    layer_violations: Vec<String>,
    unlisted: BTreeSet<String>,
    cycles: Vec<Vec<String>>,
}

fn check(tree: &Tree, layers: &BTreeMap<String, (u32, String)>) -> Findings {
    let mut f = Findings {
        layer_violations: Vec::new(),
        unlisted: BTreeSet::new(),
        cycles: Vec::new(),
    };
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (module, text) in tree {
        let code = strip(text);
        let Some(top) = module.first() else { continue };
        let Some(&(rank, _)) = layers.get(top) else {
            f.unlisted.insert(top.clone());
            continue;
        };
        for imp in imports_of(&code) {
            let Some(target) = resolve(tree, module, &imp.path) else {
                continue;
            };
            if let Some(ttop) = target.first() {
                if ttop != top {
                    match layers.get(ttop) {
                        Some(&(trank, _)) if trank < rank => {}
                        Some(&(trank, _)) => f.layer_violations.push(format!(
                            "src/{} (layer {rank}) imports {} from `{}` (layer {trank})",
                            module.join("/"),
                            imp.path.join("::"),
                            ttop
                        )),
                        None => {
                            f.unlisted.insert(ttop.clone());
                        }
                    }
                }
            }
            if !imp.reexport && target != *module && !target.is_empty() {
                edges.entry(module.clone()).or_default().insert(target);
            }
        }
    }
    f.cycles = cycles(&edges);
    f
}

/// Strongly connected components with more than one file (Tarjan).
fn cycles(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    struct T<'a> {
        edges: &'a BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        index: BTreeMap<&'a Vec<String>, usize>,
        low: BTreeMap<&'a Vec<String>, usize>,
        stack: Vec<&'a Vec<String>>,
        on: BTreeSet<&'a Vec<String>>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a Vec<String>) {
        t.index.insert(v, t.next);
        t.low.insert(v, t.next);
        t.next += 1;
        t.stack.push(v);
        t.on.insert(v);
        if let Some(ws) = t.edges.get(v) {
            for w in ws {
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let lw = t.low[w];
                    let lv = t.low.get_mut(v).unwrap();
                    *lv = (*lv).min(lw);
                } else if t.on.contains(w) {
                    let iw = t.index[w];
                    let lv = t.low.get_mut(v).unwrap();
                    *lv = (*lv).min(iw);
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(w);
                comp.push(format!("src/{}", w.join("/")));
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            visit(&mut t, v);
        }
    }
    t.out
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn the_library_follows_docs_architecture_md() {
    let doc = std::fs::read_to_string(repo().join("docs/architecture.md")).unwrap();
    let layers = layers_from_doc(&doc);
    assert!(layers.len() >= 10, "docs/architecture.md lists its layers");
    let tree = load_tree(&repo().join("src"));
    let f = check(&tree, &layers);
    assert!(
        f.unlisted.is_empty(),
        "modules missing from the layer table of docs/architecture.md: {:?}",
        f.unlisted
    );
    assert!(
        f.layer_violations.is_empty(),
        "imports from a layer above (docs/architecture.md):\n{}",
        f.layer_violations.join("\n")
    );
    assert!(
        f.cycles.is_empty(),
        "files that import each other in a cycle:\n{:?}",
        f.cycles
    );
    // Every top-level module of lib.rs is in the table, and every module in the table exists.
    let tops: BTreeSet<&String> = tree.keys().filter_map(|k| k.first()).collect();
    for m in layers.keys() {
        assert!(
            tops.contains(m),
            "docs/architecture.md lists `{m}`, which is not a module of src/"
        );
    }
}

fn fixture(files: &[(&str, &str)]) -> Tree {
    files
        .iter()
        .map(|(p, t)| {
            let segs = if p.is_empty() {
                Vec::new()
            } else {
                p.split('/').map(str::to_string).collect()
            };
            (segs, t.to_string())
        })
        .collect()
}

const FIXTURE_LAYERS: &str = "layer 2 app  app\nlayer 1 algo algo\nlayer 0 base base\n";

#[test]
fn the_checker_catches_an_import_from_a_layer_above() {
    let tree = fixture(&[
        ("", "pub mod app; pub mod algo; pub mod base;"),
        ("app", "use crate::algo::run;\n"),
        (
            "algo",
            "pub fn run() {}\n// crate::app::x in a comment is no import\n",
        ),
        ("base", "pub fn f() { crate::app::helper(); }\n"),
    ]);
    let f = check(&tree, &layers_from_doc(FIXTURE_LAYERS));
    assert_eq!(f.layer_violations.len(), 1, "{:?}", f.layer_violations);
    assert!(f.layer_violations[0].contains("src/base"));
    assert!(f.cycles.is_empty());
}

#[test]
fn the_checker_catches_a_cycle_between_files_and_follows_reexports() {
    let tree = fixture(&[
        ("", "pub mod algo;"),
        (
            "algo",
            "pub mod a; pub mod b; pub mod c;\npub use c::Thing;\n",
        ),
        ("algo/a", "use super::b::{B, other::{X}};\n"),
        ("algo/b", "use crate::algo::Thing; // re-exported from c\n"),
        ("algo/c", "pub struct Thing; fn f() { super::a::g(); }\n"),
    ]);
    let f = check(&tree, &layers_from_doc("layer 0 algo algo\n"));
    assert!(f.layer_violations.is_empty());
    assert_eq!(
        f.cycles,
        vec![vec![
            "src/algo/a".to_string(),
            "src/algo/b".to_string(),
            "src/algo/c".to_string()
        ]]
    );
    // Without the back edge there is no cycle: the mod.rs re-export is not an edge.
    let tree = fixture(&[
        ("", "pub mod algo;"),
        (
            "algo",
            "pub mod a; pub mod b; pub mod c;\npub use c::Thing;\n",
        ),
        ("algo/a", "use super::b::B;\n"),
        ("algo/b", "use crate::algo::Thing;\n"),
        ("algo/c", "pub struct Thing;\n"),
    ]);
    assert!(check(&tree, &layers_from_doc("layer 0 algo algo\n"))
        .cycles
        .is_empty());
}

mod folders;
