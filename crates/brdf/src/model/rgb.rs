//! Colour: linear Rec.709 RGB, as every source, model and table holds it.

/// Linear Rec.709 RGB.
pub type Rgb = [f64; 3];

/// Rec. 709 luminance weights: Y = 0.2126 R + 0.7152 G + 0.0722 B.
pub const LUMINANCE: Rgb = [0.2126, 0.7152, 0.0722];

/// Rec. 709 luminance ([`LUMINANCE`]).
pub fn luminance(c: Rgb) -> f64 {
    LUMINANCE[0] * c[0] + LUMINANCE[1] * c[1] + LUMINANCE[2] * c[2]
}

/// Mean of the three channels.
pub fn mean(c: Rgb) -> f64 {
    (c[0] + c[1] + c[2]) / 3.0
}
