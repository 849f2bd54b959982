//! What a library user gets from the packages (issue 16): facet-gpu's package carries every
//! production WGSL file of `shaders/` (the crates' GPU paths load them at build time) and none
//! of the test-only ones, facet-fit without its default `gpu` feature has no wgpu in its
//! dependency tree, and the renderer's has no fitter (issue 61). Both ask cargo itself, offline
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
    // The test-only pipelines (shaders/tests/) stay in the repository.
    let (tests, production): (BTreeSet<String>, BTreeSet<String>) = shaders
        .into_iter()
        .partition(|s| s.starts_with("shaders/tests/"));
    assert!(!tests.is_empty(), "no test-only pipeline in shaders/tests/");
    let missing: Vec<&String> = production.difference(&listed).collect();
    assert!(missing.is_empty(), "facet-gpu's package lacks {missing:?}");
    let shipped: Vec<&String> = tests.intersection(&listed).collect();
    assert!(shipped.is_empty(), "facet-gpu's package ships {shipped:?}");
}

/// The renderer and the glint crate depend on facet-brdf, not on the fitter: their normal
/// dependency trees hold no facet-fit (the viewer's, an application, does).
#[test]
fn the_renderer_depends_on_no_fitter() {
    let tree = |package: &str| {
        cargo(&[
            "tree",
            "-p",
            package,
            "-e",
            "normal",
            "--prefix",
            "none",
            "--offline",
        ])
    };
    let has = |tree: &str, name: &str| tree.lines().any(|l| l.starts_with(&format!("{name} ")));
    // The check has the power to fail: the viewer's tree does hold the fitter.
    assert!(has(&tree("facet-viewer"), "facet-fit"));
    for package in ["facet-render", "facet-glint"] {
        let t = tree(package);
        assert!(has(&t, "facet-brdf"), "{package}: {t}");
        assert!(
            !has(&t, "facet-fit"),
            "{package} depends on facet-fit:\n{t}"
        );
    }
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
