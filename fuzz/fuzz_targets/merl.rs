//! MERL `.binary` loader. A short input is expanded into a full-size file, so that mutations
//! reach the header, the length and the values without 35 MB inputs:
//!
//! - byte 0, bit 0 set: the rest of the input is the whole file, as is (small and odd files);
//! - otherwise, on a valid 90×90×180 table (GGX α = 0.2): byte 1 (as i8) is added to the file
//!   length (bytes cut, or zeros appended), bytes 2..14 are XORed into the 12-byte header, and
//!   each following 12 bytes write one value: a u32 (LE) index modulo 3·SAMPLES, an f64 (LE).
//!
//! The table is changed in place and restored after each run.
#![no_main]

use facet_fit::sources::merl::MerlBrdf;
use facet_fit::model::merl_grid::{MAX_STORED, MerlTable, SAMPLES, SCALE};
use facet_fuzz::{assert_brdf_sane, assert_names, run};
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use std::sync::{Mutex, OnceLock};

/// The valid file's bytes.
fn valid() -> &'static Mutex<Vec<u8>> {
    static FILE: OnceLock<Mutex<Vec<u8>>> = OnceLock::new();
    FILE.get_or_init(|| {
        let model = facet_fit::model::analytic::parse_analytic("ggx?alpha=0.2").unwrap();
        let dir = std::env::temp_dir().join(format!("facet-fuzz-merl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("ggx.binary");
        MerlTable::sample(&model).write(&file).unwrap();
        let bytes = std::fs::read(&file).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        Mutex::new(bytes)
    })
}

fn check(path: &Path, bytes: &[u8], written: &[(usize, f64)], full: bool) {
    let table = match MerlTable::parse(path, bytes) {
        Ok(t) => t,
        Err(e) => return assert_names(path, e),
    };
    assert!(full, "accepted a file that is not the 90×90×180 layout");
    for &(index, v) in written {
        assert!(v <= MAX_STORED, "accepted value {index} = {v:e}");
        let (c, s) = (index / SAMPLES, index % SAMPLES);
        if let Some(rgb) = table.value_at(s) {
            assert!(
                v >= 0.0 && rgb[c] == v * SCALE[c],
                "value {index} = {v:e} reads as {:e}",
                rgb[c]
            );
        }
    }
    for s in 0..SAMPLES {
        if let Some(v) = table.value_at(s) {
            assert!(
                v.iter().all(|x| x.is_finite() && *x >= 0.0),
                "sample {s} is {v:?}"
            );
        }
    }
    if let Ok(brdf) = MerlBrdf::from_table("fuzzed", table) {
        assert_brdf_sane("the table as a BRDF", &brdf);
    }
}

fuzz_target!(|data: &[u8]| run(|| {
    let path = Path::new("fuzzed.binary");
    if data.first().is_some_and(|b| b & 1 == 1) {
        return check(path, &data[1..], &[], false);
    }
    let mut file = valid().lock().unwrap_or_else(|e| e.into_inner());
    let valid_len = file.len();
    let delta = data.get(1).map_or(0, |&b| b as i8 as isize);
    let header: Vec<u8> = data.iter().skip(2).take(12).copied().collect();
    let mut saved: Vec<(usize, [u8; 8])> = Vec::new();
    let mut written: Vec<(usize, f64)> = Vec::new();
    for (i, x) in header.iter().enumerate() {
        file[i] ^= x;
    }
    for rec in data.get(14..).unwrap_or(&[]).chunks_exact(12) {
        let index = u32::from_le_bytes(rec[..4].try_into().unwrap()) as usize % (3 * SAMPLES);
        let at = 12 + 8 * index;
        saved.push((at, file[at..at + 8].try_into().unwrap()));
        file[at..at + 8].copy_from_slice(&rec[4..]);
        written.retain(|w| w.0 != index);
        written.push((index, f64::from_le_bytes(rec[4..].try_into().unwrap())));
    }
    let len = valid_len.saturating_add_signed(delta);
    file.resize(len.max(valid_len), 0);
    let standard = file[..12] == [90, 0, 0, 0, 90, 0, 0, 0, 180, 0, 0, 0];
    // A failed check aborts the process: no restoring needed then.
    check(path, &file[..len], &written, standard && delta == 0);
    file.truncate(valid_len);
    for (at, old) in saved.into_iter().rev() {
        file[at..at + 8].copy_from_slice(&old);
    }
    for (i, x) in header.iter().enumerate() {
        file[i] ^= x;
    }
}));
