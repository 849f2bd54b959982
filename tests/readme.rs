//! The README's Rust blocks are code that runs: each one is, line for line (indentation
//! aside), in facet-fit's README (run there as its doc test) or in the downstream example
//! (built and run by `tests/downstream.rs`).

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

#[test]
fn readme_rust_blocks_are_tested_code() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let read = |p: &str| std::fs::read_to_string(root.join(p)).unwrap();
    let readme = read("README.md");
    let tested = [
        (
            "crates/fit/README.md",
            normalised(&read("crates/fit/README.md")),
        ),
        (
            "examples/downstream/src/main.rs",
            normalised(&read("examples/downstream/src/main.rs")),
        ),
    ];
    let blocks = rust_blocks(&readme);
    assert!(blocks.len() >= 2, "README: {} rust blocks", blocks.len());
    for block in &blocks {
        let b = normalised(block);
        assert!(
            tested.iter().any(|(_, t)| t.contains(&b)),
            "README block is in none of {:?}:\n{block}",
            tested.map(|(p, _)| p)
        );
    }
}
