//! Images out of the film: linear HDR pixels, written as EXR (linear, as rendered) and PNG.
//!
//! PNG tone mapping, documented once here: v = 1 − exp(−2^exposure · L) per channel (a soft
//! clip that keeps highlights' hue ordering and never exceeds 1), then the sRGB transfer function,
//! then 8 bits. Exposure 0 leaves mid-tones nearly linear (v ≈ L for small L).

use crate::error::RenderError;
use std::path::Path;

/// `v` as f32, `f32::MAX` where it is larger (a variance of radiance past 1.8e19 is): an image
/// holds no infinity.
pub fn to_f32_saturated(v: f64) -> f32 {
    v.min(f32::MAX as f64) as f32
}

/// The values of `image` an image could not hold and were saturated to `f32::MAX`.
pub fn saturated_count(image: &Image) -> usize {
    image
        .pixels
        .iter()
        .flatten()
        .filter(|v| **v == f32::MAX)
        .count()
}

/// A linear RGB image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Linear RGB radiance, row-major, row 0 at the top.
    pub pixels: Vec<[f32; 3]>,
    /// Samples each pixel received.
    pub samples: Vec<u32>,
}

impl Image {
    /// The film's running means and counts (a pixel with no sample is black).
    pub fn from_film(width: u32, height: u32, film: &[[f32; 4]]) -> Self {
        Image {
            width,
            height,
            pixels: film.iter().map(|v| [v[0], v[1], v[2]]).collect(),
            samples: film.iter().map(|v| v[3] as u32).collect(),
        }
    }

    /// Mean of each channel over the pixels where `mask` is true.
    pub fn mean_where(&self, mask: impl Fn(u32, u32) -> bool) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        let mut n = 0usize;
        for y in 0..self.height {
            for x in 0..self.width {
                if mask(x, y) {
                    let p = self.pixels[(y * self.width + x) as usize];
                    for c in 0..3 {
                        sum[c] += p[c] as f64;
                    }
                    n += 1;
                }
            }
        }
        sum.map(|s| s / n.max(1) as f64)
    }

    /// Mean RGB over every pixel.
    pub fn mean(&self) -> [f64; 3] {
        self.mean_where(|_, _| true)
    }

    /// Root-mean-square difference to another image of the same size, over all channels.
    pub fn rmse(&self, other: &Image) -> f64 {
        let n = self.pixels.len() * 3;
        let s: f64 = self
            .pixels
            .iter()
            .zip(&other.pixels)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] as f64 - b[c] as f64).powi(2)))
            .sum();
        (s / n.max(1) as f64).sqrt()
    }

    /// Linear f32 RGB EXR, as rendered.
    pub fn write_exr(&self, path: &Path) -> Result<(), RenderError> {
        self.write_exr_with(path, None)
    }

    /// Linear f32 RGB EXR with a text attribute `(name, text)` in its header when given (a
    /// shard's record, [`crate::output::shard`]).
    pub(crate) fn write_exr_with(
        &self,
        path: &Path,
        attribute: Option<(&str, String)>,
    ) -> Result<(), RenderError> {
        use exr::meta::attribute::{AttributeValue, Text};
        use exr::prelude::{SpecificChannels, Vec2, WritableImage as _};
        let w = self.width as usize;
        let px = &self.pixels;
        let channels = SpecificChannels::rgb(|Vec2(x, y)| {
            let p: [f32; 3] = px[y * w + x];
            (p[0], p[1], p[2])
        });
        let mut image = exr::prelude::Image::from_channels((w, self.height as usize), channels);
        if let Some((name, text)) = attribute {
            let key = Text::from(name);
            let value = Text::new_or_none(text.as_str()).ok_or_else(|| RenderError::Output {
                path: path.to_owned(),
                message: format!("the \"{name}\" attribute is not EXR text"),
            })?;
            image
                .attributes
                .other
                .insert(key, AttributeValue::Text(value));
        }
        write_atomically(path, |tmp| {
            image.write().to_file(tmp).map_err(|e| e.to_string())
        })
    }

    /// 8-bit sRGB pixels after the tone mapping in the module doc (the GPU's twin:
    /// [`Wavefront::tone_mapped`](crate::Wavefront::tone_mapped)).
    pub fn tone_mapped(&self, exposure: f32) -> Vec<[u8; 3]> {
        let scale = exposure.exp2();
        self.pixels
            .iter()
            .map(|p| p.map(|v| encode_srgb(1.0 - (-scale * v.max(0.0)).exp())))
            .collect()
    }

    /// 8-bit sRGB PNG after the tone mapping in the module doc.
    pub fn write_png(&self, path: &Path, exposure: f32) -> Result<(), RenderError> {
        let bytes: Vec<u8> = self.tone_mapped(exposure).concat();
        let (w, h) = (self.width, self.height);
        write_atomically(path, |tmp| {
            image::save_buffer_with_format(
                tmp,
                &bytes,
                w,
                h,
                image::ExtendedColorType::Rgb8,
                image::ImageFormat::Png,
            )
            .map_err(|e| e.to_string())
        })
    }
}

/// The sRGB transfer function of a value in [0, 1], to 8 bits.
fn encode_srgb(v: f32) -> u8 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// Writes through a temporary file beside `path` and renames it
/// ([`facet_brdf::io::output::write_atomically`]), so a failed write never leaves a truncated
/// file where a good one was; creates the folder first.
fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), RenderError> {
    let err = |message: String| RenderError::Output {
        path: path.to_owned(),
        message,
    };
    if path.file_name().is_none() {
        return Err(err("not a file name".into()));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| err(e.to_string()))?;
    }
    facet_brdf::io::output::write_atomically(path, |tmp| write(tmp).map_err(std::io::Error::other))
        .map_err(|e| err(e.to_string()))
}
