//! The `facet` binary as a user runs it.

mod common;

use std::process::Command;

fn facet(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_facet"))
        .args(args)
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
