//! # facet-glint: discrete stochastic microfacets with the filterable DPF
//!
//! Work in progress (issue 4): [`tea`] (the per-flake hash, Rust and WGSL) and [`dpf`] (the
//! Directional Probability Function by cone integration, its tables with documented cell
//! centres and the nine-level pyramid, CPU reference). The GPU table build, 3D textures, flake
//! counting and the glint BRDF come next.
//!
//! ```
//! use facet_fit::microfacet::{AnalyticNdf, Ndf, NdfKind};
//! use facet_glint::dpf::{dpf, query_directions};
//!
//! let ndf = Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Beckmann, 0.1));
//! let (wi, wo) = query_directions(0.0, 0.0, 0.0);
//! let p = dpf(&ndf, wi, wo, 1f64.to_radians());
//! assert!((p / 7.587e-3 - 1.0).abs() < 0.01);
//! ```

pub mod dpf;
pub mod flakes;
pub mod glint_brdf;
pub mod gpu;
pub mod tea;
