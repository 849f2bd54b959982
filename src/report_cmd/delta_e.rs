//! CIEDE2000 colour differences between two renders, as the page shows them.
//!
//! A pixel's colour is what its PNG shows: the renderer's tone map at exposure 0,
//! d = 1 − exp(−L) per channel (`facet_render::film`), kept in f32 rather than rounded to 8 bits,
//! read as linear sRGB (Rec. 709 primaries, D65), converted to CIE L*a*b* (D65) and compared by
//! CIEDE2000 (Sharma, Wu & Dalal 2005) — all by the `palette` crate. ΔE is computed only where
//! the pixel sees the sphere (the background is the same in every render).

use facet_render::Image;
use palette::color_difference::Ciede2000;
use palette::{FromColor, Lab, LinSrgb};

/// A per-pixel ΔE image, `None` off the sphere.
pub struct DeltaE {
    pub width: u32,
    pub height: u32,
    pub values: Vec<Option<f32>>,
}

/// The displayed colour of a linear radiance: the PNG's tone map at exposure 0, unrounded.
pub fn displayed(radiance: [f32; 3]) -> LinSrgb {
    // d = 1 − exp(−L): facet_render::film's tone map, before its sRGB encoding.
    let d = radiance.map(|v| 1.0 - (-v.max(0.0)).exp());
    LinSrgb::new(d[0], d[1], d[2])
}

/// CIE L*a*b* (D65) of a displayed colour.
pub fn lab(c: LinSrgb) -> Lab {
    Lab::from_color(c)
}

/// CIEDE2000 ΔE between two L*a*b* colours.
pub fn ciede2000(a: Lab, b: Lab) -> f32 {
    a.difference(b)
}

/// ΔE per pixel of `test` against `reference` where `mask(x, y)` holds.
pub fn delta_e_image(reference: &Image, test: &Image, mask: &impl Fn(u32, u32) -> bool) -> DeltaE {
    assert_eq!(
        (reference.width, reference.height),
        (test.width, test.height),
        "ΔE of images of different sizes"
    );
    let w = reference.width;
    let values = (reference.pixels.iter().zip(&test.pixels))
        .enumerate()
        .map(|(i, (r, t))| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            mask(x, y).then(|| ciede2000(lab(displayed(*r)), lab(displayed(*t))))
        })
        .collect();
    DeltaE {
        width: w,
        height: reference.height,
        values,
    }
}

impl DeltaE {
    /// The mean ΔE over the pixels that have one (0 when none has).
    pub fn mean(&self) -> f64 {
        let (sum, n) = self
            .values
            .iter()
            .flatten()
            .fold((0.0, 0usize), |(s, n), &v| (s + v as f64, n + 1));
        if n == 0 { 0.0 } else { sum / n as f64 }
    }

    /// The per-pixel mean of several ΔE images of one size (a pixel with none in any is none).
    pub fn mean_of(images: &[&DeltaE]) -> Option<DeltaE> {
        let first = images.first()?;
        let values = (0..first.values.len())
            .map(|i| {
                let mut sum = 0.0f64;
                for im in images {
                    sum += im.values.get(i).copied().flatten()? as f64;
                }
                Some((sum / images.len() as f64) as f32)
            })
            .collect();
        Some(DeltaE {
            width: first.width,
            height: first.height,
            values,
        })
    }
}
