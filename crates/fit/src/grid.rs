//! The MERL grid as a set of valid samples, and microfacet models evaluated on it.
//!
//! The Fresnel average and the error metric both run over every valid sample of a source on
//! the MERL grid (bin lower edges, both directions above the horizon, the sample present).
//! Isotropic microfacet models take a fast path: D depends only on the θh bin, F only on the
//! θd bin and G1 only on θ, so each is a small table; `tests/grid.rs` checks it against the
//! direct evaluation.

use crate::brdf::{Brdf, Rgb};
use crate::geometry::{HalfDiff, azimuth_between, from_half_diff};
use crate::merl::{self, PHI_D_RES, SAMPLES, THETA_D_RES, THETA_H_RES, bin_angles};
use crate::microfacet::{MicrofacetBrdf, Ndf, correlation, g2};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

/// Entries of the Λ cos θ tables of the fast path, uniform in θ over [0, π/2].
const LAMBDA_TABLE: usize = 4096;

/// Geometry of one grid bin (rotation-independent), in the form the inner loops use.
#[derive(Clone, Copy, Debug)]
struct BinGeometry {
    cos_i: f32,
    inv_cos_i: f32,
    inv_cos_o: f32,
    /// θi and θo in units of the Λ cos θ table's step.
    gi: f32,
    go: f32,
    /// λ(φ) of the correlated G2, φ the azimuth between wi and wo.
    corr: f32,
}

/// Per-bin geometry of the whole grid, computed once per process (the grid never changes).
fn geometry() -> &'static [BinGeometry] {
    static GEOMETRY: OnceLock<Vec<BinGeometry>> = OnceLock::new();
    GEOMETRY.get_or_init(|| {
        let step = (LAMBDA_TABLE - 1) as f64 / FRAC_PI_2;
        (0..SAMPLES)
            .into_par_iter()
            .map(|s| {
                let (wi, wo) = from_half_diff(bin_angles(
                    s / (PHI_D_RES * THETA_D_RES),
                    s / PHI_D_RES % THETA_D_RES,
                    s % PHI_D_RES,
                ));
                BinGeometry {
                    cos_i: wi.z as f32,
                    inv_cos_i: (1.0 / wi.z) as f32,
                    inv_cos_o: (1.0 / wo.z) as f32,
                    gi: (wi.z.clamp(-1.0, 1.0).acos() * step) as f32,
                    go: (wo.z.clamp(-1.0, 1.0).acos() * step) as f32,
                    corr: correlation(azimuth_between(wi, wo)) as f32,
                }
            })
            .collect()
    })
}

fn above_horizon(g: &BinGeometry) -> bool {
    g.inv_cos_i > 0.0 && g.inv_cos_o > 0.0
}

/// The largest x = f_r cos θi a source may give on the MERL grid: a GGX mirror of α = 10⁻⁴ at
/// its peak stays below 10⁹; beyond 10¹² the f32 sums over 1.5·10⁶ samples of the Fresnel
/// average and the metric would overflow, so such values are refused with the value named.
pub const MAX_X: f32 = 1e12;

/// One valid sample: a MERL bin seen at azimuth rotation `rot`, with the source's value.
#[derive(Clone, Copy, Debug, Default)]
pub struct GridSample {
    /// Flat MERL bin index.
    pub bin: u32,
    /// Index into [`GridSamples::rotations`].
    pub rot: u8,
    /// θh bin and θd bin.
    pub i: u8,
    /// θd bin (`i` above is the θh bin).
    pub j: u8,
    /// x = f_r cos θi per channel.
    pub x: [f32; 3],
    /// ln(1 + x) per channel.
    pub log_x: [f32; 3],
}

/// The valid samples of a source on the MERL grid.
pub struct GridSamples {
    /// Azimuths φh at which the grid is laid: `[0]` for isotropic sources.
    pub rotations: Vec<f64>,
    /// The valid samples, in MERL bin order for each rotation.
    pub samples: Vec<GridSample>,
}

impl GridSamples {
    /// Every valid sample of the source: from its MERL table when isotropic; for an anisotropic
    /// source the grid is laid at four azimuths φh ∈ {0°, 45°, 90°, 135°}, every second θd and
    /// φd bin, to keep the sample count that of one full grid.
    pub fn new(src: &dyn Brdf) -> Self {
        if src.is_isotropic() {
            let table = src.merl_table();
            let geo = geometry();
            // Count the valid samples of each θh bin, then fill one allocation in place, a θh bin
            // per task (no intermediate vectors, no zeroing: page faults dominate this step).
            let per_i = THETA_D_RES * PHI_D_RES;
            let valid_in = |i: usize| {
                (i * per_i..(i + 1) * per_i).filter_map(|s| {
                    let g = &geo[s];
                    if !above_horizon(g) {
                        return None;
                    }
                    table.value_at(s).map(|v| make_sample(s, 0, v, g))
                })
            };
            let counts: Vec<usize> = (0..THETA_H_RES)
                .into_par_iter()
                .map(|i| {
                    (i * per_i..(i + 1) * per_i)
                        .filter(|&s| above_horizon(&geo[s]) && table.value_at(s).is_some())
                        .count()
                })
                .collect();
            let total = counts.iter().sum();
            let mut samples: Vec<GridSample> = Vec::with_capacity(total);
            let mut chunks = Vec::with_capacity(THETA_H_RES);
            let mut rest = &mut samples.spare_capacity_mut()[..total];
            for &n in &counts {
                let (head, tail) = rest.split_at_mut(n);
                chunks.push(head);
                rest = tail;
            }
            chunks.into_par_iter().enumerate().for_each(|(i, chunk)| {
                let mut written = 0;
                for (out, s) in chunk.iter_mut().zip(valid_in(i)) {
                    out.write(s);
                    written += 1;
                }
                assert_eq!(
                    written,
                    chunk.len(),
                    "the count and fill passes use one predicate"
                );
            });
            // SAFETY: every one of the `total` slots was written above (asserted per chunk).
            unsafe { samples.set_len(total) };
            return GridSamples {
                rotations: vec![0.0],
                samples,
            };
        }
        let rotations: Vec<f64> = (0..4).map(|r| r as f64 * PI / 4.0).collect();
        let samples = (0..SAMPLES * rotations.len())
            .into_par_iter()
            .filter_map(|sr| {
                let (s, r) = (sr % SAMPLES, sr / SAMPLES);
                let (j, k) = (s / PHI_D_RES % THETA_D_RES, s % PHI_D_RES);
                if j % 2 == 1 || k % 2 == 1 {
                    return None;
                }
                if !above_horizon(&geometry()[s]) {
                    return None;
                }
                let (wi, wo) = sample_directions(s, rotations[r]);
                let v = src.eval(wi, wo)?;
                Some(make_sample(s, r as u8, v, &geometry()[s]))
            })
            .collect();
        GridSamples { rotations, samples }
    }

    /// Every `stride`-th sample: the cheap set that parameter searches run on.
    pub fn subsample(&self, stride: usize) -> GridSamples {
        GridSamples {
            rotations: self.rotations.clone(),
            samples: self
                .samples
                .iter()
                .step_by(stride.max(1))
                .copied()
                .collect(),
        }
    }

    /// The number of valid samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Whether there is no valid sample.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// (wi, wo) of a sample.
    pub fn directions(&self, s: &GridSample) -> (DVec3, DVec3) {
        sample_directions(s.bin as usize, self.rotations[s.rot as usize])
    }
}

fn make_sample(s: usize, rot: u8, v: Rgb, g: &BinGeometry) -> GridSample {
    let x = v.map(|f| (f * g.cos_i as f64) as f32);
    GridSample {
        bin: s as u32,
        rot,
        i: (s / (PHI_D_RES * THETA_D_RES)) as u8,
        j: (s / PHI_D_RES % THETA_D_RES) as u8,
        x,
        log_x: x.map(ln_1p),
    }
}

/// ln(1 + x) in f32 for x ≥ 0, to ~2e-7: exponent and mantissa split, the mantissa brought
/// into m ∈ [√½, √2) and ln m = t·P(t), t = m − 1, P a degree-7 Chebyshev fit (max error
/// 6e-8). No division and no branch: the metric spends most of its time here, and libm's
/// log1pf is several times slower.
#[inline]
pub fn ln_1p(x: f32) -> f32 {
    const P: [f32; 8] = [
        0.999_999_94,
        -0.500_003_64,
        0.333_351_14,
        -0.249_700_68,
        0.198_985_44,
        -0.172_470_51,
        0.162_343_81,
        -0.101_341_79,
    ];
    let y = 1.0 + x.max(0.0);
    let bits = y.to_bits();
    let m1 = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    // Branch-free: mantissas are random, a branch would mispredict half the time.
    let up = (m1 > std::f32::consts::SQRT_2) as u32;
    let m = f32::from_bits(m1.to_bits() - (up << 23));
    let e = ((bits >> 23) & 0xff) as i32 - 127 + up as i32;
    let t = m - 1.0;
    // Estrin's scheme: shorter dependency chains than Horner.
    let t2 = t * t;
    let t4 = t2 * t2;
    let p01 = P[0] + P[1] * t;
    let p23 = P[2] + P[3] * t;
    let p45 = P[4] + P[5] * t;
    let p67 = P[6] + P[7] * t;
    let p = (p01 + p23 * t2) + (p45 + p67 * t2) * t4;
    e as f32 * std::f32::consts::LN_2 + t * p
}

fn sample_directions(s: usize, phi_h: f64) -> (DVec3, DVec3) {
    let a = bin_angles(
        s / (PHI_D_RES * THETA_D_RES),
        s / PHI_D_RES % THETA_D_RES,
        s % PHI_D_RES,
    );
    from_half_diff(HalfDiff { phi_h, ..a })
}

/// An isotropic microfacet model reduced to tables over the grid's bins.
pub struct IsoTables {
    /// D at each θh bin.
    d: [f64; THETA_H_RES],
    /// Λ(θ) cos θ on [0, π/2], uniform in θ: finite at 90° where Λ diverges (GGX: α/2), so it
    /// interpolates well, and Λ = table · (1/cos θ) needs no division in the inner loop.
    lambda_cos: Vec<f64>,
    /// F at each θd bin.
    fresnel: [Rgb; THETA_D_RES],
    /// ρd/π.
    diffuse: Rgb,
}

impl IsoTables {
    /// Tables of an isotropic model; `None` for an anisotropic one (use the direct path).
    pub fn new(model: &MicrofacetBrdf) -> Option<Self> {
        if !model.ndf.is_isotropic()
            || matches!(model.ndf, Ndf::Analytic(a) if a.rotation != 0.0 && a.alpha_x != a.alpha_y)
        {
            return None;
        }
        let d = std::array::from_fn(|i| {
            model
                .ndf
                .d(crate::geometry::spherical(bin_angles(i, 0, 0).theta_h, 0.0))
        });
        let mut lambda_cos: Vec<f64> = (0..LAMBDA_TABLE - 1)
            .map(|k| {
                let t = k as f64 / (LAMBDA_TABLE - 1) as f64 * FRAC_PI_2;
                model.ndf.lambda(crate::geometry::spherical(t, 0.0)) * t.cos()
            })
            .collect();
        // At 90° Λ cos θ is ∞ · 0: extrapolate linearly from the two entries before it.
        let n = lambda_cos.len();
        lambda_cos.push((2.0 * lambda_cos[n - 1] - lambda_cos[n - 2]).max(0.0));
        let fresnel =
            std::array::from_fn(|j| model.fresnel.eval(bin_angles(0, j, 0).theta_d.cos()));
        Some(IsoTables {
            d,
            lambda_cos,
            fresnel,
            diffuse: model.diffuse.map(|k| k / PI),
        })
    }

    /// D per θh bin.
    #[cfg(feature = "gpu")]
    pub(crate) fn d_table(&self) -> &[f64] {
        &self.d
    }

    /// Λ cos θ, uniform in θ over [0, π/2].
    #[cfg(feature = "gpu")]
    pub(crate) fn lambda_cos_table(&self) -> &[f64] {
        &self.lambda_cos
    }

    /// The same model with another Fresnel table.
    pub fn set_fresnel(&mut self, f: &[Rgb]) {
        self.fresnel.copy_from_slice(&f[..THETA_D_RES]);
    }

    /// Λ cos θ at θ given in table steps.
    #[inline]
    fn lambda_cos(&self, x: f32) -> f64 {
        let k = (x as usize).min(LAMBDA_TABLE - 2);
        let t = x as f64 - k as f64;
        self.lambda_cos[k] + t * (self.lambda_cos[k + 1] - self.lambda_cos[k])
    }

    /// D G2 / (4 cos θo): x = f cos θi of the model with F = 1 and no diffuse term; one
    /// division (G2's).
    #[inline(always)]
    fn x_ideal(&self, g: &BinGeometry, s: &GridSample) -> f64 {
        let li = self.lambda_cos(g.gi) * g.inv_cos_i as f64;
        let lo = self.lambda_cos(g.go) * g.inv_cos_o as f64;
        self.d[s.i as usize] * 0.25 * g.inv_cos_o as f64 * g2(li, lo, g.corr as f64)
    }

    #[inline]
    fn x(&self, g: &BinGeometry, s: &GridSample) -> Rgb {
        let ideal = self.x_ideal(g, s);
        let f = self.fresnel[s.j as usize];
        std::array::from_fn(|c| f[c] * ideal + self.diffuse[c] * g.cos_i as f64)
    }

    /// Σ over samples of Σ_c |ln(1 + x_model) − ln(1 + x_data)|.
    fn log_error_sum(&self, set: &GridSamples) -> f64 {
        let geo = geometry();
        set.samples
            .par_iter()
            .with_min_len(4096)
            .map(|s| log_diff(self.x(&geo[s.bin as usize], s), s))
            .sum()
    }

    /// F per θd bin for this model's D and G (see [`fresnel_average`]).
    pub fn fresnel_average(&self, set: &GridSamples) -> Vec<Rgb> {
        let geo = geometry();
        average_per_theta_d(set, |s| self.x_ideal(&geo[s.bin as usize], s))
    }
}

/// x = f cos θi of any BRDF at a sample (`None` where the model has no value).
fn x_direct(model: &dyn Brdf, set: &GridSamples, s: &GridSample) -> Option<Rgb> {
    let (wi, wo) = set.directions(s);
    model.eval(wi, wo).map(|f| f.map(|v| v * wi.z))
}

/// The error metric of the design notes: mean over valid samples and channels of
/// |ln(1 + x_model) − ln(1 + x_data)|, x = f_r cos θi. Samples where the model has no value
/// are left out.
pub fn error_metric(model: &dyn Brdf, set: &GridSamples) -> f64 {
    let (sum, count) = set
        .samples
        .par_iter()
        .filter_map(|s| x_direct(model, set, s).map(|x| log_diff(x, s)))
        .fold(|| (0.0, 0usize), |(a, n), e| (a + e, n + 1))
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    sum / (3 * count.max(1)) as f64
}

/// [`error_metric`] of a microfacet model, through its tables when it is isotropic.
pub fn microfacet_error(model: &MicrofacetBrdf, set: &GridSamples) -> f64 {
    let Some(tables) = IsoTables::new(model).filter(|_| set.rotations.len() == 1) else {
        return error_metric(model, set);
    };
    tables.log_error_sum(set) / (3 * set.len().max(1)) as f64
}

/// Error of an isotropic model given as tables (the parameter searches' inner loop).
pub fn tables_error(tables: &IsoTables, set: &GridSamples) -> f64 {
    tables.log_error_sum(set) / (3 * set.len().max(1)) as f64
}

#[inline]
fn log_diff(x: Rgb, s: &GridSample) -> f64 {
    (0..3)
        .map(|c| (ln_1p(x[c] as f32) - s.log_x[c]).abs())
        .sum::<f32>() as f64
}

/// Fresnel per θd bin and channel: F_j = Σ x_data / Σ x_ideal over the valid samples of bin j,
/// x_ideal = D G2 / (4 cos θo) of `model` (its own Fresnel and diffuse term are ignored). This
/// is the mean of f / f_ideal weighted by x_ideal, which keeps noisy tails (tiny f_ideal) from
/// dominating. Bins without samples are filled by interpolation.
pub fn fresnel_average(model: &MicrofacetBrdf, set: &GridSamples) -> Vec<Rgb> {
    match IsoTables::new(model).filter(|_| set.rotations.len() == 1) {
        Some(t) => t.fresnel_average(set),
        None => average_per_theta_d(set, |s| {
            let (wi, wo) = set.directions(s);
            model.eval_ideal(wi, wo) * wi.z
        }),
    }
}

/// For the GPU upload: (θi, θo in Λ-table steps, 1/cos θi, 1/cos θo, λ(φ)) of a sample.
#[cfg(feature = "gpu")]
pub(crate) fn sample_geometry(s: &GridSample) -> [f32; 5] {
    let g = &geometry()[s.bin as usize];
    [g.gi, g.go, g.inv_cos_i, g.inv_cos_o, g.corr]
}

/// F per θd bin from the sums (Σ x_data per channel, Σ x_ideal); empty bins interpolated.
pub(crate) fn fresnel_from_sums(acc: &[([f64; 3], f64)]) -> Vec<Rgb> {
    let per_bin: Vec<Option<Rgb>> = acc
        .iter()
        .map(|(x, w)| (*w > 0.0).then(|| x.map(|v| v / w)))
        .collect();
    merl::fill_missing(&per_bin).unwrap_or_else(|| vec![[1.0; 3]; THETA_D_RES])
}

/// Σ x_data / Σ x_ideal per θd bin, empty bins filled by interpolation.
fn average_per_theta_d(set: &GridSamples, ideal: impl Fn(&GridSample) -> f64 + Sync) -> Vec<Rgb> {
    type Acc = Vec<([f64; 3], f64)>;
    let acc: Acc = set
        .samples
        .par_iter()
        .with_min_len(4096)
        .fold(
            || vec![([0.0; 3], 0.0); THETA_D_RES],
            |mut acc: Acc, s| {
                let xi = ideal(s);
                if xi.is_finite() && xi > 0.0 {
                    let a = &mut acc[s.j as usize];
                    (0..3).for_each(|c| a.0[c] += s.x[c] as f64);
                    a.1 += xi;
                }
                acc
            },
        )
        .reduce(
            || vec![([0.0; 3], 0.0); THETA_D_RES],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    (0..3).for_each(|c| x.0[c] += y.0[c]);
                    x.1 += y.1;
                }
                a
            },
        );
    fresnel_from_sums(&acc)
}

#[cfg(test)]
mod tests {
    #[test]
    fn fast_ln_1p_matches_libm() {
        let mut worst = 0.0f32;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if !x.is_finite() {
                break;
            }
            let (a, b) = (super::ln_1p(x), x.ln_1p());
            // Absolute below 1 (1 + x rounds in f32 for tiny x), relative above.
            worst = worst.max((a - b).abs() / b.max(1.0));
        }
        assert!(worst < 3e-7, "worst error {worst}");
    }
}
