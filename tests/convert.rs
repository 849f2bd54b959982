//! `facet convert` end to end: between every pair of formats it writes (MERL, RGL `.bsdf`),
//! refusing to replace a file; a `.bsdf` as the source of `facet fit`. (The `.bsdf` reader and
//! writer themselves: facet-fit's `tests/rgl.rs`.)

mod common;

use common::scratch;
use std::process::Command;

fn facet(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_facet"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `facet convert` between every pair it writes, refusing to replace a file.
#[test]
fn convert_round_trips_and_refuses_to_overwrite() {
    let dir = scratch("rgl_convert");
    let p = |n: &str| dir.join(n).display().to_string();
    let (ok, out, err) = facet(&[
        "convert",
        "analytic:ggx?alpha=0.3&f0=0.04&kd=0.2,0.2,0.2",
        &p("a.bsdf"),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("error against"), "{out}");
    let (ok, _, err) = facet(&["convert", &p("a.bsdf"), &p("a.binary")]);
    assert!(ok, "{err}");
    let (ok, _, err) = facet(&["convert", &p("a.binary"), &p("b.bsdf")]);
    assert!(ok, "{err}");
    // Written twice, the second refused: nothing the user had is replaced.
    let before = std::fs::read(p("a.binary")).unwrap();
    let (ok, _, err) = facet(&["convert", &p("b.bsdf"), &p("a.binary")]);
    assert!(
        !ok && err.contains("exists") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(std::fs::read(p("a.binary")).unwrap(), before);
    let (ok, _, err) = facet(&["convert", &p("a.bsdf"), &p("a.bsdf"), "--force"]);
    assert!(!ok && err.contains("replace the input"), "{err}");
    let (ok, _, err) = facet(&["convert", &p("a.bsdf"), &p("a.txt")]);
    assert!(
        !ok && err.contains(".binary (MERL), .bsdf (RGL) or .json"),
        "{err}"
    );
    // A damaged file is named with its problem.
    std::fs::write(p("bad.bsdf"), b"tensor_file\0\x01\x00\x01\x00\x00\x00").unwrap();
    let (ok, _, err) = facet(&["convert", &p("bad.bsdf"), &p("c.binary")]);
    assert!(
        !ok && err.contains("bad.bsdf") && err.contains("header ends"),
        "{err}"
    );
    // The .bsdf read by the reader is the fit's source in `facet fit` too.
    let (ok, out, err) = facet(&["fit", &p("b.bsdf"), "--model", "ggx", "--out", &p("fits")]);
    assert!(ok, "{err}");
    assert!(out.contains("b "), "{out}");
    let fit = facet_fit::FittedMaterial::load(&dir.join("fits/b.json")).unwrap();
    let alpha = fit.record.ggx.unwrap().alpha_x;
    assert!(
        (alpha - 0.3).abs() < 0.015,
        "α {alpha} through .bsdf → MERL → .bsdf → fit"
    );
}

/// `nbrdf:` resolves the same way in every command: `--nbrdf`, else `$FACET_NBRDF`, else the
/// embedded proxies. `facet convert` read `$FACET_NBRDF` nowhere (its `--help` said it did): a
/// name only the variable's file holds is converted, and is unknown without it.
#[test]
fn convert_reads_the_proxy_file_in_facet_nbrdf() {
    let dir = common::scratch("convert_facet_nbrdf");
    let all: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(common::nbrdf_path()).unwrap()).unwrap();
    let lib = dir.join("lib.json");
    let one = serde_json::json!({ "only-here": all["alum-bronze"] });
    std::fs::write(&lib, one.to_string()).unwrap();
    let convert = |env: Option<&std::path::Path>, out: &str| {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_facet"));
        c.args(["convert", "nbrdf:only-here", out])
            .current_dir(&dir);
        c.env_remove("FACET_NBRDF");
        if let Some(p) = env {
            c.env("FACET_NBRDF", p);
        }
        c.output().unwrap()
    };
    let with = convert(Some(&lib), "a.binary");
    assert!(
        with.status.success(),
        "{}",
        String::from_utf8_lossy(&with.stderr)
    );
    assert!(dir.join("a.binary").is_file());
    let without = convert(None, "b.binary");
    let stderr = String::from_utf8_lossy(&without.stderr);
    assert!(
        !without.status.success() && stderr.contains("only-here"),
        "{stderr}"
    );
}
