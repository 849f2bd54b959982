//! The MERL `.binary` format: written and read back exactly, mapped as read, and looked up
//! nearest or interpolated.

mod common;

use common::{Rng, scratch, spec_table};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::geometry::from_half_diff;
use facet_fit::model::merl_grid::{MerlTable, SAMPLES, bin_angles};
use facet_fit::sources::merl::MerlBrdf;

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
        let mid = facet_fit::model::geometry::HalfDiff {
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
    table.mark_missing(facet_fit::model::merl_grid::index(30, 40, 50));
    let path = dir.join("plastic.binary");
    table.write(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let read = MerlTable::read(&path).unwrap();
    let mut mapped = MerlTable::map(&path).unwrap();
    assert!(mapped == read && mapped == table);
    #[cfg(target_os = "linux")]
    assert!(format!("{mapped:?}").ends_with("mapped)"), "{mapped:?}");
    assert_eq!(mapped.missing_count(), read.missing_count());
    for s in [
        0,
        1234,
        facet_fit::model::merl_grid::index(30, 40, 50),
        SAMPLES - 1,
    ] {
        assert_eq!(
            mapped.value_at(s).map(|v| v.map(f64::to_bits)),
            read.value_at(s).map(|v| v.map(f64::to_bits))
        );
    }
    // Both sources give the fit the same samples: the same fit, to the bit.
    let cfg = facet_fit::FitConfig {
        models: facet_fit::fitting::Models {
            tabulated: true,
            ..facet_fit::fitting::Models::NONE
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
    let s = facet_fit::model::merl_grid::index(10, 20, 30);
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
        let c = facet_fit::model::geometry::HalfDiff {
            theta_h: rng.next() * 1.2,
            phi_h: 0.0,
            theta_d: rng.next() * 1.2,
            phi_d: rng.next() * std::f64::consts::PI,
        };
        let (wi, wo) = from_half_diff(c);
        if wi.z < 0.2 || wo.z < 0.2 {
            continue;
        }
        use facet_fit::model::brdf::Brdf;
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

/// `filled()` keeps every valid sample bit for bit and fills each missing one along θd
/// between the valid samples of its (θh, φd) line: linearly inside the line, held past its
/// ends. A sampled GGX table is missing below the horizon; knocking out interior samples of a
/// line gives the linear case, whose answer is known exactly.
#[test]
fn filled_table_keeps_valid_samples_and_fills_missing_ones_along_theta_d() {
    use facet_fit::model::merl_grid::{THETA_D_RES, THETA_H_RES, index};
    let mut table = spec_table("ggx?alpha=0.3&f0=0.04");
    let before = table.missing_count();
    assert!(before > 0, "a sampled table misses its below-horizon bins");
    let (i, k) = (30, 40);
    let known: Vec<_> = (0..THETA_D_RES).map(|j| table.value(i, j, k)).collect();
    for j in 11..14 {
        table.mark_missing(index(i, j, k));
    }
    let filled = table.filled();
    assert_eq!(
        filled.missing_count(),
        0,
        "every line of a GGX table has valid samples"
    );
    for s in (0..SAMPLES).step_by(7) {
        if let Some(v) = table.value_at(s) {
            assert_eq!(filled.value_at(s), Some(v), "sample {s} changed");
        }
    }
    let (a, b) = (known[10].unwrap(), known[14].unwrap());
    for j in 11..14 {
        let t = (j - 10) as f64 / 4.0;
        let got = filled.value(i, j, k).unwrap();
        for c in 0..3 {
            let want = a[c] + t * (b[c] - a[c]);
            assert!(
                (got[c] - want).abs() <= 1e-12 * want.abs().max(1e-9),
                "θd bin {j}"
            );
        }
    }
    // Past a line's last valid sample the value is held.
    let (i, k) = (THETA_H_RES - 1, 0);
    let last = (0..THETA_D_RES)
        .rev()
        .find(|&j| table.value(i, j, k).is_some())
        .unwrap();
    assert!(
        last + 1 < THETA_D_RES,
        "grazing half vectors miss their high θd bins"
    );
    let held = table.value(i, last, k).unwrap();
    for j in last + 1..THETA_D_RES {
        let got = filled.value(i, j, k).unwrap();
        (0..3).for_each(|c| assert!((got[c] - held[c]).abs() <= 1e-12 * held[c].max(1e-9)));
    }
}

/// `bin_directions` (its sines and cosines computed once) is `from_half_diff(bin_angles(…))`
/// bit for bit on every bin of the grid.
#[test]
fn bin_directions_are_the_bins_angles_exactly() {
    use facet_fit::model::merl_grid::{PHI_D_RES, THETA_D_RES, THETA_H_RES, bin_directions};
    for i in 0..THETA_H_RES {
        for j in 0..THETA_D_RES {
            for k in 0..PHI_D_RES {
                assert_eq!(
                    bin_directions(i, j, k),
                    from_half_diff(bin_angles(i, j, k)),
                    "bin ({i}, {j}, {k})"
                );
            }
        }
    }
}
