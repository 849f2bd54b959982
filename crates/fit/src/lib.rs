//! Placeholder; filled below.
pub mod analytic;
pub mod brdf;
pub mod error;
pub mod extract;
pub mod fit;
pub mod fresnel;
pub mod geometry;
pub mod grid;
pub mod material;
pub mod merl;
pub mod microfacet;
pub mod nbrdf;
pub mod params;
pub mod quadrature;
pub mod source;
pub mod tabulated;
