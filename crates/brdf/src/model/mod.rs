//! The models: the [`brdf::Brdf`] trait every source and fit implements, the shading-frame
//! geometry, microfacet NDFs (GGX, Beckmann, tabulated with its stretch and visible-normal
//! sampling), Fresnel tables and curves, a clear coat over a base ([`coat`]), analytic specifications, the fit's objective
//! ([`metric::Metric`]) and the fit record
//! ([`material::FittedMaterial`]) that the renderer reads. Nothing here fits anything.

pub mod albedo;
pub mod analytic;
pub mod brdf;
pub mod coat;
pub mod fresnel;
pub mod fresnel_curves;
pub mod geometry;
pub mod material;
pub mod merl_grid;
pub mod metric;
pub mod microfacet;
pub mod rgb;
pub mod tabulated;
pub(crate) mod visible_normals;
pub mod visible_tables;
