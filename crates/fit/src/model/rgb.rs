//! Colour: linear Rec.709 RGB, as every source, model and table holds it.

/// Linear Rec.709 RGB.
pub type Rgb = [f64; 3];

/// Mean of the three channels.
pub fn mean(c: Rgb) -> f64 {
    (c[0] + c[1] + c[2]) / 3.0
}
