//! The `facet` binary as a user runs it. It runs in a folder under the target tmp dir, never
//! in the repository, so that an output it writes by default (`out/`) or one a broken guard
//! lets through cannot land in the checkout.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Where `facet` runs: shared by the tests of this file, never emptied while they run.
fn cwd() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli-cwd");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn facet(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_facet"))
        .args(args)
        .current_dir(cwd())
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
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

/// A copy of the committed demo scene (glTF, fit, sky) in `dir`, so that a render whose guard
/// fails can only harm the copy.
fn demo_copy(dir: &Path) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/demo");
    for f in ["demo.gltf", "default_fit.json", "sky.exr"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
    dir.join("demo.gltf")
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
