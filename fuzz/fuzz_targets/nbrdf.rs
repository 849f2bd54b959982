//! Neural BRDF JSON loader: `NbrdfLibrary::parse`, then `get` of every name and the network
//! evaluated at a few directions.
#![no_main]

use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fuzz::{assert_brdf_sane, assert_names, run};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| run(|| {
    let path = Path::new("fuzzed-nbrdf.json");
    let library = match NbrdfLibrary::parse(path, &String::from_utf8_lossy(data)) {
        Ok(l) => l,
        Err(e) => return assert_names(path, e),
    };
    for name in library.names() {
        match library.get(name) {
            Ok(brdf) => assert_brdf_sane(&format!("network `{name}`"), &brdf),
            Err(e) => assert_names(path, e),
        }
    }
}));
