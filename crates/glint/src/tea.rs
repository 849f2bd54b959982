//! The glint model's hashes. The Tiny Encryption Algorithm (Wheeler and Needham 1994): 8 rounds
//! over the pair (v0, v1) with Facet's fixed key, the hash of the filterable glint model (Wang
//! et al. 2018), here for the few hashes a query takes once (its direction cells' keys, the
//! root's flake count). pcg3d (Jarzynski & Olano 2020) for the many a walk takes per node and per
//! flake (positions' splits, flake ids and positions, lit counts' draws): ~4× fewer operations
//! than 8 TEA rounds, and the lit-count walk on lavapipe was mostly TEA. The WGSL twins are in
//! `shaders/glint/tea.inc.wgsl`; tests check both against known answers.

/// The key k0..k3.
pub const KEY: [u32; 4] = [0xA341_316C, 0xC801_3EA4, 0xAD90_777D, 0x7E95_761E];
/// TEA's round constant δ.
pub const DELTA: u32 = 0x9e37_79b9;
/// Rounds of TEA per hash.
pub const ROUNDS: u32 = 8;
// shaders/glint/tea.inc.wgsl writes out at most 16 rounds.
const _: () = assert!(ROUNDS <= 16);

/// The override constants of `shaders/glint/tea.inc.wgsl`.
pub fn pipeline_constants() -> [(&'static str, f64); 6] {
    [
        ("TEA_K0", KEY[0] as f64),
        ("TEA_K1", KEY[1] as f64),
        ("TEA_K2", KEY[2] as f64),
        ("TEA_K3", KEY[3] as f64),
        ("TEA_DELTA", DELTA as f64),
        ("TEA_ROUNDS", ROUNDS as f64),
    ]
}

/// The 64-bit hash (v1 << 32) + v0 after 8 rounds.
pub fn tea(mut v0: u32, mut v1: u32) -> u64 {
    let mut sum = 0u32;
    for _ in 0..ROUNDS {
        sum = sum.wrapping_add(DELTA);
        // v0 += ((v1 << 4) + k0) ^ (v1 + sum) ^ ((v1 >> 5) + k1), and symmetrically for v1.
        v0 = v0.wrapping_add(
            (v1 << 4).wrapping_add(KEY[0]) ^ v1.wrapping_add(sum) ^ (v1 >> 5).wrapping_add(KEY[1]),
        );
        v1 = v1.wrapping_add(
            (v0 << 4).wrapping_add(KEY[2]) ^ v0.wrapping_add(sum) ^ (v0 >> 5).wrapping_add(KEY[3]),
        );
    }
    ((v1 as u64) << 32) | v0 as u64
}

/// A uniform number in [0, 1): the top 23 bits of the hash's low word as the mantissa of a
/// float in [1, 2), minus 1.
pub fn tea_unit(v0: u32, v1: u32) -> f32 {
    let low = tea(v0, v1) as u32;
    f32::from_bits(0x3f80_0000 | (low >> 9)) - 1.0
}

/// pcg3d (Jarzynski & Olano 2020): three well-mixed words from three, cheap on a GPU.
pub fn pcg3d(v: [u32; 3]) -> [u32; 3] {
    let mut v = v.map(|x| x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    let mix = |v: &mut [u32; 3]| {
        v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
        v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
        v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    };
    mix(&mut v);
    v = v.map(|x| x ^ (x >> 16));
    mix(&mut v);
    v
}

/// A word to a uniform in [0, 1) with 24 bits (exact in f32).
pub fn unit(x: u32) -> f64 {
    (x >> 8) as f64 / 16_777_216.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_answers() {
        assert_eq!(tea(0, 0), 0x18e6_9c3c_fbc8_40dd);
        assert_eq!(tea(1, 2), 0x7a45_99fc_d5fe_6546);
        assert_eq!(tea(12345, 678), 0x6955_6b69_8924_22ac);
        let u = tea_unit(0, 0);
        assert_eq!(u, f32::from_bits(0x3f80_0000 | (0xfbc8_40dd >> 9)) - 1.0);
        assert!((0.0..1.0).contains(&u));
    }

    #[test]
    fn uniform_numbers_are_uniform() {
        // Mean 1/2 and variance 1/12 within 5σ of their sampling error over 10⁵ keys.
        let n = 100_000;
        let xs: Vec<f64> = (0..n).map(|k| tea_unit(k, 7) as f64).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(
            (mean - 0.5).abs() < 5.0 * (1.0f64 / 12.0 / n as f64).sqrt(),
            "mean {mean}"
        );
        assert!(
            (var - 1.0 / 12.0).abs() < 5.0 * (1.0f64 / 180.0 / n as f64).sqrt(),
            "variance {var}"
        );
    }
}
