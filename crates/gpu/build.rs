//! Embeds every WGSL file under the crate's `shaders/` folder, so that binaries carry their WGSL.
//!
//! In the repository `crates/gpu/shaders` is a symbolic link to `shaders/` at the workspace root,
//! the one copy that is edited; `cargo package` follows the link and writes the files into the
//! package, so a published facet-gpu carries them as a plain folder. Where a checkout has no
//! working symbolic links (Git on Windows without `core.symlinks` writes the link as a one-line
//! text file), the workspace root's `../../shaders` is used instead. Finding no WGSL file at all
//! is a build error: a facet-gpu without shaders would build and then fail on every GPU path.
//!
//! `shaders/tests/` holds the test-only pipelines (probes that read a WGSL include's answers
//! back for a test to compare with the CPU): embedded only with the feature `test-shaders`,
//! which the crates' tests ask for, and left out of the published package.

use std::path::{Path, PathBuf};

/// The test-only pipelines' folder under the shader root.
const TESTS: &str = "tests";

fn collect(dir: &Path, root: &Path, out: &mut Vec<(String, PathBuf)>) -> std::io::Result<()> {
    let with_tests = std::env::var_os("CARGO_FEATURE_TEST_SHADERS").is_some();
    for e in std::fs::read_dir(dir)? {
        let p = e?.path();
        if p.is_dir() {
            if dir == root && p.file_name().is_some_and(|n| n == TESTS) && !with_tests {
                continue;
            }
            collect(&p, root, out)?;
        } else if p.extension().is_some_and(|x| x == "wgsl") {
            let name = p
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            out.push((name, p.canonicalize()?));
        }
    }
    Ok(())
}

fn main() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let candidates = [manifest.join("shaders"), manifest.join("../../shaders")];
    let Some(root) = candidates.iter().find(|p| p.is_dir()) else {
        panic!(
            "facet-gpu: no shader folder: neither {} nor {} is a directory. The WGSL sources \
             live in `shaders/` at the workspace root and reach this crate through the \
             `crates/gpu/shaders` symbolic link (a packaged crate holds them as a folder); \
             restore the link or the folder.",
            candidates[0].display(),
            candidates[1].display()
        );
    };
    println!("cargo:rerun-if-changed={}", root.display());
    let mut files = Vec::new();
    if let Err(e) = collect(root, root, &mut files) {
        panic!(
            "facet-gpu: reading the shaders under {}: {e}",
            root.display()
        );
    }
    if files.is_empty() {
        panic!(
            "facet-gpu: no .wgsl file under {}: every GPU path of Facet would fail at run \
             time; restore the WGSL sources (`shaders/` at the workspace root).",
            root.display()
        );
    }
    files.sort();
    let mut code = String::from(
        "/// Every WGSL file under `shaders/`: (path relative to it, source).\npub static SHADERS: &[(&str, &str)] = &[\n",
    );
    for (name, path) in &files {
        println!("cargo:rerun-if-changed={}", path.display());
        code += &format!(
            "    ({name:?}, include_str!({:?})),\n",
            path.display().to_string()
        );
    }
    code += "];\n";
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap()).join("shaders.rs");
    std::fs::write(out, code).unwrap();
}
