//! Value parsers of the command line: every number is checked against its documented range when
//! it is parsed, so that clap's error names the argument and the range, and NaN or infinity
//! never reaches the work. Commands take negative numbers as values (`--exposure -2`), so a
//! negative count is refused by its range, not read as a flag.

use std::ops::RangeInclusive;

/// Largest image side of `facet render` and `facet demo` (pixels).
pub const MAX_SIDE: u32 = 16384;
/// Most samples per pixel.
pub const MAX_SPP: u32 = 1 << 20;
/// Most samples of one render in all (width × height × spp): 2⁴⁰, hours on any GPU.
pub const MAX_SAMPLES: u64 = 1 << 40;

/// A whole number in `range`.
fn whole<T>(s: &str, range: RangeInclusive<T>) -> Result<T, String>
where
    T: std::str::FromStr + PartialOrd + std::fmt::Display + Copy,
{
    let v: T = s.trim().parse().map_err(|_| {
        format!(
            "`{s}` is not a whole number from {} to {}",
            range.start(),
            range.end()
        )
    })?;
    if range.contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} is outside {} to {}",
            range.start(),
            range.end()
        ))
    }
}

/// A finite number in `range`.
fn real(s: &str, range: RangeInclusive<f64>) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a number"))?;
    if !v.is_finite() {
        return Err(format!("{s} is not a finite number"));
    }
    if range.contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "{v} is outside [{}, {}]",
            range.start(),
            range.end()
        ))
    }
}

pub use facet_render::output::shard::MAX_SAMPLE_INDEX;

/// A shard's sample indices `A..B`: 0 ≤ A < B ≤ [`MAX_SAMPLE_INDEX`], at most [`MAX_SPP`] of them.
pub fn sample_range(s: &str) -> Result<std::ops::Range<u32>, String> {
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| format!("`{s}`: expected A..B (the sample indices A to B − 1)"))?;
    let a = whole(a, 0..=MAX_SAMPLE_INDEX)?;
    let b = whole(b, 0..=MAX_SAMPLE_INDEX)?;
    if a >= b {
        return Err(format!("`{s}`: A must be below B"));
    }
    if b - a > MAX_SPP {
        return Err(format!(
            "`{s}`: {} samples; a render takes at most 2^20 per pixel",
            b - a
        ));
    }
    Ok(a..b)
}

/// An image side: 1 to [`MAX_SIDE`].
pub fn side(s: &str) -> Result<u32, String> {
    whole(s, 1..=MAX_SIDE)
}

/// Samples per pixel: 1 to [`MAX_SPP`].
pub fn spp(s: &str) -> Result<u32, String> {
    whole(s, 1..=MAX_SPP)
}

/// Bounces: 0 to 64.
pub fn depth(s: &str) -> Result<u32, String> {
    whole(s, 0..=64)
}

/// Any u32 (a seed).
pub fn seed(s: &str) -> Result<u32, String> {
    whole(s, 0..=u32::MAX)
}

/// Paths in flight: 64 to 2²⁴.
pub fn wavefront(s: &str) -> Result<u32, String> {
    whole(s, 64..=1 << 24)
}

/// Seconds: positive, finite, at most a week.
pub fn seconds(s: &str) -> Result<f64, String> {
    match real(s, f64::MIN..=f64::MAX)? {
        v if v > 0.0 && v <= 604_800.0 => Ok(v),
        _ => Err("give a positive number of seconds, at most 604800 (a week)".into()),
    }
}

/// Exposure in stops: −64 to 64.
pub fn stops(s: &str) -> Result<f32, String> {
    real(s, -64.0..=64.0).map(|v| v as f32)
}

/// Polar quadrature nodes of an isotropic fit: 2 to 4096.
pub fn resolution(s: &str) -> Result<usize, String> {
    whole(s, 2..=4096)
}

/// Azimuthal nodes of an anisotropic fit: 1 to 1024.
pub fn phi_resolution(s: &str) -> Result<usize, String> {
    whole(s, 1..=1024)
}

/// Power iterations: 1 to 10 000.
pub fn iterations(s: &str) -> Result<usize, String> {
    whole(s, 1..=10_000)
}

/// A convergence tolerance: in [1e-15, 1].
pub fn tolerance(s: &str) -> Result<f64, String> {
    real(s, 1e-15..=1.0)
}

/// An angle in degrees, finite, −360 to 360.
pub fn degrees(s: &str) -> Result<f64, String> {
    real(s, -360.0..=360.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_non_finite_values() {
        assert_eq!(side("480"), Ok(480));
        assert!(side("0").unwrap_err().contains("outside 1 to 16384"));
        assert!(side("-1").unwrap_err().contains("not a whole number"));
        assert!(spp("nan").is_err());
        assert_eq!(stops("-2"), Ok(-2.0));
        for bad in ["nan", "inf", "-inf", "1e300"] {
            assert!(stops(bad).is_err(), "{bad}");
            assert!(seconds(bad).is_err(), "{bad}");
            assert!(tolerance(bad).is_err(), "{bad}");
        }
        assert!(seconds("0").is_err());
        assert_eq!(tolerance("1e-9"), Ok(1e-9));
    }
}
