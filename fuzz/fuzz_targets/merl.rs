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

use facet_fit::model::merl_grid::{MerlTable, SAMPLES};
use facet_fuzz::{assert_merl_sane, assert_names, run};
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

/// The table as read: refused with an error naming the path, or sane, `written` read back
/// (`facet_oracles::merl_sane`: only the standard layout is accepted).
fn check(path: &Path, bytes: &[u8], written: &[(usize, f64)]) {
    match MerlTable::parse(path, bytes) {
        Ok(table) => assert_merl_sane(bytes, table, written),
        Err(e) => assert_names(path, e),
    }
}

fuzz_target!(|data: &[u8]| run(|| {
    let path = Path::new("fuzzed.binary");
    if data.first().is_some_and(|b| b & 1 == 1) {
        return check(path, &data[1..], &[]);
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
    // A failed check aborts the process: no restoring needed then.
    check(path, &file[..len], &written);
    file.truncate(valid_len);
    for (at, old) in saved.into_iter().rev() {
        file[at..at + 8].copy_from_slice(&old);
    }
    for (i, x) in header.iter().enumerate() {
        file[i] ^= x;
    }
}));
