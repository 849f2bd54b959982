//! Numerical tools with no knowledge of BRDFs: quadrature rules and the χ² goodness-of-fit
//! test.

pub mod chi2;
pub mod quadrature;
