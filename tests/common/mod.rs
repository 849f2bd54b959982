//! Helpers shared by the root package's integration tests. (Those that other crates' tests use
//! too are `facet_oracles::fixtures`'.)
#![allow(dead_code, unused_imports)]

pub use facet_oracles::fixtures::merl_from_spec;

use std::path::PathBuf;

/// The neural proxies' file inside the repository (the one facet-fit embeds).
pub fn nbrdf_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("crates/fit/data/nbrdf/merl100.json")
}

/// A scratch folder under target/ for one test.
pub fn scratch(name: &str) -> PathBuf {
    facet_oracles::fixtures::fresh_dir(env!("CARGO_TARGET_TMPDIR"), name)
}
