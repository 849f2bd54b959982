//! Fit JSON loader (`FittedMaterial::parse`): the input as text (invalid UTF-8 replaced).
#![no_main]

use facet_fit::model::material::FittedMaterial;
use facet_fuzz::{assert_fit_sane, assert_names, run};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| run(|| {
    let path = Path::new("fuzzed-fit.json");
    match FittedMaterial::parse(path, &String::from_utf8_lossy(data)) {
        Ok(fit) => assert_fit_sane(&fit),
        Err(e) => assert_names(path, e),
    }
}));
