//! Filling gaps in tabulated curves.

/// Linear RGB, as [`crate::model::rgb::Rgb`] (a plain array, so this layer imports nothing).
type Rgb = [f64; 3];

/// Fills `None` entries by linear interpolation between the nearest valid neighbours (constant
/// beyond the ends). `None` if nothing is valid.
pub fn fill_missing(v: &[Option<Rgb>]) -> Option<Vec<Rgb>> {
    let valid: Vec<usize> = (0..v.len()).filter(|&i| v[i].is_some()).collect();
    let (&first, &last) = (valid.first()?, valid.last()?);
    Some(
        (0..v.len())
            .map(|i| match v[i] {
                Some(x) => x,
                None if i < first => v[first].unwrap(),
                None if i > last => v[last].unwrap(),
                None => {
                    let hi = valid.partition_point(|&x| x < i);
                    let (a, b) = (valid[hi - 1], valid[hi]);
                    let t = (i - a) as f64 / (b - a) as f64;
                    let (va, vb) = (v[a].unwrap(), v[b].unwrap());
                    std::array::from_fn(|c| va[c] + t * (vb[c] - va[c]))
                }
            })
            .collect(),
    )
}
