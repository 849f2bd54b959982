//! Numerical tools with no knowledge of BRDFs: quadrature rules, the χ² goodness-of-fit test,
//! gap filling in tables and quantiles. (The metric's fast logarithms and the optimisers are
//! facet-fit's, the only crate that takes them.)

pub mod chi2;
pub mod interp;
pub mod quadrature;
pub mod stats;
