//! Helpers shared by the integration tests.
#![allow(dead_code)]

use facet_fit::analytic::parse_analytic;
use facet_fit::merl::{MerlBrdf, MerlTable};
use facet_fit::nbrdf::NbrdfLibrary;
use std::path::PathBuf;

/// An analytic BRDF written as a MERL table (bin lower edges) and read back as a source.
pub fn merl_from_spec(spec: &str) -> MerlBrdf {
    let model = parse_analytic(spec).unwrap();
    MerlBrdf::from_table(spec, MerlTable::sample(&model)).unwrap()
}

/// The neural proxies' file inside the repository (the one facet-fit embeds).
pub fn nbrdf_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("crates/fit/data/nbrdf/merl100.json")
}

/// The embedded MERL-100 proxies.
pub fn nbrdf() -> NbrdfLibrary {
    NbrdfLibrary::embedded()
}

/// A scratch folder under target/ for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Deterministic uniform numbers in [0, 1) (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
