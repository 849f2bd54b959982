//! The job templates in `farm/` run by a real job engine: Open Job Description's `openjd`
//! (`pip install openjd-cli`), which checks them against the specification and runs every task
//! of every step on this machine, in the order their dependencies give. Without `openjd` the
//! tests skip with a visible message, unless `FACET_REQUIRE_OPENJD=1` (`.ci/run` sets it).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The template of the job bundle `name` in `farm/` (`farm/NAME/template.yaml`).
fn template(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("farm")
        .join(name)
        .join("template.yaml")
}

/// Whether `openjd` runs here; if not, the test is reported skipped (or fails under
/// `FACET_REQUIRE_OPENJD=1`).
fn openjd_for_tests(test: &str) -> bool {
    match Command::new("openjd").arg("--version").output() {
        Ok(out) if out.status.success() => true,
        result => {
            let why = match result {
                Ok(out) => format!(
                    "`openjd --version` failed: {}",
                    String::from_utf8_lossy(&out.stderr)
                ),
                Err(e) => format!("no `openjd` command ({e}); `pip install openjd-cli` gives it"),
            };
            if std::env::var("FACET_REQUIRE_OPENJD").is_ok_and(|v| v == "1") {
                panic!("{test}: FACET_REQUIRE_OPENJD=1 but {why}");
            }
            facet_gpu::report_skip(test, &why);
            false
        }
    }
}

/// `openjd ARGS` in `cwd`, asserted to succeed; its output.
fn openjd(cwd: &Path, args: &[&str]) -> String {
    let out = Command::new("openjd")
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    let text = format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "openjd {args:?}:\n{text}");
    text
}

/// Both templates pass `openjd check`: the specification's schema and its rules (parameter
/// references, the task-chunking extension, step dependencies).
#[test]
fn templates_pass_openjd_check() {
    if !openjd_for_tests("templates_pass_openjd_check") {
        return;
    }
    for t in ["render", "fit"] {
        let out = openjd(Path::new("."), &["check", template(t).to_str().unwrap()]);
        assert!(out.contains("passes validation checks"), "{out}");
    }
}

/// `openjd run` of the render template on the demo with glints (4 chunks of 2 samples, then the
/// merge that depends on them) writes the image one `facet render --spp 8` writes: each pixel
/// within f32 rounding of the sums (see `tests/shards.rs`).
#[test]
fn render_template_run_by_openjd_is_the_one_render() {
    if !openjd_for_tests("render_template_run_by_openjd_is_the_one_render")
        || facet_gpu::gpu_for_tests("render_template_run_by_openjd_is_the_one_render").is_none()
    {
        return;
    }
    let dir = common::scratch("farm_render");
    let scene = common::reproducible_demo_copy(&dir);
    let sky = dir.join("sky.exr");
    let facet = env!("CARGO_BIN_EXE_facet");
    let p = |k: &str, v: &str| format!("{k}={v}");
    let params = [
        p("Facet", facet),
        p("SceneFile", scene.to_str().unwrap()),
        p("OutputDir", dir.join("job").to_str().unwrap()),
        p("Samples", "8"),
        p("SamplesPerTask", "2"),
        p("Width", "48"),
        p("Height", "27"),
        p("RenderOptions", &format!("--env {}", sky.display())),
    ];
    let mut args = vec![
        "run".to_string(),
        template("render").display().to_string(),
        "--step".into(),
        "Merge".into(),
        "--run-dependencies".into(),
    ];
    for param in params {
        args.extend(["-p".into(), param]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let log = openjd(&dir, &args);
    assert!(
        log.contains("merged 4 part(s): samples 0..8 (8 spp)"),
        "{log}"
    );
    let (ok, stdout, err) = common::facet_in(
        &dir,
        &[
            "render",
            scene.to_str().unwrap(),
            "--env",
            sky.to_str().unwrap(),
            "--width",
            "48",
            "--height",
            "27",
            "--spp",
            "8",
            "--variance",
            "--out",
            "one/r.png",
        ],
    );
    assert!(ok, "{stdout}\n{err}");
    let (mean, var, noisy) =
        common::render_differences(&dir.join("one/r.exr"), &dir.join("job/render.exr"), 8.0);
    assert!(
        mean <= 4e-6 && var <= 2e-5,
        "mean {mean:e}, variance {var:e}"
    );
    assert!(noisy > 0, "the scene has noisy (glint) pixels");
    std::fs::remove_dir_all(&dir).ok();
}

/// `summary.csv` without its last column (the fits' times).
fn without_times(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(rest, _)| rest).to_owned())
        .collect()
}

/// `openjd run` of the fit template over four embedded proxies in three shards, then the
/// summary step, writes the summary one `facet fit` of the four writes (times aside).
#[test]
fn fit_template_run_by_openjd_sums_up_as_one_fit() {
    if !openjd_for_tests("fit_template_run_by_openjd_sums_up_as_one_fit") {
        return;
    }
    let dir = common::scratch("farm_fit");
    let inputs = [
        "nbrdf:gold-metallic-paint",
        "nbrdf:nickel",
        "nbrdf:blue-acrylic",
        "nbrdf:white-marble",
    ];
    let job = dir.join("job");
    let fit_template = template("fit");
    let args = [
        "run",
        fit_template.to_str().unwrap(),
        "--step",
        "Summary",
        "--run-dependencies",
        "-p",
        &format!("Facet={}", env!("CARGO_BIN_EXE_facet")),
        "-p",
        &format!("OutputDir={}", job.display()),
        "-p",
        "Shards=3",
        "-p",
        &format!("Inputs={}", inputs.join(" ")),
        "-p",
        "FitOptions=--resolution 48",
    ];
    let log = openjd(&dir, &args);
    assert!(log.contains("from 3 shard(s)"), "{log}");
    let mut one = vec!["fit"];
    one.extend(inputs);
    one.extend(["--resolution", "48", "--out", "one"]);
    let (ok, stdout, err) = common::facet_in(&dir, &one);
    assert!(ok, "{stdout}\n{err}");
    let (a, b) = (
        without_times(&dir.join("one/summary.csv")),
        without_times(&job.join("summary.csv")),
    );
    assert_eq!(
        a.len(),
        inputs.len() + 2,
        "a header, the fits and the medians: {a:?}"
    );
    assert_eq!(a, b);
    std::fs::remove_dir_all(&dir).ok();
}
