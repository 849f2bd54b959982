//! ΔE images in false colour: their ΔE2000, viridis (plotters' colour map) from 0 to
//! [`DE_MAX`], pixels off the sphere dark grey. One fixed scale for every image of a report, so
//! that images compare.

use crate::delta_e::DeltaE;
use crate::error::{ReportError, Result};
use plotters::style::colors::colormaps::ViridisRGB;
use std::path::Path;

/// ΔE at the top of the colour scale (larger values show its top colour). ΔE ≈ 2.3 is a
/// just-noticeable difference (Sharma 2003); 10 is a clearly different colour.
pub const DE_MAX: f32 = 10.0;
/// The colour of pixels with no ΔE (off the sphere).
const OFF: [u8; 3] = [40, 40, 40];

/// The false colour of one ΔE.
pub fn colour(de: f32) -> [u8; 3] {
    let c = ViridisRGB::get_color_normalized(de.clamp(0.0, DE_MAX), 0.0, DE_MAX);
    [c.0, c.1, c.2]
}

/// Writes the ΔE2000 of `de` as an 8-bit PNG in false colour.
pub fn write_png(de: &DeltaE, path: &Path) -> Result<()> {
    let bytes: Vec<u8> = de
        .values
        .iter()
        .flat_map(|v| v.map_or(OFF, |v| colour(v.de2000)))
        .collect();
    image::save_buffer_with_format(
        path,
        &bytes,
        de.width,
        de.height,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| ReportError::Png {
        path: path.to_owned(),
        source: Box::new(e),
    })
}
