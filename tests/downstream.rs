//! A library user's program: `examples/downstream/`, a crate outside the workspace that uses
//! facet-fit, facet-glint and facet-render through their public API only. This test builds it
//! with cargo the way its user would (its own manifest and workspace), runs it, and checks what
//! it wrote: the fit JSON loads, the PNG decodes and shows an image (not one flat value).
//!
//! It renders on the default adapter, so without one it skips with a visible `SKIPPED` line
//! (`facet_gpu::gpu_for_tests`), unless FACET_REQUIRE_GPU=1, and skips before building.
//!
//! The example builds into the workspace's own target folder (`FACET_DOWNSTREAM_TARGET` names
//! another), so that it reuses what the workspace built where the two resolve a dependency to
//! the same package and features. That is safe: `cargo test` has released the folder's lock by
//! the time the tests run (the nested build takes it), and facet-fit, facet-gpu, ... have the
//! same package ids from both sides (the same paths), so their build scripts and outputs are
//! shared, never stale. Dependencies whose features unify differently outside the workspace
//! (naga, serde_derive, ...) build once more; a first run takes minutes on 2 cores, later runs
//! seconds. The workspace's `Cargo.lock` is copied next to the example first, so that both
//! resolve the same versions.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The target folder of the example's build.
fn downstream_target() -> PathBuf {
    if let Some(dir) = std::env::var_os("FACET_DOWNSTREAM_TARGET").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir);
    }
    // CARGO_TARGET_TMPDIR is `<target>/tmp`.
    Path::new(env!("CARGO_TARGET_TMPDIR"))
        .parent()
        .expect("CARGO_TARGET_TMPDIR has a parent")
        .to_path_buf()
}

fn run(cmd: &mut Command, what: &str) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

#[test]
fn downstream_example_fits_saves_loads_and_renders() {
    // Only the question "is there an adapter?"; the example opens its own.
    if facet_gpu::gpu_for_tests("downstream_example_fits_saves_loads_and_renders").is_none() {
        return;
    }
    let example = workspace().join("examples/downstream");
    let lock = std::fs::read(workspace().join("Cargo.lock")).unwrap();
    let example_lock = example.join("Cargo.lock");
    if std::fs::read(&example_lock).ok().as_deref() != Some(&lock[..]) {
        std::fs::write(&example_lock, &lock).unwrap();
    }
    let target = downstream_target();
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    run(
        Command::new(&cargo)
            .arg("build")
            .arg("--manifest-path")
            .arg(example.join("Cargo.toml"))
            .env("CARGO_TARGET_DIR", &target),
        "cargo build of examples/downstream",
    );

    let out = common::scratch("downstream");
    let exe = target
        .join("debug")
        .join(format!("facet-downstream{}", std::env::consts::EXE_SUFFIX));
    let stdout = run(Command::new(&exe).arg(&out), "facet-downstream");
    assert!(stdout.contains("rendered 64×64"), "{stdout}");

    let fit = facet_fit::model::material::FittedMaterial::load(&out.join("fit.json")).unwrap();
    let ggx = fit.record.ggx.as_ref().unwrap();
    assert!(ggx.alpha_x.is_finite() && ggx.alpha_x > 0.0, "{ggx:?}");

    let png = image::open(out.join("sphere.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (64, 64));
    let values: Vec<u8> = png.pixels().flat_map(|p| p.0).collect();
    let (lo, hi) = (values.iter().min().unwrap(), values.iter().max().unwrap());
    // A sphere on a floor under a sky: dark and bright pixels both, never one flat value (a
    // NaN in the film would tone-map to one).
    assert!(hi - lo > 32, "sphere.png spans only {lo}..={hi}");
}
