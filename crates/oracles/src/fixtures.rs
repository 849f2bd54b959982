//! Inputs that the tests of several crates build: analytic BRDFs as MERL sources, spectral
//! `.bsdf` files made from RGB ones, scratch folders.

use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::rgl::tensor_file::{TensorFile, TensorWriter};
use std::path::{Path, PathBuf};

/// An analytic BRDF written as a MERL table (bin lower edges) and read back as a source.
pub fn merl_from_spec(spec: &str) -> MerlBrdf {
    let model = parse_analytic(spec).unwrap();
    MerlBrdf::from_table(spec, MerlTable::sample(&model)).unwrap()
}

/// A fresh, empty folder `name` under `base` (a test's `CARGO_TARGET_TMPDIR`, which only the
/// test's own crate knows: each test crate's `common::scratch` passes it).
pub fn fresh_dir(base: impl AsRef<Path>, name: &str) -> PathBuf {
    let dir = base.as_ref().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A spectral `.bsdf` made from an RGB one: every field kept, `rgb` replaced by `spectra` at
/// 360, 370, …, 830 nm holding at every node the flat spectrum of the node's mean RGB (so that
/// it reads back as that grey).
pub fn spectral_from_rgb(rgb_file: &[u8]) -> Vec<u8> {
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
