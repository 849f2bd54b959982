//! glTF loader (`load_gltf_bytes`), JSON or `.glb`. The input is named `fuzzed.gltf` in a
//! scratch folder that holds the demo's fit as `default_fit.json`, so that `extras.facet.fit`
//! of the seeds resolves; any other relative URI finds nothing.
#![no_main]

use facet_fuzz::{assert_names, assert_scene_sane, run};
use facet_render::scene::{LoadOptions, load_gltf_bytes};
use libfuzzer_sys::fuzz_target;
use std::path::PathBuf;
use std::sync::OnceLock;

/// The fit file beside the fuzzed glTF: the demo's, under the name the seeds use.
const FIT_NAME: &str = "default_fit.json";
const FIT_JSON: &str = include_str!("../../assets/demo/default_fit.json");

fn path() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("facet-fuzz-gltf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(FIT_NAME), FIT_JSON).unwrap();
        dir.join("fuzzed.gltf")
    })
}

fuzz_target!(|data: &[u8]| run(|| {
    let path = path();
    match load_gltf_bytes(path, data, &LoadOptions::default()) {
        Ok(scene) => assert_scene_sane(&scene),
        Err(e) => assert_names(path, e),
    }
}));
