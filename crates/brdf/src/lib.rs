//! # facet-brdf: measured BRDFs and microfacet models
//!
//! What the renderer, the glint crate and the fitter all read: the input files (read safely,
//! written atomically), the numerics, the microfacet models with their fit record
//! [`FittedMaterial`], and the sources of measurements (MERL files, the neural proxies of the
//! MERL database, RGL `.bsdf` files). Fitting a model to a source is facet-fit's, which builds
//! on this crate; a renderer that depends on facet-brdf alone cannot run the fitter.
//!
//! ```
//! use facet_brdf::model::analytic::parse_analytic;
//! use facet_brdf::model::merl_grid::MerlTable;
//! use facet_brdf::Brdf;
//! use glam::DVec3;
//!
//! // A GGX conductor, evaluated directly and as the MERL-grid table sampled from it.
//! let model = parse_analytic("ggx?alpha=0.3&conductor=gold").unwrap();
//! let (wi, wo) = (DVec3::new(0.3, 0.0, 1.0).normalize(), DVec3::new(-0.2, 0.1, 1.0).normalize());
//! let f = model.eval(wi, wo).unwrap();
//! let table = MerlTable::sample(&model);
//! assert!(f[0] > 0.0 && table.first_beyond_max_x().is_none());
//! ```
//!
//! ## Layers
//!
//! Each folder imports only the folders above it in this list (and [`error`]):
//!
//! | layer | what it holds |
//! |---|---|
//! | [`io`] | input files read safely (regular, bounded, mapped), outputs written atomically |
//! | [`numerics`] | quadrature rules, interpolation, the χ² test |
//! | [`model`] | the [`Brdf`] trait, geometry, microfacet NDFs (GGX, Beckmann, tabulated), Fresnel, a clear coat over a base, analytic specs, the fit record [`FittedMaterial`] |
//! | [`sources`] | measurements: MERL files, the neural proxies, RGL `.bsdf` files; [`sources::InputSpec`] names one |
#![warn(missing_docs)]
// `!(x > 0.0)` is how the validators reject NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod error;
pub mod io;
pub mod model;
pub mod numerics;
pub mod sources;

pub use error::BrdfError;
pub use model::brdf::Brdf;
pub use model::material::FittedMaterial;
pub use model::rgb::Rgb;

/// The crate README's Rust example, compiled and run as a doc-test.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
