//! # facet-fit: measured BRDFs to microfacet models
//!
//! Extracts the normal distribution function of a measured material by power iterations on the
//! backscattering slice (Dupuy et al., EGSR 2015), tabulates G1 and the Fresnel curve, and fits
//! GGX and Beckmann parameters, on the CPU in f64. Isotropic fits add a Lambertian lobe to every
//! model ([`diffuse`]), refine the tabulated NDF in the metric's space and fit physical Fresnel
//! curves to the tables ([`fresnel_fit`]).
//!
//! ```
//! use facet_fit::analytic::parse_analytic;
//! use facet_fit::fit::{fit_material, FitConfig};
//! use facet_fit::merl::{MerlBrdf, MerlTable};
//!
//! // A GGX conductor written as a MERL table, then fitted as if it were a measurement.
//! let model = parse_analytic("ggx?alpha=0.3&conductor=gold").unwrap();
//! let source = MerlBrdf::from_table("gold", MerlTable::sample(&model)).unwrap();
//! let fit = fit_material(&source, "example", &FitConfig::isotropic()).unwrap();
//! let ggx = fit.record.ggx.as_ref().unwrap();
//! assert!((ggx.alpha_x - 0.3).abs() < 0.003);
//! println!("GGX α = {:.4}, error {:.5}", ggx.alpha_x, ggx.error);
//! ```
//!
//! Sources implement [`brdf::Brdf`]: MERL files ([`merl::MerlBrdf`]), RGL `.bsdf` files
//! ([`rgl::RglBsdf`], written by [`rgl::write_rgl`]), the neural proxies
//! ([`nbrdf::NbrdfLibrary`]), analytic models ([`analytic::parse_analytic`]) and fits themselves
//! ([`material::FittedMaterial`]). [`fit::fit_material`] runs the whole pipeline;
//! [`extract`] holds the power iteration, [`tabulated`] the stretched tabulated NDF with its
//! sampling, [`grid`] the error metric and the Fresnel average over the MERL grid.
//! [`export`] writes a fit's GGX or Beckmann model for Mitsuba 3, pbrt-v4 or glTF 2.0, with
//! what the target approximates and its error in the metric.
//!
//! ## Features
//!
//! `gpu` (default): the same extraction and passes over the whole grid (the Fresnel average,
//! the error metric) as WGSL compute passes on a wgpu adapter, through facet-gpu. Without it facet-fit is CPU-only and builds no wgpu.
#![cfg_attr(
    feature = "gpu",
    doc = "With it, [`gpu`] holds the passes and [`fit::fit_material_on`] with \
           [`fit::Backend::Gpu`] runs a fit on them."
)]
#![warn(missing_docs)]
// `!(x > 0.0)` is how the validators reject NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod albedo;
pub mod analytic;
pub mod brdf;
pub mod chi2;
pub mod cie;
pub mod diffuse;
pub mod error;
pub mod export;
pub mod extract;
pub mod fit;
pub mod fresnel;
pub mod fresnel_fit;
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod grid;
pub(crate) mod huge_pages;
pub mod input;
pub(crate) mod iso_grid;
pub(crate) mod lambda_table;
pub(crate) mod mapped_file;
pub mod material;
pub mod merl;
pub(crate) mod merl_geometry;
pub mod microfacet;
pub mod nbrdf;
pub mod params;
pub mod quadrature;
pub(crate) mod refine;
pub mod rgl;
pub mod source;
pub mod tabulated;
pub mod tensor_file;
pub(crate) mod visible_normals;
pub mod visible_tables;
pub mod warp2d;

pub use brdf::{Brdf, Rgb};
pub use error::FitError;
pub use fit::{FitConfig, fit_material};
pub use material::FittedMaterial;

/// The crate README's Rust examples, compiled and run as doc-tests (the workspace README's
/// fitting example is the same text; `tests/readme.rs` at the workspace root checks that).
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
