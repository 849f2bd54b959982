//! Helpers shared by the integration tests.
#![allow(dead_code)]

use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
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

/// A spectral `.bsdf` made from an RGB one: every field kept, `rgb` replaced by `spectra` at
/// 360, 370, …, 830 nm holding at every node the flat spectrum of the node's mean RGB (so that
/// it reads back as that grey).
pub fn spectral_from_rgb(rgb_file: &[u8]) -> Vec<u8> {
    use facet_fit::sources::rgl::tensor_file::{TensorFile, TensorWriter};
    let t = TensorFile::parse(rgb_file.to_vec()).unwrap();
    let mut w = TensorWriter::default();
    for name in t.names() {
        match name {
            "description" | "jacobian" => w.u8s(name, t.u8s(name).unwrap()),
            "rgb" => {
                let (v, shape) = t.floats("rgb").unwrap();
                let wavelengths: Vec<f32> = (0..48).map(|k| 360.0 + 10.0 * k as f32).collect();
                let plane = shape[3] * shape[4];
                let slices = shape[0] * shape[1];
                let mut spectra = Vec::with_capacity(slices * 48 * plane);
                for s in 0..slices {
                    let base = s * 3 * plane;
                    for _ in 0..48 {
                        spectra.extend((0..plane).map(|p| {
                            ((v[base + p] + v[base + plane + p] + v[base + 2 * plane + p]) / 3.0)
                                as f32
                        }));
                    }
                }
                w.f32s("wavelengths", &[48], &wavelengths);
                w.f32s(
                    "spectra",
                    &[shape[0], shape[1], 48, shape[3], shape[4]],
                    &spectra,
                );
            }
            _ => {
                let (v, shape) = t.floats(name).unwrap();
                let shape = shape.to_vec();
                w.f32s(
                    name,
                    &shape,
                    &v.iter().map(|&x| x as f32).collect::<Vec<_>>(),
                );
            }
        }
    }
    w.to_bytes()
}
