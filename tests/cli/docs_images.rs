//! The documentation's pictures stay in step with `docs/images/`: every image the README or a
//! `docs/*.md` page links exists, and every file in `docs/images/` is linked somewhere.
//! `make docs-images` regenerates them.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Image targets of Markdown links (`![alt](target)`) and HTML `<img src="target">` in `text`.
fn image_links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(k) = rest.find("![") {
        rest = &rest[k + 2..];
        let Some(close) = rest.find("](") else { break };
        let after = &rest[close + 2..];
        if let Some(end) = after.find(')') {
            out.push(
                after[..end]
                    .split_whitespace()
                    .next()
                    .unwrap_or("")
                    .to_string(),
            );
        }
        rest = after;
    }
    let mut rest = text;
    while let Some(k) = rest.find("<img") {
        rest = &rest[k + 4..];
        if let Some(s) = rest.find("src=\"") {
            let after = &rest[s + 5..];
            if let Some(end) = after.find('"') {
                out.push(after[..end].to_string());
            }
        }
    }
    out
}

fn pages() -> Vec<PathBuf> {
    let mut pages = vec![repo().join("README.md")];
    for e in std::fs::read_dir(repo().join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            pages.push(p);
        }
    }
    pages.sort();
    pages
}

#[test]
fn every_linked_image_exists_and_every_image_is_linked() {
    let mut linked = BTreeSet::new();
    let mut broken = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let base = page.parent().unwrap();
        for link in image_links(&text) {
            if link.starts_with("http://") || link.starts_with("https://") {
                continue;
            }
            let target = base.join(&link);
            match target.canonicalize() {
                Ok(t) => {
                    linked.insert(t);
                }
                Err(_) => broken.push(format!("{} links {link}", page.display())),
            }
        }
    }
    assert!(
        broken.is_empty(),
        "links to missing images:\n{}",
        broken.join("\n")
    );
    let dir = repo().join("docs/images");
    let mut unlinked = Vec::new();
    let mut count = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path().canonicalize().unwrap();
        count += 1;
        if !linked.contains(&p) {
            unlinked.push(p.display().to_string());
        }
    }
    assert!(count > 0, "docs/images is empty: run `make docs-images`");
    assert!(
        unlinked.is_empty(),
        "images in docs/images that no page links (link them or delete them):\n{}",
        unlinked.join("\n")
    );
}

#[test]
fn the_link_reader_finds_markdown_and_html_images() {
    let text =
        "a ![x](images/a.png) b ![y](../b.png \"title\") <img src=\"c.png\" width=3> [not](d.png)";
    assert_eq!(image_links(text), vec!["images/a.png", "../b.png", "c.png"]);
    assert!(Path::new("x").is_relative());
}
