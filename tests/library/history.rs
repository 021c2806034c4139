//! Comments and docs a newcomer can follow: papers cited by author and year, measurements by the
//! command that reproduces them, never the project's own history ("stop 46", "issue 14").

use std::path::PathBuf;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Phrases that name the project's own history instead of the papers or a measurement.
fn history_words(text: &str) -> Vec<String> {
    let lower = text.to_lowercase();
    let mut found = Vec::new();
    for phrase in ["the seed", "seed's", "seed fog", "seed model"] {
        for (k, _) in lower.match_indices(phrase) {
            let after = lower[k + phrase.len()..].chars().next();
            if !lower[k..].starts_with("the seed corpus")
                && !after.is_some_and(|c| c.is_alphanumeric())
            {
                found.push(phrase.to_string());
            }
        }
    }
    for word in ["stop ", "stops ", "issue ", "issues "] {
        for (k, _) in lower.match_indices(word) {
            let before = lower[..k].chars().last();
            let after = lower[k + word.len()..].chars().next();
            if !before.is_some_and(|c| c.is_alphanumeric() || c == '-')
                && after.is_some_and(|c| c.is_ascii_digit())
            {
                found.push(format!("{word}N"));
            }
        }
    }
    found
}

#[test]
fn comments_and_docs_cite_papers_not_project_history() {
    let mut hits = Vec::new();
    let mut stack = vec![
        repo().join("src"),
        repo().join("docs"),
        repo().join("shaders"),
    ];
    let mut files = vec![repo().join("README.md")];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p
                .extension()
                .is_some_and(|e| e == "rs" || e == "md" || e == "wgsl")
            {
                files.push(p);
            }
        }
    }
    for p in files {
        let text = std::fs::read_to_string(&p).unwrap();
        for (n, line) in text.lines().enumerate() {
            for w in history_words(line) {
                hits.push(format!(
                    "{}:{}: {w}",
                    p.strip_prefix(repo()).unwrap().display(),
                    n + 1
                ));
            }
        }
    }
    assert!(
        hits.is_empty(),
        "project history where a newcomer needs the paper (author, year) or the command that \
         measures it:\n{}",
        hits.join("\n")
    );
    assert_eq!(history_words("as stop 46 measured"), vec!["stop N"]);
    assert_eq!(history_words("the seed's fog"), vec!["the seed", "seed's"]);
    assert!(history_words("a non-stop 3 and the seed corpus, the seeded rng, seed: 0").is_empty());
}
