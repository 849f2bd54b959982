//! Timing: medians of repeated runs after a warm-up.

use crate::error::Result;
use std::time::Instant;

/// Median of `runs` timed calls of `f` (ms) after one untimed call when runs > 1.
pub fn median_ms(runs: usize, mut f: impl FnMut() -> Result<()>) -> Result<f64> {
    if runs > 1 {
        f()?;
    }
    let mut t: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let s = Instant::now();
            f().map(|_| s.elapsed().as_secs_f64() * 1e3)
        })
        .collect::<Result<_>>()?;
    Ok(median(&mut t))
}

/// The median of `t` (sorts it; the upper one of an even count).
pub fn median(t: &mut [f64]) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}
