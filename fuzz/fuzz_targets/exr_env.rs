//! OpenEXR environment map loader (`EnvironmentMap::from_exr_bytes`).
#![no_main]

use facet_fuzz::{assert_env_sane, assert_names, run};
use facet_render::scene::EnvironmentMap;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| run(|| {
    let path = Path::new("fuzzed.exr");
    match EnvironmentMap::from_exr_bytes(path, data) {
        Ok((map, _warnings)) => assert_env_sane(&map),
        Err(e) => assert_names(path, e),
    }
}));
