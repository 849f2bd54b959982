//! χ² goodness of fit of a sampler of directions on the upper hemisphere against its pdf: how
//! Facet's tests check every sampler (CPU and WGSL), usable for yours.
//!
//! Samples are binned on [`N_THETA`] × [`N_PHI`] cells uniform in (√(θ / (π/2)), φ) (finer near
//! the pole, where narrow lobes live); the expected count of a cell is the pdf integrated over it
//! by a midpoint rule; cells expecting fewer than 5 samples are pooled. The statistic's z score
//! follows Wilson–Hilferty: (χ²/k)^⅓ is about normal with mean 1 − 2/9k and variance 2/9k.

use glam::DVec3;
use std::f64::consts::PI;

/// Polar cells of the histogram.
pub const N_THETA: usize = 16;
/// Azimuthal cells of the histogram.
pub const N_PHI: usize = 32;

/// The outcome of [`chi2_hemisphere`].
#[derive(Clone, Copy, Debug)]
pub struct Chi2 {
    /// ∫ pdf over the hemisphere by the same midpoint rule (1 for a normalised pdf).
    pub integral: f64,
    /// Σ (observed − expected)² / expected over the compared cells.
    pub chi2: f64,
    /// Degrees of freedom: cells compared, less one.
    pub dof: f64,
    /// The statistic as a standard normal score: above 5 is a one-in-3·10⁶ accident for a
    /// sampler that follows its pdf.
    pub z: f64,
}

/// Bins `samples` (unit vectors; those below the horizon fall into the last ring) and compares
/// them with `pdf` (over solid angle) integrated on each cell by a `sub` × `sub` midpoint rule
/// in (x, φ), θ = (π/2) x², dω = sin θ · π x dx dφ.
pub fn chi2_hemisphere(samples: &[DVec3], pdf: impl Fn(DVec3) -> f64, sub: usize) -> Chi2 {
    let n = samples.len() as f64;
    let mut hist = vec![0f64; N_THETA * N_PHI];
    for h in samples {
        let x = (h.z.clamp(-1.0, 1.0).acos() / (0.5 * PI)).sqrt();
        let ci = ((x * N_THETA as f64) as usize).min(N_THETA - 1);
        let phi = h.y.atan2(h.x).rem_euclid(2.0 * PI);
        let pi = ((phi / (2.0 * PI)) * N_PHI as f64) as usize % N_PHI;
        hist[ci * N_PHI + pi] += 1.0;
    }
    let (mut chi2, mut integral, mut dof) = (0.0, 0.0, 0usize);
    let (mut pool_o, mut pool_e) = (0.0, 0.0);
    for ci in 0..N_THETA {
        for pi in 0..N_PHI {
            let mut e = 0.0;
            for a in 0..sub {
                let x = (ci as f64 + (a as f64 + 0.5) / sub as f64) / N_THETA as f64;
                let theta = 0.5 * PI * x * x;
                let (s, c) = theta.sin_cos();
                let jacobian = s * PI * x;
                for b in 0..sub {
                    let phi = 2.0 * PI * (pi as f64 + (b as f64 + 0.5) / sub as f64) / N_PHI as f64;
                    e += pdf(DVec3::new(s * phi.cos(), s * phi.sin(), c)) * jacobian;
                }
            }
            e *= (1.0 / N_THETA as f64) * (2.0 * PI / N_PHI as f64) / (sub * sub) as f64;
            integral += e;
            let (o, e) = (hist[ci * N_PHI + pi], e * n);
            if e < 5.0 {
                pool_o += o;
                pool_e += e;
            } else {
                chi2 += (o - e).powi(2) / e;
                dof += 1;
            }
        }
    }
    if pool_e > 0.0 {
        chi2 += (pool_o - pool_e).powi(2) / pool_e.max(1.0);
        dof += 1;
    }
    let k = dof.saturating_sub(1).max(1) as f64;
    let z = ((chi2 / k).cbrt() - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    Chi2 {
        integral,
        chi2,
        dof: k,
        z,
    }
}

/// Independent uniform numbers in [0, 1) from a seed (SplitMix64), so that χ² has its
/// textbook law.
pub fn uniforms(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
