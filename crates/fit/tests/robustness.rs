//! Missing samples, noise, and bad inputs.

mod common;

use common::{Rng, merl_from_spec, scratch};
use facet_fit::analytic::parse_analytic;
use facet_fit::error::FitError;
use facet_fit::fit::{FitConfig, fit_material};
use facet_fit::geometry::from_half_diff;
use facet_fit::merl::{MerlBrdf, MerlTable, PHI_D_RES, SAMPLES, THETA_D_RES, bin_angles};
use std::path::Path;

fn ggx_alpha(src: &MerlBrdf) -> (f64, f64) {
    let p = fit_material(src, "test", &FitConfig::isotropic())
        .unwrap()
        .record
        .ggx
        .unwrap();
    (p.alpha_x, p.moments.alpha_x)
}

fn spec_table(spec: &str) -> MerlTable {
    MerlTable::sample(&parse_analytic(spec).unwrap())
}

#[test]
fn missing_bins_and_horizon_barely_move_alpha() {
    for alpha in [0.1, 0.4] {
        let spec = format!("ggx?alpha={alpha}&f0=0.04");
        let clean = ggx_alpha(&merl_from_spec(&spec));
        let mut table = spec_table(&spec);
        let mut rng = Rng(7);
        let mut dropped = 0;
        for s in 0..SAMPLES {
            let (i, j, k) = (
                s / (PHI_D_RES * THETA_D_RES),
                s / PHI_D_RES % THETA_D_RES,
                s % PHI_D_RES,
            );
            let (wi, wo) = from_half_diff(bin_angles(i, j, k));
            // Everything below the horizon is already missing (the writer marks it); mark 5 % more.
            if wi.z > 0.0 && wo.z > 0.0 && rng.next() < 0.05 {
                table.mark_missing(s);
                dropped += 1;
            }
        }
        assert!(dropped > 40_000);
        let holed = ggx_alpha(&MerlBrdf::from_table("holed", table).unwrap());
        for (what, a, b) in [
            ("least squares", clean.0, holed.0),
            ("moments", clean.1, holed.1),
        ] {
            let moved = (b / a - 1.0).abs();
            println!(
                "GGX {alpha}: 5 % missing moves {what} α by {:.4} %",
                moved * 100.0
            );
            assert!(moved < 0.005, "{what}: {a} → {b}");
        }
    }
}

#[test]
fn multiplicative_noise_keeps_alpha_within_two_percent() {
    for alpha in [0.05, 0.2, 0.5] {
        let spec = format!("ggx?alpha={alpha}&f0=0.04");
        let mut table = spec_table(&spec);
        let mut rng = Rng(11);
        for s in 0..SAMPLES {
            // 5 % noise: uniform factor with standard deviation 0.05 (half-width 0.05·√3), per channel.
            let f = std::array::from_fn(|_| 1.0 + 0.05 * 3f64.sqrt() * (2.0 * rng.next() - 1.0));
            table.scale_sample(s, f);
        }
        let (lsq, moments) = ggx_alpha(&MerlBrdf::from_table("noisy", table).unwrap());
        println!("GGX {alpha} with 5 % noise: least squares {lsq:.5}, moments {moments:.5}");
        assert!((lsq / alpha - 1.0).abs() < 0.02 && (moments / alpha - 1.0).abs() < 0.02);
    }
}

#[test]
fn merl_write_read_round_trip_is_exact() {
    let dir = scratch("merl_round_trip");
    let table = spec_table("beckmann?alpha=0.3&conductor=gold&kd=0.1");
    let path = dir.join("gold.binary");
    table.write(&path).unwrap();
    assert_eq!(
        std::fs::metadata(&path).unwrap().len(),
        12 + 3 * 8 * SAMPLES as u64
    );
    let back = MerlTable::read(&path).unwrap();
    assert!(back == table, "round trip changed the samples");
    // Nearest lookup anywhere inside a bin returns that bin; interpolation at the sample's own
    // angles returns the sample.
    let src = MerlBrdf::open(&path).unwrap();
    for &(i, j, k) in &[(10, 20, 30), (45, 5, 170), (80, 60, 90)] {
        let v = table.value(i, j, k).unwrap();
        let u = (i as f64 + 0.5) / 90.0;
        let mid = facet_fit::geometry::HalfDiff {
            theta_h: u * u * std::f64::consts::FRAC_PI_2,
            phi_h: 0.0,
            theta_d: (j as f64 + 0.5) / 90.0 * std::f64::consts::FRAC_PI_2,
            phi_d: (k as f64 + 0.5) / 180.0 * std::f64::consts::PI,
        };
        let (wi, wo) = from_half_diff(mid);
        assert_eq!(table.lookup_nearest(wi, wo).unwrap(), v);
        let (wi, wo) = from_half_diff(bin_angles(i, j, k));
        let w = table.lookup_interpolated(wi, wo).unwrap();
        assert!(
            (0..3).all(|c| (w[c] / v[c] - 1.0).abs() < 1e-9),
            "{w:?} vs {v:?}"
        );
        assert_eq!(src.table().value(i, j, k), Some(v));
    }
}

/// A mapped table (`facet fit`'s way) holds the values a read one does, bit for bit, missing
/// samples included; changing it copies it into memory and leaves the file as it was.
#[test]
fn mapped_merl_table_equals_the_read_one_and_never_writes_the_file() {
    let dir = scratch("merl_mapped");
    let mut table = spec_table("ggx?alpha=0.1&f0=0.04&kd=0.2");
    table.mark_missing(facet_fit::merl::index(30, 40, 50));
    let path = dir.join("plastic.binary");
    table.write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let read = MerlTable::read(&path).unwrap();
    let mut mapped = MerlTable::map(&path).unwrap();
    assert!(mapped == read && mapped == table);
    #[cfg(target_os = "linux")]
    assert!(format!("{mapped:?}").ends_with("mapped)"), "{mapped:?}");
    assert_eq!(mapped.missing_count(), read.missing_count());
    for s in [0, 1234, facet_fit::merl::index(30, 40, 50), SAMPLES - 1] {
        assert_eq!(
            mapped.value_at(s).map(|v| v.map(f64::to_bits)),
            read.value_at(s).map(|v| v.map(f64::to_bits))
        );
    }
    // Both sources give the fit the same samples: the same fit, to the bit.
    let cfg = facet_fit::FitConfig {
        models: facet_fit::fit::Models {
            tabulated: true,
            ..facet_fit::fit::Models::NONE
        },
        ..facet_fit::FitConfig::isotropic()
    };
    let fit = |src: &MerlBrdf| {
        let m = facet_fit::fit_material(src, "t", &cfg).unwrap();
        m.record.tabulated.error.map(f64::to_bits)
    };
    assert_eq!(
        fit(&MerlBrdf::map(&path).unwrap()),
        fit(&MerlBrdf::open(&path).unwrap())
    );
    let s = facet_fit::merl::index(10, 20, 30);
    mapped.scale_sample(s, [2.0; 3]);
    let v = read.value_at(s).unwrap();
    assert_eq!(mapped.value_at(s).unwrap(), v.map(|v| v * 2.0));
    assert!(mapped.value_at(s + 1) == read.value_at(s + 1));
    assert!(format!("{mapped:?}").ends_with("in memory)"), "{mapped:?}");
    assert_eq!(
        std::fs::read(&path).unwrap(),
        bytes,
        "the mapped file changed"
    );
}

#[test]
fn interpolated_lookup_beats_nearest_between_bins() {
    let model = parse_analytic("ggx?alpha=0.3&f0=0.04").unwrap();
    let table = MerlTable::sample(&model);
    let mut rng = Rng(3);
    let (mut e_near, mut e_interp) = (0.0, 0.0);
    for _ in 0..2000 {
        let c = facet_fit::geometry::HalfDiff {
            theta_h: rng.next() * 1.2,
            phi_h: 0.0,
            theta_d: rng.next() * 1.2,
            phi_d: rng.next() * std::f64::consts::PI,
        };
        let (wi, wo) = from_half_diff(c);
        if wi.z < 0.2 || wo.z < 0.2 {
            continue;
        }
        use facet_fit::brdf::Brdf;
        let t = model.eval(wi, wo).unwrap()[0];
        e_near += (table.lookup_nearest(wi, wo).unwrap()[0] / t - 1.0).abs();
        e_interp += (table.lookup_interpolated(wi, wo).unwrap()[0] / t - 1.0).abs();
    }
    println!(
        "mean relative error: nearest {:.4}, interpolated {:.4}",
        e_near / 2000.0,
        e_interp / 2000.0
    );
    assert!(e_interp < 0.25 * e_near);
}

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
    let lib = facet_fit::nbrdf::NbrdfLibrary::open(&bad).unwrap();
    let err = lib.get("m").err().unwrap().to_string();
    assert!(
        err.contains("bad.json") && err.contains("W1 must be 6×1"),
        "{err}"
    );
    std::fs::write(&bad, "[1, 2").unwrap();
    let err = facet_fit::nbrdf::NbrdfLibrary::open(&bad)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("bad.json") && err.contains("not a JSON object"),
        "{err}"
    );
}
