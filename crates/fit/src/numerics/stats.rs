//! Order statistics of measured values (the examples' and benchmarks' medians and p90s).

/// The `q`-quantile of `v` (0 ≤ q ≤ 1) by the nearest rank: the element at round((n − 1) q) of
/// the sorted values. `v` must not be empty.
pub fn quantile(v: &[f64], q: f64) -> f64 {
    debug_assert!(!v.is_empty() && (0.0..=1.0).contains(&q));
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

#[cfg(test)]
mod tests {
    #[test]
    fn quantile_is_the_nearest_rank() {
        let v = [5.0, 1.0, 4.0, 2.0, 3.0];
        assert_eq!(super::quantile(&v, 0.5), 3.0);
        assert_eq!(super::quantile(&v, 0.0), 1.0);
        assert_eq!(super::quantile(&v, 1.0), 5.0);
        // round(4 · 0.9) = 4: the largest.
        assert_eq!(super::quantile(&v, 0.9), 5.0);
    }
}
