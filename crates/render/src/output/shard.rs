//! A shard: a part of a render that holds some of its sample indices, rendered apart (on another
//! machine of a farm) and merged later ([`crate::output::merge`]). What a merge must know of a part —
//! which samples it holds, with which seed, of which scene and settings, by which Facet — travels
//! in its EXR header as the text attribute [`EXR_ATTRIBUTE`] (a JSON [`ShardRecord`]), so a part is
//! an ordinary EXR that any viewer opens.
//!
//! Every pixel of a part holds the same sample indices: a render stops only between whole passes
//! over the image ([`Integrator::render_more`](crate::Integrator::render_more)).

use crate::error::RenderError;
use crate::output::film::Image;
use facet_brdf::io::input::{self, Cap};
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::io::BufReader;
use std::ops::Range;
use std::path::Path;

/// The name of the EXR header attribute (image level, text) that holds a [`ShardRecord`].
pub const EXR_ATTRIBUTE: &str = "facet";

/// Largest sample index a render may reach (a shard's `--samples A..B` has B at most this; a
/// part's record holds no range past it).
pub const MAX_SAMPLE_INDEX: u32 = 1 << 30;

/// Largest image side a part may declare (as `facet render` allows).
const MAX_SIDE: usize = 16384;

/// The largest part read: MAX_SIDE² RGB f32 pixels uncompressed (3 GiB) and its headers.
const PART_CAP: Cap = Cap::new("render part (OpenEXR)", 3 * 1024 * 1024 * 1024 + (64 << 20));

/// What the pixels of a part are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PixelKind {
    /// The mean of the samples: the image.
    Mean,
    /// The variance of that mean: the samples' unbiased variance over their count
    /// ([`Wavefront::variance`](crate::Wavefront::variance)).
    VarianceOfMean,
}

/// Which samples of which render a part holds.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardRecord {
    /// What its pixels are.
    pub pixels: PixelKind,
    /// The sample indices every pixel holds: half-open ranges, disjoint, increasing, none empty,
    /// none touching the next (a merge joins touching ranges).
    pub samples: Vec<[u32; 2]>,
    /// The seed of the per-pixel random numbers.
    pub seed: u32,
    /// Identity of the scene and of the settings that decide the image (the caller's digest):
    /// parts merge only when theirs are equal.
    pub digest: String,
    /// The version of the renderer that made it: parts merge only when theirs are equal.
    pub version: String,
}

impl ShardRecord {
    /// The record of a part of `pixels` holding the samples `range` of every pixel.
    pub fn new(
        pixels: PixelKind,
        range: Range<u32>,
        seed: u32,
        digest: String,
        version: String,
    ) -> Self {
        ShardRecord {
            pixels,
            samples: vec![[range.start, range.end]],
            seed,
            digest,
            version,
        }
    }

    /// Samples per pixel: the ranges' total length.
    pub fn count(&self) -> u64 {
        self.samples.iter().map(|[a, b]| (b - a) as u64).sum()
    }

    /// The ranges as `A..B, C..D`.
    pub fn ranges_text(&self) -> String {
        let r: Vec<String> = self
            .samples
            .iter()
            .map(|[a, b]| format!("{a}..{b}"))
            .collect();
        r.join(", ")
    }

    /// Checks the invariants of [`ShardRecord::samples`]: something wrong is described.
    pub fn validate(&self) -> Result<(), String> {
        if self.samples.is_empty() {
            return Err("it holds no sample range".into());
        }
        for w in self.samples.windows(2) {
            if w[0][1] >= w[1][0] {
                return Err(format!(
                    "its sample ranges {} are not disjoint, increasing and apart",
                    self.ranges_text()
                ));
            }
        }
        if let Some([a, b]) = self.samples.iter().find(|[a, b]| a >= b) {
            return Err(format!("its sample range {a}..{b} is empty"));
        }
        if let Some([a, b]) = self.samples.iter().find(|[_, b]| *b > MAX_SAMPLE_INDEX) {
            return Err(format!(
                "its sample range {a}..{b} reaches past {MAX_SAMPLE_INDEX}, the last sample \
                 index a render takes"
            ));
        }
        for (field, text) in [("digest", &self.digest), ("version", &self.version)] {
            if text.chars().any(char::is_control) {
                return Err(format!(
                    "its {field} \"{}\" holds control characters",
                    text.escape_debug()
                ));
            }
        }
        Ok(())
    }
}

impl Image {
    /// [`Image::write_exr`] with `record` in the header ([`EXR_ATTRIBUTE`]).
    pub fn write_shard_exr(&self, path: &Path, record: &ShardRecord) -> Result<(), RenderError> {
        debug_assert!(record.validate().is_ok(), "{:?}", record.validate());
        debug_assert!(
            self.samples.iter().all(|&n| n as u64 == record.count()),
            "every pixel holds the record's samples"
        );
        let json = serde_json::to_string(record).expect("a record serialises");
        self.write_exr_with(path, Some((EXR_ATTRIBUTE, json)))
    }

    /// A part written by [`Image::write_shard_exr`]: its pixels and its record. A file that is
    /// not an RGB EXR, has no readable record, or is larger than a render can be, is refused
    /// naming the file; the header is read and checked before any pixel.
    pub fn read_shard_exr(path: &Path) -> Result<(Image, ShardRecord), RenderError> {
        let bad = |m: String| RenderError::input(path, m);
        let not_exr = |e: exr::error::Error| bad(format!("not a readable OpenEXR image: {e}"));
        // Through the input door: a regular file under its cap (a FIFO, a device or a
        // directory is refused before it is opened), opened without blocking.
        let open = || input::open(path, PART_CAP).map(|(f, len)| (BufReader::new(f), len));
        let (file, bytes) = open()?;
        let meta = crate::scene::gltf_file::guard(path, "the OpenEXR image", || {
            exr::meta::MetaData::read_from_buffered(file, false).map_err(not_exr)
        })?;
        let record = record_of(&meta).map_err(bad)?;
        let header = &meta.headers[0];
        let (w, h) = (header.layer_size.0, header.layer_size.1);
        if w > MAX_SIDE || h > MAX_SIDE {
            return Err(bad(format!(
                "{w} × {h} pixels: larger than a render can be"
            )));
        }
        // Each chunk has an 8-byte entry in the offset table, which the decoder allocates from
        // the header: more than the file can hold is a damaged (or hostile) header.
        if (header.chunk_count as u64).saturating_mul(8) > bytes {
            return Err(bad(format!(
                "the header declares {} chunks, more than the file's {bytes} bytes can hold",
                header.chunk_count
            )));
        }
        let (file, _) = open()?;
        let pixels = crate::scene::gltf_file::guard(path, "the OpenEXR image", || {
            read_rgb(file, w).map_err(not_exr)
        })?;
        if pixels.len() != w * h {
            return Err(bad(format!("{} pixels for {w} × {h}", pixels.len())));
        }
        if let Some(i) = pixels.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(bad(format!(
                "pixel ({}, {}) is not finite: not a render's output",
                i % w,
                i / w
            )));
        }
        let count = u32::try_from(record.count()).map_err(|_| bad("too many samples".into()))?;
        let image = Image {
            width: w as u32,
            height: h as u32,
            samples: vec![count; pixels.len()],
            pixels,
        };
        Ok((image, record))
    }
}

/// The record in a header, checked.
fn record_of(meta: &exr::meta::MetaData) -> Result<ShardRecord, String> {
    use exr::meta::attribute::{AttributeValue, Text};
    let [header] = meta.headers.as_slice() else {
        return Err(format!(
            "{} layers: a render's EXR has one",
            meta.headers.len()
        ));
    };
    let key = Text::from(EXR_ATTRIBUTE);
    // Written with the image's attributes; read back among the layer's (exr files unknown
    // attributes there).
    let found = (header.own_attributes.other.get(&key))
        .or_else(|| header.shared_attributes.other.get(&key));
    let text = match found {
        Some(AttributeValue::Text(t)) => t.to_string(),
        Some(_) => return Err(format!("its \"{EXR_ATTRIBUTE}\" attribute is not text")),
        None => {
            return Err(format!(
                "no \"{EXR_ATTRIBUTE}\" attribute in its header: not written by `facet render` \
                 (or written by an older Facet)"
            ));
        }
    };
    let record: ShardRecord = serde_json::from_str(&text)
        .map_err(|e| format!("its \"{EXR_ATTRIBUTE}\" attribute is not a shard record: {e}"))?;
    record.validate()?;
    Ok(record)
}

/// The RGB pixels of the first layer, row-major.
fn read_rgb(file: BufReader<File>, width: usize) -> exr::error::Result<Vec<[f32; 3]>> {
    use exr::prelude::{ReadChannels as _, ReadLayers as _};
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |res, _| vec![[0.0f32; 3]; res.width() * res.height()],
            move |px: &mut Vec<[f32; 3]>, pos, (r, g, b): (f32, f32, f32)| {
                px[pos.y() * width + pos.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(file)?;
    Ok(image.layer_data.channel_data.pixels)
}
