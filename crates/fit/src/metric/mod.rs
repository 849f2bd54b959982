//! The passes over the MERL grid that every fit asks for: the error metric (mean
//! |ln(1 + x_model/ε) − ln(1 + x_data/ε)|, x = f_r cos θi, ε set by the [`Metric`]), the
//! Fresnel average and the linear solves for F and a diffuse albedo, on the CPU (the GPU twins
//! are in [`crate::gpu`]).

pub mod fast_log;
pub mod grid;
pub(crate) mod iso;
pub mod iso_tables;
pub(crate) mod lambda_table;
pub mod look;
pub(crate) mod merl_geometry;
pub(crate) mod sums;

pub use crate::model::metric::Metric;
