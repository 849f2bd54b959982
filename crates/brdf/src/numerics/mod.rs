//! Numerical tools with no knowledge of BRDFs: quadrature rules, the χ² goodness-of-fit test,
//! gap filling in tables, the fast logarithms of the metric, the 1-D and simplex optimisers and
//! quantiles.

pub mod chi2;
pub mod fast_log;
pub mod interp;
pub mod quadrature;
pub mod stats;
