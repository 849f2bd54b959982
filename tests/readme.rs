//! The Rust blocks of the README and of the manual under `docs/` are code that runs: each one
//! is, line for line (indentation aside), in facet-fit's README (run there as its doc test) or
//! in the downstream example (built and run by `tests/downstream.rs`). Only blocks whose info
//! string is exactly `rust` are checked; fence a block that is not meant to compile as `text`
//! (or `rust,ignore`).

use std::path::{Path, PathBuf};

fn normalised(text: &str) -> String {
    text.lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join("\n")
}

/// The bodies of the fenced blocks whose info string is `rust`.
fn rust_blocks(markdown: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in markdown.lines() {
        match (&mut current, line.trim_start().strip_prefix("```")) {
            (None, Some(info)) if info.trim() == "rust" => current = Some(String::new()),
            (Some(_), Some(_)) => blocks.push(current.take().unwrap()),
            (Some(body), None) => {
                body.push_str(line);
                body.push('\n');
            }
            _ => {}
        }
    }
    blocks
}

/// Every `.md` file under `dir`, depth first, sorted (none when `dir` does not exist, as in a
/// packaged crate, which leaves `docs/` out).
fn markdown_under(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut paths: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
    paths.sort();
    let mut files = Vec::new();
    for path in paths {
        if path.is_dir() {
            files.extend(markdown_under(&path));
        } else if path.extension().is_some_and(|e| e == "md") {
            files.push(path);
        }
    }
    files
}

#[test]
fn readme_rust_blocks_are_tested_code() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let read = |p: &Path| std::fs::read_to_string(root.join(p)).unwrap();
    let tested = [
        (
            "crates/fit/README.md",
            normalised(&read(Path::new("crates/fit/README.md"))),
        ),
        (
            "examples/downstream/src/main.rs",
            normalised(&read(Path::new("examples/downstream/src/main.rs"))),
        ),
    ];
    let mut files = vec![root.join("README.md")];
    files.extend(markdown_under(&root.join("docs")));
    let mut checked = 0;
    for file in &files {
        let name = file.strip_prefix(root).unwrap().display();
        let blocks = rust_blocks(&read(file));
        if file.ends_with("README.md") {
            assert!(!blocks.is_empty(), "{name}: no rust block");
        }
        for block in &blocks {
            let b = normalised(block);
            assert!(
                tested.iter().any(|(_, t)| t.contains(&b)),
                "a rust block of {name} is in none of {:?} (fence it as `text` if it is not \
                 meant to compile):\n{block}",
                tested.map(|(p, _)| p)
            );
        }
        checked += blocks.len();
    }
    assert!(
        checked >= 2,
        "{checked} rust blocks in {} files",
        files.len()
    );
}
