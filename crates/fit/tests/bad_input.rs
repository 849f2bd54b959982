//! Bad input to the fitter's readers gets clear errors naming it: MERL files, analytic specs,
//! neural BRDF proxies. (The same loaders under seeded mutation: the root package's
//! `tests/loader_mutation/`.)

mod common;

use common::{scratch, spec_table};
use facet_fit::error::FitError;
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::{MerlTable, SAMPLES};
use facet_fit::sources::merl::MerlBrdf;
use std::path::Path;

fn expect_merl_error(path: &Path, needle: &str) {
    match MerlTable::read(path) {
        Err(e @ FitError::Merl { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains(&path.display().to_string()),
                "error does not name the file: {msg}"
            );
            assert!(
                msg.contains(needle),
                "error `{msg}` does not say `{needle}`"
            );
        }
        other => panic!(
            "{}: expected a MERL error about `{needle}`, got {other:?}",
            path.display()
        ),
    }
}

#[test]
fn bad_merl_files_get_clear_errors() {
    let dir = scratch("bad_merl");
    let good = dir.join("good.binary");
    spec_table("ggx?alpha=0.2").write(&good).unwrap();
    let bytes = std::fs::read(&good).unwrap();

    let write = |name: &str, data: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, data).unwrap();
        p
    };
    expect_merl_error(&write("empty.binary", &[]), "empty");
    expect_merl_error(
        &write("short-header.binary", &bytes[..7]),
        "truncated header",
    );
    expect_merl_error(
        &write("truncated.binary", &bytes[..bytes.len() - 8]),
        "truncated",
    );
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 16]);
    expect_merl_error(&write("oversized.binary", &long), "oversized");
    let mut dims = bytes.clone();
    dims[..12].copy_from_slice(&[45, 0, 0, 0, 180, 0, 0, 0, 180, 0, 0, 0]); // 45×180×180: same size, other layout
    expect_merl_error(
        &write("layout.binary", &dims),
        "not the standard 90×90×180 layout",
    );
    let mut negative = bytes.clone();
    negative[4..8].copy_from_slice(&(-90i32).to_le_bytes());
    expect_merl_error(&write("negative-dims.binary", &negative), "not positive");
    expect_merl_error(
        &write(
            "text.binary",
            b"this is not a MERL file at all, just text\n",
        ),
        "truncated",
    );
    let mut nan = bytes.clone();
    let at = 12 + 8 * 1000;
    nan[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    expect_merl_error(&write("nan.binary", &nan), "NaN");
    let mut inf = bytes.clone();
    inf[at..at + 8].copy_from_slice(&f64::INFINITY.to_le_bytes());
    expect_merl_error(&write("inf.binary", &inf), "inf");
    // Not a file at all: refused by the input layer, before the MERL reader.
    for (path, needle) in [
        (dir.clone(), "is a directory"),
        (dir.join("does-not-exist.binary"), "no such file"),
    ] {
        match MerlTable::read(&path) {
            Err(e @ FitError::Input(_)) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(&path.display().to_string()) && msg.contains(needle),
                    "{msg}"
                );
            }
            other => panic!("expected an input error, got {other:?}"),
        }
    }
    // All samples missing: the reader accepts the file, the source says what is wrong.
    let mut empty = spec_table("ggx?alpha=0.2");
    (0..SAMPLES).for_each(|s| empty.mark_missing(s));
    let err = MerlBrdf::from_table("nothing", empty).err().unwrap();
    assert!(err.contains("no valid backscattering sample"), "{err}");
}

#[test]
fn bad_specs_and_proxies_get_clear_errors() {
    for (spec, needle) in [
        ("phong?alpha=0.2", "unknown model"),
        ("ggx?alpha=-1", "α must lie in"),
        ("ggx?alpha=abc", "not a finite number"),
        ("ggx?f0=0.04", "give alpha"),
        ("ggx?alpha=0.2&eta=1,1,1", "both eta and k"),
        ("ggx?alpha=0.2&colour=red", "unknown key"),
    ] {
        let err = parse_analytic(spec).err().unwrap().to_string();
        assert!(err.contains(spec) && err.contains(needle), "{spec}: {err}");
    }
    let lib = common::nbrdf();
    let err = lib.get("no-such-material").err().unwrap().to_string();
    assert!(
        err.contains("merl100.json") && err.contains("no material named"),
        "{err}"
    );
    let dir = scratch("bad_nbrdf");
    let bad = dir.join("bad.json");
    std::fs::write(&bad, r#"{"m": {"W1": [[1.0]], "b1": [0.0], "W2": [[1.0]], "b2": [0.0], "W3": [[1.0]], "b3": [0.0]}}"#).unwrap();
    let lib = facet_fit::sources::nbrdf::NbrdfLibrary::open(&bad).unwrap();
    let err = lib.get("m").err().unwrap().to_string();
    assert!(
        err.contains("bad.json") && err.contains("W1 must be 6×1"),
        "{err}"
    );
    std::fs::write(&bad, "[1, 2").unwrap();
    let err = facet_fit::sources::nbrdf::NbrdfLibrary::open(&bad)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("bad.json") && err.contains("not a JSON object"),
        "{err}"
    );
}
