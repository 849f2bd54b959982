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

/// Entries of the G1 tables of the fast path, uniform in θ over [0, π/2].
const G1_TABLE: usize = 4096;

/// Geometry of one grid bin (rotation-independent).
#[derive(Clone, Copy, Debug)]
struct BinGeometry {
    cos_i: f32,
    cos_o: f32,
    theta_i: f32,
    theta_o: f32,
    /// λ(φ) of the correlated G2, φ the azimuth between wi and wo.
    corr: f32,
}

/// Per-bin geometry of the whole grid, computed once per process (the grid never changes).
fn geometry() -> &'static [BinGeometry] {
    static GEOMETRY: OnceLock<Vec<BinGeometry>> = OnceLock::new();
    GEOMETRY.get_or_init(|| {
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
                    cos_o: wo.z as f32,
                    theta_i: wi.z.clamp(-1.0, 1.0).acos() as f32,
                    theta_o: wo.z.clamp(-1.0, 1.0).acos() as f32,
                    corr: correlation(azimuth_between(wi, wo)) as f32,
                }
            })
            .collect()
    })
}

/// One valid sample: a MERL bin seen at azimuth rotation `rot`, with the source's value.
#[derive(Clone, Copy, Debug, Default)]
pub struct GridSample {
    /// Flat MERL bin index.
    pub bin: u32,
    /// Index into [`GridSamples::rotations`].
    pub rot: u8,
    /// θh bin and θd bin.
    pub i: u8,
    pub j: u8,
    pub cos_i: f32,
    pub cos_o: f32,
    /// θi and θo in units of the G1 table's step.
    pub gi: f32,
    pub go: f32,
    /// λ(φ) of the correlated G2.
    pub corr: f32,
    /// x = f_r cos θi per channel.
    pub x: [f32; 3],
    /// ln(1 + x) per channel.
    pub log_x: [f32; 3],
}

/// The valid samples of a source on the MERL grid.
pub struct GridSamples {
    /// Azimuths φh at which the grid is laid: [0] for isotropic sources.
    pub rotations: Vec<f64>,
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
            // per task (no intermediate vectors: the set is ~60 MB and page faults dominate).
            let per_i = THETA_D_RES * PHI_D_RES;
            let valid = |s: usize| {
                let g = &geo[s];
                g.cos_i > 0.0 && g.cos_o > 0.0 && table.value_at(s).is_some()
            };
            let counts: Vec<usize> = (0..THETA_H_RES)
                .into_par_iter()
                .map(|i| (i * per_i..(i + 1) * per_i).filter(|&s| valid(s)).count())
                .collect();
            let mut samples = vec![GridSample::default(); counts.iter().sum()];
            let mut chunks = Vec::with_capacity(THETA_H_RES);
            let mut rest = samples.as_mut_slice();
            for &n in &counts {
                let (head, tail) = rest.split_at_mut(n);
                chunks.push(head);
                rest = tail;
            }
            chunks.into_par_iter().enumerate().for_each(|(i, chunk)| {
                let valid_bins = (i * per_i..(i + 1) * per_i).filter_map(|s| {
                    let g = &geo[s];
                    if g.cos_i <= 0.0 || g.cos_o <= 0.0 {
                        return None;
                    }
                    table.value_at(s).map(|v| make_sample(s, 0, v, g))
                });
                chunk
                    .iter_mut()
                    .zip(valid_bins)
                    .for_each(|(out, s)| *out = s);
            });
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
                let (wi, wo) = sample_directions(s, rotations[r]);
                if wi.z <= 0.0 || wo.z <= 0.0 {
                    return None;
                }
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

    pub fn len(&self) -> usize {
        self.samples.len()
    }

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
    let step = (G1_TABLE - 1) as f32 / FRAC_PI_2 as f32;
    GridSample {
        bin: s as u32,
        rot,
        i: (s / (PHI_D_RES * THETA_D_RES)) as u8,
        j: (s / PHI_D_RES % THETA_D_RES) as u8,
        cos_i: g.cos_i,
        cos_o: g.cos_o,
        gi: g.theta_i * step,
        go: g.theta_o * step,
        corr: g.corr,
        x,
        log_x: x.map(ln_1p),
    }
}

/// ln(1 + x) in f32 for x ≥ 0, to ~1e-7 relative: exponent and mantissa split, the mantissa
/// m ∈ [√½, √2) through ln m = 2 atanh(t), t = (m − 1)/(m + 1), |t| ≤ 0.172, series to t⁹.
/// The metric spends most of its time here; libm's log1pf is several times slower.
#[inline]
pub fn ln_1p(x: f32) -> f32 {
    let y = 1.0 + x.max(0.0);
    let bits = y.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 127;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    if m > std::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let series =
        t * (2.0 + t2 * (2.0 / 3.0 + t2 * (2.0 / 5.0 + t2 * (2.0 / 7.0 + t2 * (2.0 / 9.0)))));
    e as f32 * std::f32::consts::LN_2 + series
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
    /// G1 on [0, π/2], uniform in θ (interpolated as G1, which stays bounded at grazing
    /// angles where Λ diverges).
    g1: Vec<f64>,
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
        let g1 = (0..G1_TABLE)
            .map(|k| {
                let t = k as f64 / (G1_TABLE - 1) as f64 * FRAC_PI_2;
                1.0 / (1.0 + model.ndf.lambda(crate::geometry::spherical(t, 0.0)))
            })
            .collect();
        let fresnel =
            std::array::from_fn(|j| model.fresnel.eval(bin_angles(0, j, 0).theta_d.cos()));
        Some(IsoTables {
            d,
            g1,
            fresnel,
            diffuse: model.diffuse.map(|k| k / PI),
        })
    }

    /// The same model with another Fresnel table.
    pub fn set_fresnel(&mut self, f: &[Rgb]) {
        self.fresnel.copy_from_slice(&f[..THETA_D_RES]);
    }

    /// Λ at θ given in table steps.
    #[inline]
    fn lambda(&self, x: f32) -> f64 {
        let k = (x as usize).min(G1_TABLE - 2);
        let t = x as f64 - k as f64;
        let g = self.g1[k] + t * (self.g1[k + 1] - self.g1[k]);
        if g <= 0.0 {
            f64::INFINITY
        } else {
            1.0 / g - 1.0
        }
    }

    /// D G2 / (4 cos θo): x = f cos θi of the model with F = 1 and no diffuse term.
    #[inline]
    fn x_ideal(&self, s: &GridSample) -> f64 {
        self.d[s.i as usize] * g2(self.lambda(s.gi), self.lambda(s.go), s.corr as f64)
            / (4.0 * s.cos_o as f64)
    }

    #[inline]
    fn x(&self, s: &GridSample) -> Rgb {
        let ideal = self.x_ideal(s);
        let f = self.fresnel[s.j as usize];
        std::array::from_fn(|c| f[c] * ideal + self.diffuse[c] * s.cos_i as f64)
    }

    /// Σ over samples of Σ_c |ln(1 + x_model) − ln(1 + x_data)|.
    fn log_error_sum(&self, set: &GridSamples) -> f64 {
        set.samples
            .par_iter()
            .with_min_len(4096)
            .map(|s| log_diff(self.x(s), s))
            .sum()
    }

    /// F per θd bin for this model's D and G (see [`fresnel_average`]).
    pub fn fresnel_average(&self, set: &GridSamples) -> Vec<Rgb> {
        average_per_theta_d(set, |s| self.x_ideal(s))
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
    let per_bin: Vec<Option<Rgb>> = acc
        .iter()
        .map(|(x, w)| (*w > 0.0).then(|| x.map(|v| v / w)))
        .collect();
    merl::fill_missing(&per_bin).unwrap_or_else(|| vec![[1.0; 3]; THETA_D_RES])
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
