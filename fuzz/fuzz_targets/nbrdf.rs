//! Neural BRDF JSON loader: `NbrdfLibrary::parse`, then `get` of every name and the network
//! evaluated at a few directions.
#![no_main]

use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fuzz::{assert_names, assert_nbrdf_sane, run};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| run(|| {
    let path = Path::new("fuzzed-nbrdf.json");
    match NbrdfLibrary::parse(path, &String::from_utf8_lossy(data)) {
        Ok(library) => assert_nbrdf_sane(path, &library),
        Err(e) => assert_names(path, e),
    }
}));
