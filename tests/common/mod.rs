//! Helpers shared by the root package's integration tests. (Those that other crates' tests use
//! too are `facet_oracles::fixtures`'.)
#![allow(dead_code, unused_imports)]

pub use facet_oracles::fixtures::merl_from_spec;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The neural proxies' file inside the repository (the one facet-fit embeds).
pub fn nbrdf_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("crates/brdf/data/nbrdf/merl100.json")
}

/// A scratch folder under target/ for one test.
pub fn scratch(name: &str) -> PathBuf {
    facet_oracles::fixtures::fresh_dir(env!("CARGO_TARGET_TMPDIR"), name)
}

/// Runs the `facet` binary in `cwd` with `args`: (success, stdout, stderr).
pub fn facet_in(cwd: &Path, args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_facet"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// A copy of the committed demo scene (glTF, fit, sky) in `dir`, so that a render whose guard
/// fails can only harm the copy.
pub fn demo_copy(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/demo");
    for f in ["demo.gltf", "default_fit.json", "sky.exr"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    dir.join("demo.gltf")
}

/// A copy of the demo whose glint sphere has 1000× fewer flakes, so that renders repeat bit for
/// bit on lavapipe too. At the demo's density (and still at a tenth of it) footprints hold
/// enough flakes for llvmpipe's cap of 65 535 iterations per loop, which it counts over a SIMD
/// group of invocations, to cut some counts short; which paths share a group changes from run
/// to run, so a dozen glint pixels of 960 differ between identical renders there.
pub fn reproducible_demo_copy(dir: &Path) -> PathBuf {
    let demo = demo_copy(dir);
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&demo).unwrap()).unwrap();
    let mut changed = 0;
    for m in doc["materials"].as_array_mut().unwrap() {
        if let Some(g) = m.pointer_mut("/extras/facet/glint/density") {
            *g = serde_json::json!(g.as_f64().unwrap() / 1000.0);
            changed += 1;
        }
    }
    assert_eq!(changed, 1, "the demo has one glint material");
    std::fs::write(&demo, serde_json::to_string(&doc).unwrap()).unwrap();
    demo
}

/// The worst per-pixel differences between two renders of one scene (`STEM.exr` and
/// `STEM.variance.exr` beside each, of `n` samples per pixel): (mean, variance). The mean's is
/// relative to the pixel; the variance's relative to Σ L² / (n (n − 1)), the size of the terms
/// that the variance of the mean is a difference of (the f32 rounding of both renders' sums is
/// relative to that). Also the number of channels whose variance is over 1 (noisy, as glints).
pub fn render_differences(a: &Path, b: &Path, n: f64) -> (f64, f64, usize) {
    use facet_render::Image;
    let read = |p: PathBuf| {
        Image::read_shard_exr(&p)
            .unwrap_or_else(|e| panic!("{e}"))
            .0
    };
    let (ma, mb) = (read(a.with_extension("exr")), read(b.with_extension("exr")));
    let (va, vb) = (
        read(a.with_extension("variance.exr")),
        read(b.with_extension("variance.exr")),
    );
    assert_eq!((ma.width, ma.height), (mb.width, mb.height));
    let (mut mean, mut var, mut noisy) = (0.0f64, 0.0f64, 0);
    for k in 0..ma.pixels.len() {
        for c in 0..3 {
            let (x, y) = (ma.pixels[k][c] as f64, mb.pixels[k][c] as f64);
            mean = mean.max((x - y).abs() / x.abs().max(y.abs()).max(1e-30));
            let (u, v) = (va.pixels[k][c] as f64, vb.pixels[k][c] as f64);
            // Σ L² / (n (n − 1)) = u + m² / (n − 1), from u = (Σ L² − n m²) / (n (n − 1)).
            let second = u + x * x / (n - 1.0);
            var = var.max((u - v).abs() / second.max(1e-30));
            noisy += (u > 1.0) as usize;
        }
    }
    (mean, var, noisy)
}
