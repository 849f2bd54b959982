//! What `docs/architecture.md` says about the layout, checked where a test can check it:
//! facet-brdf's, facet-fit's and facet-render's folders import only the folders above them (their unit tests
//! aside), and every WGSL file
//! that is not an include is one pipeline with one `@compute` entry point. (That the renderer
//! does not depend on the fitter is Cargo's to enforce; `tests/packaging.rs` checks the tree.)

use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file with extension `ext` under `dir`, recursively.
fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, ext, out);
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}

/// `text` without its `//` comments (doc comments name other layers in prose).
fn code(text: &str) -> String {
    text.lines()
        // A file's unit tests, at its end, may use any layer.
        .take_while(|l| l.trim() != "#[cfg(test)]")
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The layers that `crate::LAYER` paths in `text` name.
fn layers_named(text: &str) -> Vec<String> {
    let code = code(text);
    let mut named = Vec::new();
    for (at, _) in code.match_indices("crate::") {
        // `facet_crate::` is not `crate::`.
        if code[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &code[at + "crate::".len()..];
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        named.push(rest[..end].to_owned());
    }
    named
}

/// The upward imports of a crate whose folders are `layers`, top first: (file, layer named).
fn upward_imports(krate: &str, layers: &[&str]) -> Vec<(String, String)> {
    let src = workspace().join(krate).join("src");
    let mut found = Vec::new();
    for (rank, layer) in layers.iter().enumerate() {
        let mut sources = Vec::new();
        files(&src.join(layer), "rs", &mut sources);
        assert!(!sources.is_empty(), "{krate}: no layer folder `{layer}`");
        for file in sources {
            let text = std::fs::read_to_string(&file).unwrap();
            for named in layers_named(&text) {
                let above = layers[..=rank].contains(&named.as_str()) || named == "error";
                if !above && layers.contains(&named.as_str()) {
                    let rel = file.strip_prefix(workspace()).unwrap();
                    found.push((rel.display().to_string(), named));
                }
            }
        }
    }
    found
}

#[test]
fn each_layer_imports_only_the_layers_above_it() {
    let brdf = ["io", "numerics", "model", "sources"];
    let fit = ["extract", "metric", "gpu", "fitting", "export"];
    let up = upward_imports("crates/brdf", &brdf);
    assert!(up.is_empty(), "facet-brdf imports upward: {up:?}");
    let up = upward_imports("crates/fit", &fit);
    assert!(up.is_empty(), "facet-fit imports upward: {up:?}");
    // facet-render's rooms: the material classes below the resources that upload them; the
    // integrator reads the film back through output/.
    let render = [
        "scene",
        "bvh",
        "layout",
        "materials",
        "resources",
        "output",
        "integrator",
    ];
    let up = upward_imports("crates/render", &render);
    assert!(up.is_empty(), "facet-render imports upward: {up:?}");
    // The check has the power to fail: the same scan finds the export's use of the fitting when
    // the order is reversed.
    let reversed: Vec<&str> = fit.iter().rev().copied().collect();
    assert!(!upward_imports("crates/fit", &reversed).is_empty());
}

#[test]
fn layer_scan_reads_paths_not_prose() {
    let text = "use crate::model::rgb::Rgb; // see crate::fitting\nlet x = facet_crate::io::f;\n\
                #[cfg(test)]\nmod tests { use crate::export::x; }";
    assert_eq!(layers_named(text), ["model"]);
}

/// Every WGSL file that is not an include (`*.inc.wgsl`) is one pipeline: one `@compute` entry.
#[test]
fn every_pipeline_file_has_one_entry_point() {
    let mut wgsl = Vec::new();
    files(&workspace().join("shaders"), "wgsl", &mut wgsl);
    assert!(wgsl.len() > 20, "{} WGSL files", wgsl.len());
    let mut wrong = Vec::new();
    for file in wgsl {
        let name = file.file_name().unwrap().to_string_lossy().into_owned();
        let entries = code(&std::fs::read_to_string(&file).unwrap())
            .matches("@compute")
            .count();
        let expected = if name.ends_with(".inc.wgsl") { 0 } else { 1 };
        if entries != expected {
            wrong.push(format!("{name}: {entries} entry points"));
        }
    }
    assert!(wrong.is_empty(), "{wrong:?}");
}
