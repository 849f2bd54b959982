//! # facet-fit: measured BRDFs to microfacet models
//!
//! Extracts the normal distribution function of a measured material by power iterations on the
//! backscattering slice (Dupuy et al., EGSR 2015), tabulates G1 and the Fresnel curve, and fits
//! GGX and Beckmann parameters, on the CPU in f64. Isotropic fits add a Lambertian lobe to every
//! model ([`fitting::diffuse`]), refine the tabulated NDF in the metric's space and fit physical
//! Fresnel curves to the tables ([`fitting::fresnel_fit`]).
//!
//! ```
//! use facet_fit::fitting::{fit_material, FitConfig};
//! use facet_fit::model::analytic::parse_analytic;
//! use facet_fit::sources::merl::MerlBrdf;
//! use facet_fit::model::merl_grid::MerlTable;
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
//! ## Layers
//!
//! Each folder imports only the folders above it in this list (and [`error`]). The first four
//! are facet-brdf's (re-exported here under their old paths), which the renderer depends on
//! without the fitter:
//!
//! | layer | what it holds |
//! |---|---|
//! | [`io`] | input files read safely (regular, bounded, mapped), outputs written atomically |
//! | [`numerics`] | quadrature rules, the χ² test |
//! | [`model`] | the [`Brdf`] trait, geometry, microfacet NDFs (GGX, Beckmann, tabulated), Fresnel, a clear coat over a base, analytic specs, the fit record [`FittedMaterial`] |
//! | [`sources`] | measurements: MERL files, the neural proxies, RGL `.bsdf` files; [`sources::InputSpec`] names one |
//! | [`extract`] | the paper's algorithm: the kernel and the power iteration |
//! | [`metric`] | passes over the MERL grid: the error metric, the Fresnel average, the linear solves |
//! | `gpu` | the extraction and the grid passes as WGSL compute passes (feature `gpu`) |
//! | [`fitting`] | one fit from a source: [`fitting::fit_material`], the analytic fits, the diffuse lobe, the refinement, the Fresnel curves, the coat |
//! | [`export`] | a fit written for Mitsuba 3, pbrt-v4, glTF 2.0, or as an RGL `.bsdf` |
//!
//! ## Features
//!
//! `gpu` (default): the same extraction and passes over the whole grid (the Fresnel average,
//! the error metric) as WGSL compute passes on a wgpu adapter, through facet-gpu. Without it facet-fit is CPU-only and builds no wgpu.
#![cfg_attr(
    feature = "gpu",
    doc = "With it, [`gpu`] holds the passes and [`fitting::fit_material_on`] with \
           [`fitting::Backend::Gpu`] runs a fit on them."
)]
#![warn(missing_docs)]
// `!(x > 0.0)` is how the validators reject NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod export;
pub mod extract;
pub mod fitting;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod metric;

// The layers below the fit, in facet-brdf, under the paths they have always had here.
pub use facet_brdf::{io, model, numerics, sources};

pub use error::FitError;
pub use fitting::{FitConfig, fit_material};
pub use model::brdf::Brdf;
pub use model::material::FittedMaterial;
pub use model::rgb::Rgb;

/// The crate README's Rust examples, compiled and run as doc-tests (the workspace README's
/// fitting example is the same text; `tests/readme.rs` at the workspace root checks that).
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
