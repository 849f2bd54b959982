//! Order statistics of measured values (the examples' and benchmarks' medians and p90s).

/// The `q`-quantile of `v` (0 ≤ q ≤ 1) by the nearest rank: the element at round((n − 1) q) of
/// the sorted values. `v` must not be empty.
pub fn quantile(v: &[f64], q: f64) -> f64 {
    debug_assert!(!v.is_empty() && (0.0..=1.0).contains(&q));
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// The median of `v` (the upper one of an even count), reordering `v` in place: O(n), for the
/// metric's floor over a grid's samples. 0 when `v` is empty.
pub fn median_in_place(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
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
