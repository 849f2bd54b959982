//! # facet-glint: discrete stochastic microfacets with the filterable DPF
//!
//! [`tea`]: the per-flake hash (Rust and WGSL). [`cone_rule`]: the quadrature over a cone,
//! sized to the NDF's lobe, shared by the CPU and the GPU, and [`lobe_rule`] about the lobe for
//! wide cones. [`dpf`]: the Directional Probability Function
//! by cone integration, its tables (documented cell centres) and the nine-level pyramid, with
//! the paper's Gaussian-blurred levels for comparison. [`flakes`]: the procedural flake field,
//! its consistent quadtree and counting over footprints. [`lit`]: lit counts per node, so a
//! count costs O(footprint boundary), blended over the four nearest direction cells. [`glint_brdf`]: the glint BRDF with its
//! filtered switch, sampling and pdf. [`gpu`]: the pyramid built on the GPU into 3D textures,
//! glint counting, evaluation and sampling in WGSL. [`tags`]: the NDF kind as the WGSL reads
//! it.
//!
//! ```
//! use facet_brdf::model::microfacet::{AnalyticNdf, Ndf, NdfKind};
//! use facet_glint::dpf::{dpf, query_directions};
//!
//! let ndf = Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Beckmann, 0.1));
//! let (wi, wo) = query_directions(0.0, 0.0, 0.0);
//! let p = dpf(&ndf, wi, wo, 1f64.to_radians());
//! assert!((p / 7.587e-3 - 1.0).abs() < 0.01);
//! ```

#![warn(missing_docs)]

pub mod cone_rule;
pub mod dpf;
pub mod flakes;
pub mod glint_brdf;
pub mod gpu;
pub mod lit;
pub mod lobe_rule;
pub mod tags;
pub mod tea;
