//! # facet-oracles: what a loader's answer must satisfy
//!
//! The sanity checks shared by the root package's mutation test (`tests/loader_mutation/`) and
//! the cargo-fuzz targets (`fuzz/`), and the fixtures that the tests of several crates build
//! their inputs with. Not published: test code only.
//!
//! Every oracle returns `Err(what is wrong)` instead of panicking, so that a caller decides:
//! the mutation test counts and reports distinct failures, a fuzz target panics (a crash).
//!
//! ```
//! use facet_oracles::{brdf_sane, fixtures::merl_from_spec};
//!
//! let source = merl_from_spec("ggx?alpha=0.3");
//! assert!(brdf_sane("GGX as a MERL table", &source).is_ok());
//! ```
//!
//! - [`brdf`]: the BRDF, fit JSON, neural BRDF and MERL table oracles, and [`names_path`];
//! - `scene` (feature `render`): glTF scenes and OpenEXR environment maps;
//! - [`fixtures`]: analytic BRDFs as MERL sources, spectral `.bsdf` files, scratch folders.
#![warn(missing_docs)]

pub mod brdf;
pub mod fixtures;
#[cfg(feature = "render")]
pub mod scene;

pub use brdf::{
    brdf_sane, direction_pairs, fit_sane, merl_sane, merl_standard_layout, names_path, nbrdf_sane,
};
#[cfg(feature = "render")]
pub use scene::{env_sane, scene_sane};
