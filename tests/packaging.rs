//! What a library user gets from the packages (issue 16): facet-gpu's package carries every WGSL
//! file of `shaders/` (the crates' GPU paths load them at build time), and facet-fit without its
//! default `gpu` feature has no wgpu in its dependency tree. Both ask cargo itself, offline
//! (the test build has fetched everything).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn cargo(args: &[&str]) -> String {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .args(args)
        .current_dir(workspace())
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn wgsl_under(dir: &Path, root: &Path, out: &mut BTreeSet<String>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            wgsl_under(&p, root, out);
        } else if p.extension().is_some_and(|x| x == "wgsl") {
            let rel = p
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            out.insert(format!("shaders/{rel}"));
        }
    }
}

#[test]
fn the_gpu_package_carries_every_shader() {
    let listed: BTreeSet<String> = cargo(&[
        "package",
        "-p",
        "facet-gpu",
        "--list",
        "--allow-dirty",
        "--offline",
    ])
    .lines()
    .map(str::to_owned)
    .collect();
    let mut shaders = BTreeSet::new();
    let root = workspace().join("shaders");
    wgsl_under(&root, &root, &mut shaders);
    assert!(
        shaders.len() > 20,
        "{} WGSL files in shaders/",
        shaders.len()
    );
    let missing: Vec<&String> = shaders.difference(&listed).collect();
    assert!(missing.is_empty(), "facet-gpu's package lacks {missing:?}");
}

#[test]
fn a_cpu_only_facet_fit_builds_no_wgpu() {
    let tree = cargo(&[
        "tree",
        "-p",
        "facet-fit",
        "--no-default-features",
        "-e",
        "normal",
        "--prefix",
        "none",
        "--offline",
    ]);
    let with_gpu = cargo(&[
        "tree",
        "-p",
        "facet-fit",
        "-e",
        "normal",
        "--prefix",
        "none",
        "--offline",
    ]);
    // The check has the power to fail: the default build does pull wgpu in.
    assert!(
        with_gpu.lines().any(|l| l.starts_with("wgpu ")),
        "{with_gpu}"
    );
    let gpu_crates: Vec<&str> = tree
        .lines()
        .filter(|l| l.starts_with("wgpu") || l.starts_with("naga ") || l.starts_with("facet-gpu "))
        .collect();
    assert!(
        gpu_crates.is_empty(),
        "CPU-only facet-fit depends on {gpu_crates:?}"
    );
}
