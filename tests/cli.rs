//! The `facet` binary as a user runs it. It runs in a folder under the target tmp dir, never
//! in the repository, so that an output it writes by default (`out/`) or one a broken guard
//! lets through cannot land in the checkout.

mod common;

use common::{demo_copy, reproducible_demo_copy};

use std::path::{Path, PathBuf};
use std::process::Command;

/// Where `facet` runs: shared by the tests of this file, never emptied while they run.
fn cwd() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-cwd");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn facet(args: &[&str]) -> (bool, String, String) {
    common::facet_in(&cwd(), args)
}

#[test]
fn fit_writes_json_with_the_documented_fields() {
    let dir = common::scratch("cli_fit");
    let nbrdf = common::nbrdf_path();
    let (ok, stdout, stderr) = facet(&[
        "fit",
        "nbrdf:gold-metallic-paint",
        "analytic:beckmann?alpha=0.3&f0=0.5",
        "--out",
        dir.to_str().unwrap(),
        "--nbrdf",
        nbrdf.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("gold-metallic-paint") && stdout.contains("median error over 2 fits"),
        "{stdout}"
    );
    assert!(!stderr.contains("not isotropic"), "{stderr}");
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("gold-metallic-paint.json")).unwrap(),
    )
    .unwrap();
    for key in [
        "name",
        "source",
        "backend",
        "resolution",
        "iterations",
        "tabulated",
        "ggx",
        "beckmann",
        "fresnel",
        "timings_ms",
    ] {
        assert!(json.get(key).is_some(), "missing {key}");
    }
    for key in ["alpha_x", "alpha_y", "rotation", "error"] {
        assert!(
            json["ggx"][key].is_number() && json["beckmann"][key].is_number(),
            "missing {key}"
        );
    }
    assert!(json["tabulated"]["error"].is_number());
    assert_eq!(
        json["fresnel"]["theta_d"].as_array().unwrap().len(),
        json["fresnel"]["rgb"].as_array().unwrap().len()
    );
    for key in ["load", "extract", "fresnel", "fit", "total"] {
        assert!(json["timings_ms"][key].as_f64().unwrap() >= 0.0);
    }
    assert!(dir.join("gold-metallic-paint.tables.csv").exists());
    // The analytic input comes back with its α.
    let name = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| {
            p.to_string_lossy().contains("beckmann") && p.extension().is_some_and(|e| e == "json")
        })
        .unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(name).unwrap()).unwrap();
    assert!((json["beckmann"]["alpha_x"].as_f64().unwrap() / 0.3 - 1.0).abs() < 0.01);
}

/// An anisotropic source fitted without --aniso cannot take the diffuse lobe (solved on the
/// isotropic grid): the fit says so rather than dropping it silently, and the JSON records it.
#[test]
fn anisotropic_source_without_aniso_says_it_fits_one_lobe() {
    let dir = common::scratch("cli_fit_aniso_source");
    let (ok, stdout, stderr) = facet(&[
        "fit",
        "--model",
        "ggx",
        "--backend",
        "cpu",
        "analytic:ggx?alpha_x=0.1&alpha_y=0.2&f0=0.04",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stderr.contains("not isotropic"), "{stderr}");
    let json = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert_eq!(json["diffuse_lobe"], serde_json::Value::Bool(false));
}

#[test]
fn bad_inputs_fail_cleanly_and_the_rest_still_run() {
    let dir = common::scratch("cli_bad");
    let bad = dir.join("broken.binary");
    std::fs::write(&bad, [1u8, 2, 3]).unwrap();
    let (ok, stdout, stderr) = facet(&[
        "fit",
        bad.to_str().unwrap(),
        "analytic:ggx?alpha=0.2",
        "--model",
        "ggx",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(!ok, "a failed input must make the exit status non-zero");
    assert!(
        stderr.contains("broken.binary") && stderr.contains("truncated header"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stdout.contains("wrote 1 fit"),
        "the good input still ran: {stdout}"
    );
    assert_eq!(
        std::fs::read(&bad).unwrap(),
        [1, 2, 3],
        "the input was not touched"
    );
    let (ok, _, stderr) = facet(&["fit", "analytic:ggx?alpha=0.2", "--resolution", "1"]);
    assert!(!ok && stderr.contains("--resolution"), "{stderr}");
}

/// The sweep of the shard tests: five embedded proxies (not pearl-paint or green-latex, whose
/// fits vary in their last bits between runs), one of them twice (its second fit is
/// `nickel-2.json`, in another shard than `nickel.json`), and an unknown name that fails.
const SWEEP: [&str; 7] = [
    "nbrdf:gold-metallic-paint",
    "nbrdf:alum-bronze",
    "nbrdf:blue-acrylic",
    "nbrdf:nickel",
    "nbrdf:delrin",
    "nbrdf:nickel",
    "nbrdf:no-such-material",
];

/// `facet fit` of [`SWEEP`] into `out` on the CPU, with `extra` options.
fn fit_sweep(out: &Path, extra: &[&str]) -> (bool, String, String) {
    let mut args = vec!["fit"];
    args.extend(SWEEP);
    args.extend(["--backend", "cpu", "--out", out.to_str().unwrap()]);
    args.extend(extra);
    facet(&args)
}

/// `summary.csv` in `dir` without its last column, the time (which changes from run to run).
fn untimed_summary(dir: &Path) -> String {
    let csv = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    csv.lines()
        .map(|l| &l[..l.rfind(',').unwrap()])
        .collect::<Vec<_>>()
        .join("\n")
}

/// The printed table's rows without their last column, the time.
fn untimed_rows(stdout: &str) -> Vec<String> {
    stdout
        .lines()
        .skip_while(|l| !l.starts_with("material "))
        .skip(1)
        .take_while(|l| !l.starts_with("median error"))
        .map(|l| {
            let l = l.trim_end();
            l[..l.rfind(' ').unwrap()].trim_end().to_owned()
        })
        .collect()
}

/// The fits' files in `dir` (not summary.csv or shard manifests), sorted.
fn fit_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "summary.csv" && !n.ends_with(".facet-shard.json"))
        .collect();
    names.sort();
    names
}

/// A sweep split into three shards, writing into one folder or into one folder each, and put
/// back together by `--summary`: the same fits' files, the same printed rows and the same
/// summary.csv (but for the time) as one run over all the inputs, the failed input reported.
#[test]
fn fit_shards_in_one_folder_or_many_sum_up_to_one_run() {
    let dir = common::scratch("cli_fit_shards");
    let (ok, one, stderr) = fit_sweep(&dir.join("one"), &[]);
    assert!(
        !ok && stderr.contains("no-such-material"),
        "{one}\n{stderr}"
    );
    let rows = untimed_rows(&one);
    assert_eq!(rows.len(), 6, "{one}");
    let csv = untimed_summary(&dir.join("one"));
    assert!(csv.contains("\nnickel,nickel-2.json,"), "{csv}");
    let runs = [
        (0, "shared"),
        (1, "shared"),
        (2, "shared"),
        (0, "s0"),
        (1, "s1"),
        (2, "s2"),
    ];
    for (i, folder) in runs {
        let folder = dir.join(folder);
        let (_, stdout, stderr) = fit_sweep(&folder, &["--shard", &format!("{i}/3")]);
        let manifest = format!("shard-{i}-of-3.facet-shard.json");
        assert!(folder.join(&manifest).exists(), "{stdout}\n{stderr}");
        assert!(
            !folder.join("summary.csv").exists(),
            "a shard writes no summary.csv"
        );
    }
    // Each shard names its fits as the one run does (nickel-2.json in shard 2).
    let one_files = fit_files(&dir.join("one"));
    assert_eq!(fit_files(&dir.join("shared")), one_files);
    let mut separate: Vec<String> = ["s0", "s1", "s2"]
        .iter()
        .flat_map(|d| fit_files(&dir.join(d)))
        .collect();
    separate.sort();
    assert_eq!(separate, one_files);
    assert!(fit_files(&dir.join("s2")).contains(&"nickel-2.json".to_owned()));
    let s = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    // The folders in any order: the rows are in the inputs' order.
    for (folders, out) in [
        (vec![s("shared")], s("sum-shared")),
        (vec![s("s2"), s("s0"), s("s1")], s("sum-separate")),
    ] {
        let mut args = vec!["fit", "--summary"];
        args.extend(folders.iter().map(String::as_str));
        args.extend(["--out", &out]);
        let (ok, stdout, stderr) = facet(&args);
        assert!(!ok, "a failed input fails the summary too: {stdout}");
        assert!(
            stderr.contains("error: ") && stderr.contains("no-such-material"),
            "{stderr}"
        );
        assert_eq!(untimed_rows(&stdout), rows, "{stdout}");
        assert!(stdout.contains("median error over 6 fits"), "{stdout}");
        assert_eq!(untimed_summary(Path::new(&out)), csv, "{out}");
    }
}

/// `--summary` refuses, naming the problem and writing nothing, a sweep with a shard missing,
/// shards of other settings, a fit no manifest lists and a JSON that is not a fit.
#[test]
fn fit_summary_refuses_an_incomplete_or_mixed_sweep() {
    let dir = common::scratch("cli_fit_summary_refusals");
    let s = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let shard = |folder: &str, shard: &str, extra: &[&str]| {
        let out = s(folder);
        let mut args = vec![
            "fit",
            "analytic:ggx?alpha=0.2",
            "analytic:beckmann?alpha=0.3",
            "--model",
            "ggx",
            "--backend",
            "cpu",
            "--shard",
            shard,
            "--out",
            &out,
        ];
        args.extend(extra);
        let (ok, stdout, stderr) = facet(&args);
        assert!(ok, "{stdout}\n{stderr}");
    };
    shard("missing", "0/2", &[]);
    shard("mixed", "0/2", &[]);
    shard("mixed", "1/2", &["--resolution", "32"]);
    shard("stray", "0/2", &[]);
    shard("stray", "1/2", &[]);
    std::fs::copy(
        dir.join("stray/analytic-ggx_alpha_0.2.json"),
        dir.join("stray/old-fit.json"),
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("junk")).unwrap();
    std::fs::write(dir.join("junk/notes.json"), r#"{"a": 1}"#).unwrap();
    for (folder, problem) in [
        ("missing", "no shard-1-of-2.facet-shard.json"),
        ("mixed", "disagree on the fit settings"),
        (
            "stray",
            "old-fit.json is a fit that no shard manifest lists",
        ),
        ("junk", "notes.json: neither a fit nor a shard manifest"),
    ] {
        let out = s(&format!("{folder}-summary"));
        let (ok, stdout, stderr) = facet(&["fit", "--summary", &s(folder), "--out", &out]);
        assert!(
            !ok && stderr.contains(problem),
            "{folder}: {stdout}\n{stderr}"
        );
        assert!(!Path::new(&out).exists(), "{folder}: something was written");
    }
}

/// A bad `--shard` is refused by the parser, naming the option and the rule.
#[test]
fn fit_shard_values_are_checked() {
    for (value, problem) in [
        ("3/3", "I must be below N"),
        ("1/0", "N must be at least 1"),
        ("x", "is not I/N"),
    ] {
        let (ok, _, stderr) = facet(&["fit", "analytic:ggx?alpha=0.2", "--shard", value]);
        assert!(
            !ok && stderr.contains("--shard") && stderr.contains(problem),
            "{value}: {stderr}"
        );
    }
    let (ok, _, stderr) = facet(&["fit", "analytic:ggx?alpha=0.2", "--summary", "out"]);
    assert!(!ok && stderr.contains("cannot be used with"), "{stderr}");
}

#[test]
fn dpf_query_and_exr_slices() {
    let (ok, stdout, stderr) = facet(&[
        "dpf",
        "--ndf",
        "analytic:beckmann?alpha=0.1",
        "--gamma",
        "6",
        "--theta-o",
        "20",
        "--theta-i",
        "25",
        "--dphi",
        "170",
        "--json",
        "--resolution",
        "preview",
    ]);
    assert!(ok, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let (p, direct) = (v["p"].as_f64().unwrap(), v["p_direct"].as_f64().unwrap());
    // Preview cells are 7.5°: the trilinear table value stays within 25 % of the integral here.
    assert!(
        p > 0.0 && (p / direct - 1.0).abs() < 0.25,
        "table {p}, direct {direct}"
    );
    assert_eq!(v["levels_deg"], serde_json::json!([5.0, 10.0]));

    let dir = common::scratch("cli_dpf");
    let (ok, stdout, stderr) = facet(&[
        "dpf",
        "--ndf",
        "analytic:ggx?alpha=0.3",
        "--write",
        dir.to_str().unwrap(),
        "--resolution",
        "preview",
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("wrote 9 levels"), "{stdout}");
    for g in [1, 2, 5, 10, 20, 30, 45, 60, 90] {
        let path = dir.join(format!("dpf-gamma{g:02}.exr"));
        let image = exr::prelude::read_first_rgba_layer_from_file(
            &path,
            |res, _| vec![0f32; res.width() * res.height()],
            |px: &mut Vec<f32>, pos, (r, _, _, _): (f32, f32, f32, f32)| {
                px[pos.y() * 12 * 24 + pos.x()] = r
            },
        )
        .unwrap();
        let px = &image.layer_data.channel_data.pixels;
        assert_eq!(px.len(), 12 * 24 * 12);
        assert!(
            px.iter().all(|v| v.is_finite() && *v >= 0.0) && px.iter().any(|v| *v > 0.0),
            "{}",
            path.display()
        );
    }
    let (ok, _, stderr) = facet(&["dpf", "--ndf", "analytic:ggx?alpha=0.3", "--gamma", "5"]);
    assert!(!ok && stderr.contains("--theta-o"), "{stderr}");
}

/// `facet render` on bad inputs: each error names the file and nothing is written. Runs on a
/// copy of the demo scene: the output that would replace the environment map is aimed at the
/// copy's sky, never at `assets/demo/`.
#[test]
fn render_bad_inputs_name_the_file() {
    let dir = common::scratch("cli_render_bad");
    let out = dir.join("img.png");
    let out_s = out.to_str().unwrap();
    let demo = demo_copy(&dir);
    let demo = demo.to_str().unwrap();
    let sky = dir.join("sky.exr");
    let sky_before = std::fs::read(&sky).unwrap();
    let not_gltf = dir.join("broken.gltf");
    std::fs::write(&not_gltf, "{ this is not json").unwrap();
    let bad_fit = dir.join("bad_fit.json");
    std::fs::write(&bad_fit, "{\"name\": 3}").unwrap();
    let cases: Vec<(Vec<String>, String)> = vec![
        (
            vec!["render".into(), "no/such/scene.gltf".into()],
            "no/such/scene.gltf".into(),
        ),
        (
            vec!["render".into(), not_gltf.display().to_string()],
            "broken.gltf".into(),
        ),
        (
            vec![
                "render".into(),
                demo.into(),
                "--env".into(),
                "no/such/sky.exr".into(),
            ],
            "no/such/sky.exr".into(),
        ),
        (
            vec![
                "render".into(),
                demo.into(),
                "--material".into(),
                format!("ggx={}", bad_fit.display()),
            ],
            "bad_fit.json".into(),
        ),
        (
            vec![
                "render".into(),
                demo.into(),
                "--material".into(),
                "nosuch=x.json".into(),
            ],
            "nosuch".into(),
        ),
        (
            // The EXR beside the PNG would be the environment map itself.
            vec![
                "render".into(),
                demo.into(),
                "--env".into(),
                sky.display().to_string(),
                "--out".into(),
                dir.join("sky.png").display().to_string(),
            ],
            "would replace the input".into(),
        ),
    ];
    for (args, needle) in cases {
        let mut a: Vec<&str> = args.iter().map(String::as_str).collect();
        if !a.contains(&"--out") {
            a.extend(["--out", out_s]);
        }
        // Small, so that a check that fails to refuse costs a second, not a full render.
        a.extend(["--width", "16", "--height", "9", "--spp", "1"]);
        let (ok, _, err) = facet(&a);
        assert!(!ok, "{a:?} succeeded");
        assert!(err.contains(&needle), "{a:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        println!("{a:?} -> {}", err.trim());
    }
    assert!(!out.exists() && !out.with_extension("exr").exists());
    assert_eq!(
        std::fs::read(&sky).unwrap(),
        sky_before,
        "the environment map was replaced"
    );
    assert!(!dir.join("sky.png").exists(), "a sky.png was written");
    std::fs::remove_dir_all(&dir).ok();
}

/// `facet render` of the committed demo scene, small: both files, an image that is not black.
#[test]
fn render_demo_scene_writes_png_and_exr() {
    if facet_gpu::gpu_for_tests("render_demo_scene_writes_png_and_exr").is_none() {
        return;
    }
    let dir = std::env::temp_dir().join(format!("facet-cli-demo-{}", std::process::id()));
    let out = dir.join("demo.png");
    let demo = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/demo/demo.gltf");
    let sky = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/demo/sky.exr");
    let (ok, stdout, err) = facet(&[
        "render",
        demo,
        "--env",
        sky,
        "--width",
        "64",
        "--height",
        "36",
        "--spp",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{err}");
    println!("{stdout}");
    let png = image::open(&out).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (64, 36));
    let mean: f64 = png.pixels().map(|p| p.0[1] as f64).sum::<f64>() / (64.0 * 36.0);
    assert!(mean > 20.0 && mean < 250.0, "mean green {mean}");
    assert!(out.with_extension("exr").exists());
    assert!(stdout.contains("classes [\"diffuse\", \"analytic\", \"tabulated\", \"glint\"]"));
    std::fs::remove_dir_all(&dir).ok();
}

/// A measurement named without a fit is fitted by `facet render` in a step of its own, shown
/// with its time, once however many materials name it (the renderer's loader never fits).
#[test]
fn render_fits_a_measurement_named_without_a_fit_in_a_visible_step() {
    if facet_gpu::gpu_for_tests("render_fits_a_measurement_named_without_a_fit").is_none() {
        return;
    }
    let dir = common::scratch("cli_render_fits");
    let out = dir.join("measured.png");
    let demo = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/demo/demo.gltf");
    let (ok, stdout, err) = facet(&[
        "render",
        demo,
        "--material",
        "ggx=nbrdf:alum-bronze",
        "--material",
        "tabulated=nbrdf:alum-bronze",
        "--env-color",
        "1",
        "--width",
        "16",
        "--height",
        "9",
        "--spp",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{err}");
    let step = "fitted the sampling NDF of nbrdf:alum-bronze (no fit named beside it) in ";
    assert_eq!(stdout.matches(step).count(), 1, "{stdout}");
    assert!(out.exists());
}

// ---- features that must visibly act -------------------------------------------------------

#[path = "../crates/render/tests/common/mod.rs"]
mod render_common;

/// The linear pixels of an EXR (width, height, rgb).
fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| px[pos.y() * *w + pos.x()] = [r, g, b],
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let size = img.layer_data.size;
    (
        size.width(),
        size.height(),
        img.layer_data.channel_data.pixels.1,
    )
}

/// The tone map of docs/rendering.md (Output), written out here: 255 · sRGB(1 − exp(−2^e L)),
/// before rounding.
fn tone_map(l: f32, exposure: f64) -> f64 {
    let v = 1.0 - (-(exposure.exp2()) * (l.max(0.0) as f64)).exp();
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    255.0 * s
}

/// Asserts that every `step`-th pixel of the PNG is its EXR pixel through the tone map, rounded
/// (within half a step: f32 in the writer, f64 here); returns their mean byte.
fn check_tone_map(png: &image::RgbImage, exr: &[[f32; 3]], exposure: f64, step: usize) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for (i, p) in png.pixels().enumerate().step_by(step) {
        for (c, (&byte, &l)) in p.0.iter().zip(&exr[i]).enumerate() {
            let want = tone_map(l, exposure);
            assert!(
                (byte as f64 - want).abs() <= 0.5 + 1e-3,
                "exposure {exposure}: pixel {i} channel {c} is {byte} for {want:.3}"
            );
            sum += byte as f64;
            n += 1;
        }
    }
    sum / n as f64
}

/// `spp` in "timings (ms): … (N spp, …)".
fn reported_spp(stdout: &str) -> u32 {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("timings (ms): resources"))
        .unwrap_or_else(|| panic!("no timings line in {stdout}"));
    let (before, _) = line.split_once(" spp,").unwrap();
    before.rsplit('(').next().unwrap().parse().unwrap()
}

/// Samples per pixel of `render_small`, unless `--time-limit` cuts it short.
const SMALL_SPP: u32 = 2;

/// A 40 × 24 render of `demo` at SMALL_SPP (or at 2000 spp with a `--time-limit` in `extra`).
fn render_small(demo: &str, out: &Path, extra: &[&str]) -> String {
    let spp = if extra.contains(&"--time-limit") {
        "2000".to_string()
    } else {
        SMALL_SPP.to_string()
    };
    let mut args = vec![
        "render",
        demo,
        "--width",
        "40",
        "--height",
        "24",
        "--spp",
        &spp,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let (ok, stdout, err) = facet(&args);
    assert!(ok, "{args:?}: {stdout}\n{err}");
    stdout
}

/// `--exposure` scales what the PNG shows exactly as the tone map says, and leaves the EXR
/// (linear) alone: every PNG byte is the tone map of its EXR pixel, rounded.
#[test]
fn exposure_changes_the_png_as_the_tone_map_says() {
    if facet_gpu::gpu_for_tests("exposure_changes_the_png_as_the_tone_map_says").is_none() {
        return;
    }
    let dir = common::scratch("cli_exposure");
    let demo = reproducible_demo_copy(&dir);
    let sky = dir.join("sky.exr");
    let mut exrs = Vec::new();
    let mut means = Vec::new();
    for exposure in [0.0, 2.0, -1.5] {
        let out = dir.join(format!("e{exposure}.png"));
        let e = format!("{exposure}");
        render_small(
            demo.to_str().unwrap(),
            &out,
            &["--env", sky.to_str().unwrap(), "--exposure", &e],
        );
        let (w, h, px) = read_exr(&out.with_extension("exr"));
        let png = image::open(&out).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), (w as u32, h as u32));
        means.push(check_tone_map(&png, &px, exposure, 1));
        exrs.push(px);
    }
    println!("mean PNG byte at exposure 0, +2, −1.5: {means:.1?}");
    assert!(
        exrs[1] == exrs[0] && exrs[2] == exrs[0],
        "the EXR changed with --exposure"
    );
    assert!(means[2] < means[0] && means[0] < means[1], "{means:?}");
}

/// `--time-limit` stops after the pass in which the time runs out: fewer samples than asked
/// for, reported as such, and both outputs written.
#[test]
fn time_limit_stops_early_with_fewer_spp() {
    if facet_gpu::gpu_for_tests("time_limit_stops_early_with_fewer_spp").is_none() {
        return;
    }
    let dir = common::scratch("cli_time_limit");
    let demo = demo_copy(&dir);
    let out = dir.join("t.png");
    // 2000 spp take half a minute on lavapipe; half a second allows a few passes of 4 spp.
    let stdout = render_small(demo.to_str().unwrap(), &out, &["--time-limit", "0.5"]);
    let spp = reported_spp(&stdout);
    println!("time limit 0.5 s: {spp} of 2000 spp");
    assert!((1..2000).contains(&spp), "{spp} spp");
    assert!(out.exists() && out.with_extension("exr").exists());
    let (_, _, px) = read_exr(&out.with_extension("exr"));
    assert!(px.iter().flatten().all(|v| v.is_finite()));
    // Without the limit the same command takes every sample.
    let stdout = render_small(demo.to_str().unwrap(), &dir.join("full.png"), &[]);
    assert_eq!(reported_spp(&stdout), SMALL_SPP);
}

/// The wavefront size is scheduling only: 64 paths in flight (the minimum, many tiles), a size
/// that splits the image unevenly and the default give the same image, bit for bit.
#[test]
fn wavefront_sizes_give_the_same_image() {
    if facet_gpu::gpu_for_tests("wavefront_sizes_give_the_same_image").is_none() {
        return;
    }
    let dir = common::scratch("cli_wavefront");
    let demo = reproducible_demo_copy(&dir);
    let images: Vec<_> = [None, Some("64"), Some("333")]
        .iter()
        .enumerate()
        .map(|(k, w)| {
            let out = dir.join(format!("w{k}.png"));
            let extra: Vec<&str> = w.map(|w| vec!["--wavefront", w]).unwrap_or_default();
            render_small(demo.to_str().unwrap(), &out, &extra);
            read_exr(&out.with_extension("exr")).2
        })
        .collect();
    assert!(images[0].iter().flatten().any(|&v| v > 0.0));
    assert!(images[1] == images[0], "--wavefront 64 changed the image");
    assert!(images[2] == images[0], "--wavefront 333 changed the image");
}

/// `--material ball=FIT` puts a fitted material on the glTF material "ball": a blue Lambertian
/// sphere in a white furnace becomes the fit, whose pixels are its directional albedo E(θo),
/// computed on the CPU from the same fit JSON.
#[test]
fn material_flag_replaces_the_material_as_predicted() {
    if facet_gpu::gpu_for_tests("material_flag_replaces_the_material_as_predicted").is_none() {
        return;
    }
    use facet_fit::model::material::{FittedMaterial, ModelChoice};
    use glam::DVec3;
    let dir = common::scratch("cli_material");
    // The fit: a grey GGX conductor.
    let (ok, stdout, err) = facet(&[
        "fit",
        "analytic:ggx?alpha=0.3&f0=0.5",
        "--backend",
        "cpu",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{err}");
    let fit_path = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .expect("a fit JSON");
    // The scene: a unit sphere, material "ball" (blue, Lambertian), camera at z = 3.
    let mut b = render_common::GltfBuilder::default();
    let (p, n, _, _, idx) = render_common::demo::uv_sphere(1.0);
    let (pa, na, ia) = (b.vec3s(&p), b.vec3s(&n), b.indices(&idx));
    let ball = b.material(serde_json::json!({
        "name": "ball",
        "pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.1, 0.9, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
        "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}
    }));
    b.extensions_used.push("KHR_materials_specular");
    let mesh = b.mesh(
        "ball",
        serde_json::json!({"POSITION": pa, "NORMAL": na}),
        Some(ia),
        Some(ball),
    );
    b.cameras.push(
        serde_json::json!({"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.01}}),
    );
    let m = b.node(serde_json::json!({"mesh": mesh}));
    let c = b.node(serde_json::json!({"camera": 0, "translation": [0.0, 0.0, 3.0]}));
    let scene = dir.join("ball.gltf");
    b.write(&[m, c], &scene);
    let size = 48u32;
    let render = |out: &str, extra: &[&str]| {
        let out = dir.join(out);
        let s = size.to_string();
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "--env-color",
            "1",
            "--width",
            &s,
            "--height",
            &s,
            "--spp",
            "32",
            "--max-depth",
            "1",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let (ok, stdout, err) = facet(&args);
        assert!(ok, "{args:?}: {stdout}\n{err}");
        read_exr(&out.with_extension("exr")).2
    };
    let before = render("before.png", &[]);
    let spec = format!("ball={}", fit_path.display());
    let after = render("after.png", &["--material", &spec]);
    // θo of each pixel centre on the exact sphere, kept below 70° (away from the silhouette).
    let t = (0.5f64 * 0.6).tan();
    let theta = |x: u32, y: u32| {
        let ndc = (
            2.0 * (x as f64 + 0.5) / size as f64 - 1.0,
            1.0 - 2.0 * (y as f64 + 0.5) / size as f64,
        );
        let (o, d) = (
            DVec3::new(0.0, 0.0, 3.0),
            DVec3::new(ndc.0 * t, ndc.1 * t, -1.0).normalize(),
        );
        let b = o.dot(d);
        let disc = b * b - (o.length_squared() - 1.0);
        (disc > 0.0)
            .then(|| {
                let n = (o + (-b - disc.sqrt()) * d).normalize();
                n.dot(-d).clamp(-1.0, 1.0).acos()
            })
            .filter(|t| t.to_degrees() < 70.0)
    };
    let fit = FittedMaterial::load(&fit_path).unwrap();
    let brdf = fit.model(ModelChoice::Tabulated).unwrap();
    let (mut gpu, mut cpu, mut blue, mut count) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, 0);
    for y in 0..size {
        for x in 0..size {
            let Some(th) = theta(x, y) else { continue };
            let i = (y * size + x) as usize;
            gpu += DVec3::from_array(after[i].map(f64::from));
            blue += DVec3::from_array(before[i].map(f64::from));
            let e = facet_fit::model::albedo::directional_albedo(
                brdf,
                DVec3::new(th.sin(), 0.0, th.cos()),
                64,
            );
            cpu += DVec3::from_array(e);
            count += 1;
        }
    }
    let (gpu, cpu, blue) = (gpu / count as f64, cpu / count as f64, blue / count as f64);
    println!(
        "sphere mean over {count} pixels: before {blue:.4}, after {gpu:.4}, CPU albedo {cpu:.4}"
    );
    // Before: the blue Lambertian's albedo, exactly (white furnace, one bounce).
    assert!(
        (blue - DVec3::new(0.05, 0.1, 0.9)).abs().max_element() < 0.01,
        "{blue}"
    );
    // After: the fit's albedo, to 1.5 % (the tabulated model's GPU tables against its CPU twin).
    assert!(
        ((gpu - cpu) / cpu).abs().max_element() < 0.015,
        "{gpu} vs {cpu}"
    );
}

/// `facet` with no arguments in an empty folder runs the demo and writes what the README says:
/// `out/default-gold-ggx.json` (a GGX fit with α = 0.15) and its tables, `out/demo.png` and
/// `out/demo.exr` at 480 × 270.
#[test]
fn demo_runs_and_writes_what_the_readme_says() {
    if facet_gpu::gpu_for_tests("demo_runs_and_writes_what_the_readme_says").is_none() {
        return;
    }
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    for claim in [
        "`out/default-gold-ggx.json`",
        "`out/demo.png`",
        "`out/demo.exr` (480 × 270, 16 spp)",
        "(α = 0.15)",
    ] {
        assert!(readme.contains(claim), "the README no longer says {claim}");
    }
    let cwd = common::scratch("cli_demo_cwd");
    let out = Command::new(env!("CARGO_BIN_EXE_facet"))
        .current_dir(&cwd)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    println!("{stdout}");
    assert_eq!(reported_spp(&stdout), 16);
    let mut names: Vec<String> = std::fs::read_dir(&cwd)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    assert_eq!(names, ["out"], "the demo wrote outside out/");
    names = std::fs::read_dir(cwd.join("out"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "default-gold-ggx.json",
            "default-gold-ggx.tables.csv",
            "demo.exr",
            "demo.png"
        ]
    );
    let png = image::open(cwd.join("out/demo.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (480, 270));
    let (w, h, px) = read_exr(&cwd.join("out/demo.exr"));
    assert_eq!((w, h), (480, 270));
    // The PNG is the EXR through the tone map at exposure 0.
    check_tone_map(&png, &px, 0.0, 97);
    let fit =
        facet_fit::model::material::FittedMaterial::load(&cwd.join("out/default-gold-ggx.json"))
            .unwrap();
    let ggx = fit.record.ggx.as_ref().unwrap();
    assert!(
        (ggx.alpha_x - 0.15).abs() < 0.003 && (ggx.alpha_y - 0.15).abs() < 0.003,
        "{ggx:?}"
    );
    let mean: f64 = px.iter().map(|p| p[1] as f64).sum::<f64>() / px.len() as f64;
    assert!(mean > 0.02 && mean.is_finite(), "mean green {mean}");
}

/// `facet bench --smoke`: every section of the report is there, with finite positive figures,
/// the adapter, the commit and the date.
#[test]
fn bench_smoke_reports_every_section() {
    if facet_gpu::gpu_for_tests("bench_smoke_reports_every_section").is_none() {
        return;
    }
    let dir = common::scratch("cli_bench");
    let json = dir.join("bench.json");
    let (ok, stdout, err) = facet(&["bench", "--smoke", "--json", json.to_str().unwrap()]);
    assert!(ok, "{stdout}\n{err}");
    println!("{stdout}");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let positive = |v: &serde_json::Value, what: &str| {
        let x = v.as_f64().unwrap_or_else(|| panic!("{what}: {v}"));
        assert!(x.is_finite() && x > 0.0, "{what}: {x}");
    };
    assert_eq!(r["mode"], "smoke");
    assert!(r["commit"].as_str().is_some_and(|c| !c.is_empty()));
    assert!(
        r["date"]
            .as_str()
            .is_some_and(|d| d.len() == 20 && d.starts_with("20")),
        "{}",
        r["date"]
    );
    assert!(r["adapter"]["name"].as_str().is_some_and(|n| !n.is_empty()));
    let fit = r["fit"].as_array().unwrap();
    assert_eq!(fit.len(), 6, "3 cases × CPU and GPU");
    for row in fit {
        positive(&row["median_ms"], "fit ms");
    }
    let trace = r["trace"].as_array().unwrap();
    assert_eq!(trace.len(), 4, "camera and random rays × closest and any");
    for row in trace {
        positive(&row["mrays_per_s"], "Mrays/s");
    }
    let integrator = r["integrator"].as_array().unwrap();
    assert_eq!(
        integrator.len(),
        3,
        "without glints, with glints, glints unfiltered"
    );
    for row in integrator {
        positive(&row["msamples_per_s"], "Msamples/s");
    }
    let stages: Vec<&str> = r["stages"]["with_glints"]["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["stage"].as_str().unwrap())
        .collect();
    for s in [
        "logic",
        "generate",
        "extend",
        "shade glint 0",
        "connect",
        "close shade",
    ] {
        assert!(stages.contains(&s), "{s} missing from {stages:?}");
    }
    for key in ["overhead_percent", "unfiltered_overhead_percent"] {
        assert!(
            r["glint"][key].as_f64().is_some_and(f64::is_finite),
            "{key}"
        );
    }
    positive(&r["glint"]["dpf_build_ms"], "DPF build");
    positive(&r["viewer"]["frames_per_s"], "viewer frames/s");
    positive(&r["viewer"]["msamples_per_s"], "viewer Msamples/s");
}

/// `--variance` writes STEM.variance.exr beside the image: the same size, finite, non-negative,
/// not all zero; without the flag there is none.
#[test]
fn variance_flag_writes_the_variance_image() {
    if facet_gpu::gpu_for_tests("variance_flag_writes_the_variance_image").is_none() {
        return;
    }
    let dir = common::scratch("cli_variance");
    let demo = demo_copy(&dir);
    let out = dir.join("v.png");
    let stdout = render_small(demo.to_str().unwrap(), &out, &["--variance"]);
    assert!(stdout.contains("v.variance.exr"), "{stdout}");
    let (w, h, var) = read_exr(&dir.join("v.variance.exr"));
    assert_eq!((w, h), (40, 24));
    assert!(var.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
    assert!(var.iter().flatten().any(|v| *v > 0.0));
    render_small(demo.to_str().unwrap(), &dir.join("plain.png"), &[]);
    assert!(!dir.join("plain.variance.exr").exists());
}
