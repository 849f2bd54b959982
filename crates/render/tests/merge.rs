//! `merge::merge` on the CPU, against sums taken directly: parts made from known samples merge to
//! the mean and variance of all the samples, whatever their order; ranges join; overlaps and
//! strangers are refused.

use facet_render::Image;
use facet_render::output::merge::{MergeError, Part, merge};
use facet_render::output::shard::{PixelKind, ShardRecord};
use std::path::PathBuf;

/// Radiance of sample `s` of pixel `k`, channel `c`: spread over four decades, with a rare
/// bright outlier as a glint gives.
fn sample(k: usize, s: u32, c: usize) -> f64 {
    let h = (k as u64 * 2_654_435_761 + s as u64 * 40_503 + c as u64 * 97)
        .wrapping_mul(6_364_136_223_846_793_005);
    let u = (h >> 11) as f64 / (1u64 << 53) as f64;
    if u > 0.97 { 500.0 * u } else { 0.01 + u * u }
}

const PIXELS: usize = 37;

fn record(pixels: PixelKind, a: u32, b: u32) -> ShardRecord {
    ShardRecord::new(pixels, a..b, 3, "digest".into(), "0.1.0".into())
}

/// The part holding samples a..b, as `facet render --samples a..b --variance` writes it: the
/// mean and the variance of the mean, each rounded to f32.
fn part(a: u32, b: u32) -> Part {
    let n = (b - a) as f64;
    let stats: Vec<([f32; 3], [f32; 3])> = (0..PIXELS)
        .map(|k| {
            let mean: [f64; 3] =
                std::array::from_fn(|c| (a..b).map(|s| sample(k, s, c)).sum::<f64>() / n);
            let var = std::array::from_fn(|c| {
                let m2: f64 = (a..b).map(|s| (sample(k, s, c) - mean[c]).powi(2)).sum();
                if n < 2.0 {
                    0.0
                } else {
                    (m2 / (n * (n - 1.0))) as f32
                }
            });
            (mean.map(|m| m as f32), var)
        })
        .collect();
    let image = |pixels: Vec<[f32; 3]>| Image {
        width: PIXELS as u32,
        height: 1,
        pixels,
        samples: vec![b - a; PIXELS],
    };
    Part {
        path: PathBuf::from(format!("part-{a}-{b}.exr")),
        image: (
            image(stats.iter().map(|s| s.0).collect()),
            record(PixelKind::Mean, a, b),
        ),
        variance: Some((
            image(stats.iter().map(|s| s.1).collect()),
            record(PixelKind::VarianceOfMean, a, b),
        )),
    }
}

/// Parts of 1, 2, 5 and 9 samples (one of a single sample: no variance of its own) merged in a
/// shuffled order give, per pixel, the mean and variance of the mean of all 17 samples computed
/// directly in f64: within f32 rounding of the inputs (relative 1e-6; the variance relative to
/// the sum of squares it is a difference of).
#[test]
fn parts_merge_to_the_statistics_of_all_their_samples() {
    let ranges = [(8, 17), (0, 1), (3, 8), (1, 3)];
    let parts: Vec<Part> = ranges.iter().map(|&(a, b)| part(a, b)).collect();
    let merged = merge(&parts).unwrap();
    assert_eq!(merged.record.samples, vec![[0, 17]]);
    let variance = merged.variance.as_ref().unwrap();
    let n = 17.0;
    for k in 0..PIXELS {
        for c in 0..3 {
            let all: Vec<f64> = (0..17).map(|s| sample(k, s, c)).collect();
            let mean = all.iter().sum::<f64>() / n;
            let m2: f64 = all.iter().map(|x| (x - mean).powi(2)).sum();
            let var = m2 / (n * (n - 1.0));
            let got = merged.image.pixels[k][c] as f64;
            assert!(
                (got - mean).abs() <= 1e-6 * mean,
                "pixel {k}: mean {got} for {mean}"
            );
            let second = all.iter().map(|x| x * x).sum::<f64>() / (n * (n - 1.0));
            let got = variance.pixels[k][c] as f64;
            assert!(
                (got - var).abs() <= 1e-6 * second,
                "pixel {k}: variance {got} for {var}"
            );
        }
    }
}

/// Ranges that touch join; ranges apart stay apart (a part of fewer samples, said as such).
#[test]
fn ranges_join_where_they_touch() {
    let merged = merge(&[part(4, 6), part(0, 2), part(2, 3)]).unwrap();
    assert_eq!(merged.record.samples, vec![[0, 3], [4, 6]]);
    assert_eq!(merged.record.count(), 5);
    assert_eq!(merged.image.samples[0], 5);
    // The merge of a merge is the merge of all.
    let again = merge(&[
        Part {
            path: "m.exr".into(),
            image: (merged.image.clone(), merged.record.clone()),
            variance: Some((merged.variance.clone().unwrap(), merged.variance_record())),
        },
        part(3, 4),
    ])
    .unwrap();
    assert_eq!(again.record.samples, vec![[0, 6]]);
}

fn refused(parts: &[Part]) -> MergeError {
    merge(parts).expect_err("merged parts that do not belong together")
}

/// Each mismatch names the part at fault.
#[test]
fn strangers_are_refused_by_name() {
    let e = refused(&[part(0, 4), part(2, 6)]);
    assert_eq!(e.path, PathBuf::from("part-2-6.exr"));
    assert!(
        e.message
            .contains("overlap the samples 0..4 of part-0-4.exr"),
        "{e}"
    );
    let mut seed = part(4, 6);
    seed.image.1.seed = 9;
    assert!(
        refused(&[part(0, 4), seed])
            .message
            .contains("another seed (9)")
    );
    let mut digest = part(4, 6);
    digest.image.1.digest = "other".into();
    assert!(
        refused(&[part(0, 4), digest])
            .message
            .contains("scene or settings")
    );
    let mut version = part(4, 6);
    version.image.1.version = "9.9.9".into();
    assert!(
        refused(&[part(0, 4), version])
            .message
            .contains("Facet version")
    );
    let mut small = part(4, 6);
    small.image.0.width -= 1;
    small.image.0.pixels.pop();
    assert!(
        refused(&[part(0, 4), small])
            .message
            .contains("36 × 1 pixels")
    );
    let mut var_of_other = part(4, 6);
    var_of_other.variance.as_mut().unwrap().1.samples = vec![[5, 6]];
    assert!(
        refused(&[part(0, 4), var_of_other])
            .message
            .contains("its variance image")
    );
    let mut no_var = part(4, 6);
    no_var.variance = None;
    assert!(
        refused(&[part(0, 4), no_var])
            .message
            .contains("no variance image")
    );
    let mut variance_as_part = part(4, 6);
    variance_as_part.image.1.pixels = PixelKind::VarianceOfMean;
    assert!(
        refused(&[part(0, 4), variance_as_part])
            .message
            .contains("a variance image")
    );
    assert!(merge(&[]).is_err());
}

/// A part's record travels in its EXR header and comes back equal, with the pixels; files that
/// are not a render's parts are refused naming the file.
#[test]
fn shard_records_travel_in_the_exr_header() {
    let dir = std::env::temp_dir().join(format!("facet-shard-exr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = part(2, 7);
    let path = dir.join("part.exr");
    p.image.0.write_shard_exr(&path, &p.image.1).unwrap();
    let (image, record) = Image::read_shard_exr(&path).unwrap();
    assert_eq!(record, p.image.1);
    assert_eq!(image, p.image.0);
    // A plain EXR (no record), a file that is no EXR, a record that is not one.
    let plain = dir.join("plain.exr");
    p.image.0.write_exr(&plain).unwrap();
    let e = Image::read_shard_exr(&plain).unwrap_err().to_string();
    assert!(
        e.contains("plain.exr") && e.contains("no \"facet\" attribute"),
        "{e}"
    );
    let junk = dir.join("junk.exr");
    std::fs::write(&junk, b"not an exr at all").unwrap();
    let e = Image::read_shard_exr(&junk).unwrap_err().to_string();
    assert!(
        e.contains("junk.exr") && e.contains("not a readable OpenEXR"),
        "{e}"
    );
    let mut bad = p.image.1.clone();
    bad.samples = vec![[3, 3]];
    let bad_path = dir.join("bad.exr");
    // Written around write_shard_exr's debug check, as a damaged or hand-made file would be.
    let mut text = serde_json::to_value(&bad).unwrap();
    text["samples"] = serde_json::json!([[5, 2]]);
    write_with_attribute(&bad_path, &p.image.0, &text.to_string());
    let e = Image::read_shard_exr(&bad_path).unwrap_err().to_string();
    assert!(e.contains("bad.exr") && e.contains("is empty"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// `image` as an RGB EXR with `text` as its "facet" attribute.
fn write_with_attribute(path: &std::path::Path, image: &Image, text: &str) {
    use exr::meta::attribute::{AttributeValue, Text};
    use exr::prelude::{SpecificChannels, Vec2, WritableImage as _};
    let w = image.width as usize;
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let p: [f32; 3] = image.pixels[y * w + x];
        (p[0], p[1], p[2])
    });
    let mut e = exr::prelude::Image::from_channels((w, image.height as usize), channels);
    e.attributes
        .other
        .insert(Text::from("facet"), AttributeValue::Text(Text::from(text)));
    e.write().to_file(path).unwrap();
}

/// What a part's record or variance cannot be is refused where it enters, naming the part: a
/// sample range past the last index a render takes (2³⁰), control characters in its digest or
/// version (printed escaped, never raw to a terminal), a negative variance.
#[test]
fn impossible_records_and_variances_are_refused() {
    let mut far = part(4, 6);
    far.image.1.samples = vec![[4, (1 << 30) + 2]];
    let e = refused(&[part(0, 4), far]);
    assert!(e.message.contains("reaches past 1073741824"), "{e}");
    let mut escape = part(4, 6);
    escape.image.1.version = "0.1.0\u{1b}[31m".into();
    let e = refused(&[part(0, 4), escape]);
    assert!(
        e.message.contains("version") && e.message.contains("\\u{1b}[31m"),
        "{e}"
    );
    assert!(!e.to_string().contains('\u{1b}'), "{e}");
    let mut negative = part(4, 6);
    negative.variance.as_mut().unwrap().0.pixels[5][1] = -1e-3;
    let e = refused(&[part(0, 4), negative]);
    assert!(e.message.contains("negative at pixel (5, 0)"), "{e}");
}

/// Two finite parts whose means differ by ±3e38 merge to a finite variance: the between-part
/// term (n (mᵢ − m)², past 1e77) is summed in f64 and saturated to `f32::MAX`, not cast to
/// infinity.
#[test]
fn far_apart_parts_merge_to_a_finite_variance() {
    let mut a = part(0, 4);
    let mut b = part(4, 8);
    for (p, v) in [(&mut a, 3e38f32), (&mut b, -3e38)] {
        p.image.0.pixels.iter_mut().for_each(|px| *px = [v; 3]);
    }
    let merged = merge(&[a, b]).unwrap();
    assert!(merged.image.pixels.iter().flatten().all(|v| *v == 0.0));
    let var = merged.variance.unwrap();
    assert!(
        var.pixels.iter().flatten().all(|v| *v == f32::MAX),
        "{:?}",
        var.pixels[0]
    );
}

/// A part, or its variance, that is a FIFO, a directory or a device is refused by name before
/// it is opened: reading one blocked `facet merge` forever (a FIFO with no writer).
#[cfg(unix)]
#[test]
fn a_part_that_is_not_a_regular_file_is_refused_without_blocking() {
    let dir = std::env::temp_dir().join(format!("facet-shard-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("part.exr");
    std::fs::remove_file(&fifo).ok();
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", fifo.display());
    for path in [fifo.clone(), dir.clone(), PathBuf::from("/dev/zero")] {
        let (tx, rx) = std::sync::mpsc::channel();
        let p = path.clone();
        std::thread::spawn(move || tx.send(Image::read_shard_exr(&p).map(|_| ())).ok());
        let got = rx
            .recv_timeout(std::time::Duration::from_secs(20))
            .unwrap_or_else(|_| panic!("{} blocked the reader", path.display()));
        let e = got.unwrap_err().to_string();
        assert!(
            e.contains(&path.display().to_string()) && e.contains("not a regular file"),
            "{e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
