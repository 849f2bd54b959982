//! OpenEXR environment maps.

use crate::harness::{refused, save_dir};
use facet_oracles::env_sane;
use facet_render::scene::EnvironmentMap;
use std::path::Path;

pub fn check_exr(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    match EnvironmentMap::from_exr_bytes(path, bytes) {
        Ok((map, _warnings)) => env_sane(&map)
            .map(|()| true)
            .map_err(|p| format!("accepted, but {p}")),
        Err(e) => refused(path, e),
    }
}

/// A tiny RGB EXR written by the exr crate (f32, its default compression).
pub fn tiny_exr() -> Vec<u8> {
    let file = save_dir().join("tiny-seed.exr");
    ::exr::prelude::write_rgb_file(&file, 8, 4, |x, y| (x as f32 * 0.25, y as f32 * 0.5, 1.0))
        .unwrap();
    let bytes = std::fs::read(&file).unwrap();
    std::fs::remove_file(&file).unwrap();
    bytes
}
