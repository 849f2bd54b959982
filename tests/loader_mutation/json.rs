//! Fit JSON and neural BRDF JSON.

use crate::harness::refused;
use crate::repo;
use facet_fit::model::material::FittedMaterial;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_oracles::{fit_sane, nbrdf_sane};
use std::path::Path;

pub fn check_fit(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(bytes);
    let fit = match FittedMaterial::parse(path, &text) {
        Ok(fit) => fit,
        Err(e) => return refused(path, e),
    };
    fit_sane(&fit)?;
    Ok(true)
}

/// The first `n` networks of the embedded MERL-100 file, as a JSON object.
pub fn nbrdf_entries(n: usize) -> Vec<u8> {
    let text = std::fs::read_to_string(repo("crates/brdf/data/nbrdf/merl100.json")).unwrap();
    let all: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&text).unwrap();
    let some: serde_json::Map<String, serde_json::Value> = all.into_iter().take(n).collect();
    serde_json::to_vec(&some).unwrap()
}

pub fn check_nbrdf(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    let text = String::from_utf8_lossy(bytes);
    let library = match NbrdfLibrary::parse(path, &text) {
        Ok(l) => l,
        Err(e) => return refused(path, e),
    };
    nbrdf_sane(path, &library)
}
