//! Helpers shared by facet-fit's integration tests. (Those that the root package's tests and
//! other crates' use too are `facet_oracles::fixtures`'.)
#![allow(dead_code, unused_imports)]

pub use facet_oracles::fixtures::{merl_from_spec, spectral_from_rgb};

use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use std::path::PathBuf;

/// An analytic BRDF sampled as a MERL table (bin lower edges).
pub fn spec_table(spec: &str) -> MerlTable {
    MerlTable::sample(&parse_analytic(spec).unwrap())
}

/// The embedded MERL-100 proxies.
pub fn nbrdf() -> NbrdfLibrary {
    NbrdfLibrary::embedded()
}

/// A scratch folder under target/ for one test.
pub fn scratch(name: &str) -> PathBuf {
    facet_oracles::fixtures::fresh_dir(env!("CARGO_TARGET_TMPDIR"), name)
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
