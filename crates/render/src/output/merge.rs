//! Merging shards ([`crate::output::shard`]): parts of one render holding disjoint sample ranges become
//! the render of their union — each pixel's mean weighted by the parts' sample counts, its
//! variance by the exact pairwise formula (Chan, Golub & LeVeque 1979) — after checking that
//! the parts belong together. Parts come in any order; the result is a part too, so merges nest.

use crate::output::film::{Image, to_f32_saturated};
use crate::output::shard::{PixelKind, ShardRecord};
use std::path::PathBuf;

/// One part to merge: its image, and its variance when the merge takes variances.
#[derive(Clone, Debug)]
pub struct Part {
    /// The file it came from (named in messages).
    pub path: PathBuf,
    /// The mean image and its record.
    pub image: (Image, ShardRecord),
    /// The variance of the mean and its record.
    pub variance: Option<(Image, ShardRecord)>,
}

/// The union of the parts: one image (and variance) holding all their samples.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The mean of every sample of every part, per pixel.
    pub image: Image,
    /// Its record: the union of the ranges, the parts' seed, digest and version.
    pub record: ShardRecord,
    /// The variance of that mean, when every part had one.
    pub variance: Option<Image>,
}

impl Merged {
    /// The record of the merged variance image.
    pub fn variance_record(&self) -> ShardRecord {
        ShardRecord {
            pixels: PixelKind::VarianceOfMean,
            ..self.record.clone()
        }
    }
}

/// Why parts cannot be merged: the part at fault and the problem.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct MergeError {
    /// The part.
    pub path: PathBuf,
    /// What is wrong with it.
    pub message: String,
}

/// The union of `parts` (any order), or the first part that does not belong with the others.
/// Checked before anything is summed: the same size, seed, digest and version as the first
/// part, mean images (and variances where asked) with records that agree, sample ranges that
/// overlap no other part's.
pub fn merge(parts: &[Part]) -> Result<Merged, MergeError> {
    let Some(first) = parts.first() else {
        return Err(MergeError {
            path: PathBuf::new(),
            message: "no part to merge".into(),
        });
    };
    for p in parts {
        check_part(p, first)?;
    }
    let record = union_record(parts)?;
    let image = mean(parts);
    let variance = first
        .variance
        .is_some()
        .then(|| variance_of_mean(parts, &image));
    Ok(Merged {
        image,
        record,
        variance,
    })
}

/// `part` agrees with itself (its variance, when it has one, is of the same samples) and with
/// `first`.
fn check_part(part: &Part, first: &Part) -> Result<(), MergeError> {
    let err = |message: String| MergeError {
        path: part.path.clone(),
        message,
    };
    let (image, record) = &part.image;
    let (first_image, first_record) = &first.image;
    record.validate().map_err(err)?;
    if record.pixels != PixelKind::Mean {
        return Err(err("a variance image, not a render's mean image".into()));
    }
    if (image.width, image.height) != (first_image.width, first_image.height) {
        return Err(err(format!(
            "{} × {} pixels, while {} has {} × {}",
            image.width,
            image.height,
            first.path.display(),
            first_image.width,
            first_image.height
        )));
    }
    let differs = |what: &str, this: &dyn std::fmt::Display, that: &dyn std::fmt::Display| {
        err(format!(
            "rendered with another {what} ({this}) than {} ({that})",
            first.path.display()
        ))
    };
    if record.seed != first_record.seed {
        return Err(differs("seed", &record.seed, &first_record.seed));
    }
    if record.digest != first_record.digest {
        return Err(differs(
            "scene or settings: digest",
            &record.digest,
            &first_record.digest,
        ));
    }
    if record.version != first_record.version {
        return Err(differs(
            "Facet version",
            &record.version,
            &first_record.version,
        ));
    }
    match (&part.variance, &first.variance) {
        (Some((var, var_record)), Some(_)) => {
            let expected = ShardRecord {
                pixels: PixelKind::VarianceOfMean,
                ..record.clone()
            };
            if *var_record != expected || (var.width, var.height) != (image.width, image.height) {
                return Err(err(
                    "its variance image is of other samples or another size than its image".into(),
                ));
            }
            if let Some(k) = var.pixels.iter().position(|p| p.iter().any(|v| *v < 0.0)) {
                let w = var.width as usize;
                return Err(err(format!(
                    "its variance image is negative at pixel ({}, {}): not a variance",
                    k % w,
                    k / w
                )));
            }
        }
        (None, Some(_)) => return Err(err("no variance image beside it".into())),
        (Some(_), None) | (None, None) => {}
    }
    Ok(())
}

/// The parts' ranges joined (touching ranges become one), refused where two overlap.
fn union_record(parts: &[Part]) -> Result<ShardRecord, MergeError> {
    let mut ranges: Vec<([u32; 2], usize)> = parts
        .iter()
        .enumerate()
        .flat_map(|(i, p)| p.image.1.samples.iter().map(move |r| (*r, i)))
        .collect();
    ranges.sort_by_key(|(r, _)| *r);
    let mut joined: Vec<[u32; 2]> = Vec::new();
    for w in ranges.windows(2) {
        let ((a, i), (b, j)) = (w[0], w[1]);
        if b[0] < a[1] {
            return Err(MergeError {
                path: parts[j].path.clone(),
                message: format!(
                    "its samples {}..{} overlap the samples {}..{} of {}",
                    b[0],
                    b[1],
                    a[0],
                    a[1],
                    parts[i].path.display()
                ),
            });
        }
    }
    for (r, _) in ranges {
        match joined.last_mut() {
            Some(last) if last[1] == r[0] => last[1] = r[1],
            _ => joined.push(r),
        }
    }
    Ok(ShardRecord {
        samples: joined,
        ..parts[0].image.1.clone()
    })
}

/// Samples per pixel in all the parts.
fn total_count(parts: &[Part]) -> f64 {
    parts.iter().map(|p| p.image.1.count() as f64).sum()
}

/// Σ nᵢ mᵢ / Σ nᵢ of channel `c` of pixel `k`, in f64.
fn pixel_mean(parts: &[Part], k: usize, c: usize) -> f64 {
    let sum: f64 = parts
        .iter()
        .map(|p| p.image.1.count() as f64 * p.image.0.pixels[k][c] as f64)
        .sum();
    sum / total_count(parts)
}

/// The merged image: [`pixel_mean`] of every pixel.
fn mean(parts: &[Part]) -> Image {
    let first = &parts[0].image.0;
    let pixels = (0..first.pixels.len())
        .map(|k| std::array::from_fn(|c| pixel_mean(parts, k, c) as f32))
        .collect();
    Image {
        width: first.width,
        height: first.height,
        pixels,
        samples: vec![total_count(parts) as u32; first.pixels.len()],
    }
}

/// Per pixel, the variance of the merged mean (the pixels of `merged`) from the parts' variances of their means
/// vᵢ: each part's sum of squared deviations Mᵢ = vᵢ nᵢ (nᵢ − 1), then the pairwise formula
/// M = Σ Mᵢ + Σ nᵢ (mᵢ − m)², and M / (N (N − 1)) (0 with fewer than two samples), in f64,
/// saturated to `f32::MAX` as the film's variance is ([`to_f32_saturated`]).
fn variance_of_mean(parts: &[Part], merged: &Image) -> Image {
    let n_total = total_count(parts);
    let pixels = (0..merged.pixels.len())
        .map(|k| {
            std::array::from_fn(|c| {
                if n_total < 2.0 {
                    return 0.0;
                }
                let m = pixel_mean(parts, k, c);
                let m2: f64 = parts
                    .iter()
                    .map(|p| {
                        let n = p.image.1.count() as f64;
                        let mi = p.image.0.pixels[k][c] as f64;
                        let vi = p.variance.as_ref().map_or(0.0, |v| v.0.pixels[k][c] as f64);
                        vi * n * (n - 1.0) + n * (mi - m) * (mi - m)
                    })
                    .sum();
                to_f32_saturated(m2 / (n_total * (n_total - 1.0)))
            })
        })
        .collect();
    Image {
        pixels,
        ..merged.clone()
    }
}
