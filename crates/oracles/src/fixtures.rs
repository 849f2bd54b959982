//! Inputs that the tests of several crates build: analytic BRDFs as MERL sources, spectral
//! `.bsdf` files made from RGB ones, scratch folders.

use facet_fit::export::rgl::{BsdfResolution, rgl_tensor};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::rgl::RglBsdf;
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

/// The `.bsdf` bytes Facet writes for the analytic `spec` on its own NDF: `theta_i` θi slices,
/// `phi_i` φi slices (anisotropic specs), 32² sample space and VNDF, 64 NDF nodes.
pub fn rgl_written(spec: &str, theta_i: usize, phi_i: usize) -> Vec<u8> {
    let src = parse_analytic(spec).unwrap();
    let res = BsdfResolution {
        theta_i,
        phi_i,
        sample: 32,
        vndf: 32,
        ndf: 64,
    };
    rgl_tensor(&src, &src.ndf, res, "").unwrap().0.to_bytes()
}

/// A written anisotropic file cut to its first `keep` φi slices (from −π): of 9 slices, 5
/// span π (the format's fold by 2), 3 span π/2 (its fold by 4).
pub fn rgl_cut_phi(bytes: Vec<u8>, keep: usize) -> Vec<u8> {
    let tf = TensorFile::parse(bytes).unwrap();
    let mut w = TensorWriter::default();
    for name in ["description", "jacobian"] {
        w.u8s(name, tf.u8s(name).unwrap());
    }
    let fields = [
        "theta_i",
        "phi_i",
        "ndf",
        "sigma",
        "vndf",
        "luminance",
        "rgb",
    ];
    for name in fields {
        let (v, shape) = tf.floats(name).unwrap();
        let mut shape = shape.to_vec();
        let mut v: Vec<f32> = v.iter().map(|&x| x as f32).collect();
        if ["phi_i", "vndf", "luminance", "rgb"].contains(&name) {
            v.truncate(v.len() / shape[0] * keep);
            shape[0] = keep;
        }
        w.f32s(name, &shape, &v);
    }
    w.to_bytes()
}

/// Four `.bsdf` files written from GGX with `theta_i` θi slices: isotropic (with a diffuse
/// term), anisotropic and rotated, and anisotropic folded by 2 and by 4
/// ([`RglBsdf::reduction`] 1, 1, 2, 4).
pub fn rgl_test_files(theta_i: usize) -> Vec<(&'static str, RglBsdf)> {
    let aniso = "ggx?alpha_x=0.12&alpha_y=0.35&f0=0.9";
    let rotated = "ggx?alpha_x=0.12&alpha_y=0.35&rotation=30&f0=0.9";
    let parse = |b: Vec<u8>| RglBsdf::parse("t", b).unwrap();
    let isotropic = "ggx?alpha=0.2&f0=0.04&kd=0.3,0.1,0.05";
    vec![
        ("isotropic", parse(rgl_written(isotropic, theta_i, 2))),
        ("anisotropic", parse(rgl_written(rotated, theta_i, 9))),
        (
            "folded by 2",
            parse(rgl_cut_phi(rgl_written(rotated, theta_i, 9), 5)),
        ),
        (
            "folded by 4",
            parse(rgl_cut_phi(rgl_written(aniso, theta_i, 9), 3)),
        ),
    ]
}
