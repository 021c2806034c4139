//! The folders inside modules: the tree drawn in docs/architecture.md equals src/'s folders, and
//! the children of a module with folders import only from children below them (its `within`
//! line).

use super::{fixture, imports_of, load_tree, repo, resolve, strip, Tree};
use std::collections::{BTreeMap, BTreeSet};

/// The layers inside modules with folders: lines `within a::b  x y < z < w` of
/// docs/architecture.md (bottom to top; names in one group share a rank).
type Within = BTreeMap<Vec<String>, BTreeMap<String, u32>>;

fn within_from_doc(doc: &str) -> Within {
    let mut out = Within::new();
    for line in doc.lines() {
        let mut words = line.split_whitespace();
        if words.next() != Some("within") {
            continue;
        }
        let module: Vec<String> = words
            .next()
            .expect("a `within` line names its module")
            .split("::")
            .map(str::to_string)
            .collect();
        let mut ranks = BTreeMap::new();
        let mut rank = 0;
        for w in words {
            if w == "<" {
                rank += 1;
            } else {
                assert!(
                    ranks.insert(w.to_string(), rank).is_none(),
                    "`{w}` is listed twice in the `within {}` line",
                    module.join("::")
                );
            }
        }
        assert!(out.insert(module, ranks).is_none(), "two `within` lines");
    }
    out
}

/// Imports between the children of a module against its `within` line; children missing from
/// the line, and listed children that do not exist.
fn check_within(tree: &Tree, within: &Within) -> (Vec<String>, Vec<String>) {
    let (mut violations, mut unlisted) = (Vec::new(), Vec::new());
    for (m, ranks) in within {
        let children: BTreeSet<&String> = tree
            .keys()
            .filter(|k| k.len() > m.len() && k.starts_with(m))
            .map(|k| &k[m.len()])
            .collect();
        for c in &children {
            if !ranks.contains_key(*c) {
                unlisted.push(format!("src/{}/{c}", m.join("/")));
            }
        }
        for c in ranks.keys() {
            if !children.contains(c) {
                unlisted.push(format!(
                    "`within {}` lists `{c}`, which does not exist",
                    m.join("::")
                ));
            }
        }
        for (file, text) in tree
            .iter()
            .filter(|(k, _)| k.len() > m.len() && k.starts_with(m))
        {
            let here = &file[m.len()];
            let Some(&rank) = ranks.get(here) else {
                continue;
            };
            for imp in imports_of(&strip(text)) {
                let Some(t) = resolve(tree, file, &imp.path) else {
                    continue;
                };
                if t.len() <= m.len() || !t.starts_with(m) || &t[m.len()] == here {
                    continue;
                }
                match ranks.get(&t[m.len()]) {
                    Some(&r) if r <= rank && (r < rank || !is_folder(tree, m, here)) => {}
                    _ => violations.push(format!(
                        "src/{} imports {} from `{}` (not below `{here}` in `within {}`)",
                        file.join("/"),
                        imp.path.join("::"),
                        t[m.len()],
                        m.join("::")
                    )),
                }
            }
        }
    }
    (violations, unlisted)
}

/// Whether child `c` of module `m` is a folder (has children of its own).
fn is_folder(tree: &Tree, m: &[String], c: &str) -> bool {
    tree.keys()
        .any(|k| k.len() > m.len() + 1 && k.starts_with(m) && k[m.len()] == c)
}

/// The folders of the tree drawn in docs/architecture.md (`src/` indented by two spaces a level).
fn folders_from_doc(doc: &str) -> BTreeSet<String> {
    let start = doc
        .find("## The tree")
        .expect("docs/architecture.md draws the tree");
    let block = &doc[start..];
    let open = block.find("```text\n").expect("the tree is a text block") + 8;
    let close = open + block[open..].find("```").unwrap();
    let mut stack: Vec<String> = Vec::new();
    let mut out = BTreeSet::new();
    for line in block[open..close].lines() {
        let depth = (line.len() - line.trim_start().len()) / 2;
        let Some(name) = line.split_whitespace().next().filter(|n| n.ends_with('/')) else {
            continue;
        };
        stack.truncate(depth);
        stack.push(name.trim_end_matches('/').to_string());
        out.insert(stack.join("/"));
    }
    out
}

#[test]
fn the_folders_follow_docs_architecture_md() {
    let doc = std::fs::read_to_string(repo().join("docs/architecture.md")).unwrap();
    let drawn = folders_from_doc(&doc);
    let mut real = BTreeSet::new();
    let mut stack = vec![repo().join("src")];
    while let Some(dir) = stack.pop() {
        real.insert(
            dir.strip_prefix(repo())
                .unwrap()
                .to_string_lossy()
                .into_owned(),
        );
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            }
        }
    }
    let missing: Vec<_> = real.difference(&drawn).collect();
    let stale: Vec<_> = drawn.difference(&real).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "the tree of docs/architecture.md misses folders {missing:?} and names folders that do \
         not exist {stale:?}"
    );

    let tree = load_tree(&repo().join("src"));
    let within = within_from_doc(&doc);
    // Every module with a folder inside it has a `within` line.
    for dir in &real {
        let segs: Vec<String> = dir.split('/').skip(1).map(str::to_string).collect();
        if segs.len() >= 2 && segs[0] != "bin" {
            let parent = segs[..segs.len() - 1].to_vec();
            assert!(
                within.contains_key(&parent),
                "src/{} has folders inside it but no `within {}` line in docs/architecture.md",
                parent.join("/"),
                parent.join("::")
            );
        }
    }
    let (violations, unlisted) = check_within(&tree, &within);
    assert!(
        unlisted.is_empty(),
        "children missing from (or stale in) the `within` lines of docs/architecture.md:\n{}",
        unlisted.join("\n")
    );
    assert!(
        violations.is_empty(),
        "imports against the `within` lines of docs/architecture.md:\n{}",
        violations.join("\n")
    );
}

#[test]
fn the_within_checker_catches_an_import_from_a_folder_above() {
    let tree = fixture(&[
        ("", "pub mod t;"),
        ("t", "pub mod hard; pub mod horizon; pub struct Root;"),
        ("t/hard", "pub mod walk;"),
        (
            "t/hard/walk",
            "use crate::t::horizon::Map; use crate::t::Root;\n",
        ),
        (
            "t/horizon",
            "pub struct Map; fn f() { crate::t::hard::walk::g(); }\n",
        ),
    ]);
    let within = within_from_doc("within t  hard < horizon\n");
    let (violations, unlisted) = check_within(&tree, &within);
    assert!(unlisted.is_empty(), "{unlisted:?}");
    assert_eq!(violations.len(), 1, "{violations:?}");
    assert!(violations[0].contains("src/t/hard/walk"));
    let (_, unlisted) = check_within(&tree, &within_from_doc("within t  hard\n"));
    assert_eq!(unlisted, vec!["src/t/horizon".to_string()]);
}
