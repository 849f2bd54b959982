//! The MERL grid as a set of valid samples, and microfacet models evaluated on it.
//!
//! The Fresnel average and the error metric both run over every valid sample of a source on
//! the MERL grid (bin lower edges, both directions above the horizon, the sample present).
//! Isotropic sources are held in a compact row form (`iso_grid.rs`), and isotropic
//! microfacet models take a fast path there: D depends only on the θh bin, F only on the θd
//! bin and Λ only on cos θ, so each is a small table; `tests/grid.rs` checks it against the
//! direct evaluation.

use crate::brdf::{Brdf, Rgb};
use crate::fresnel::Fresnel;
use crate::geometry::{HalfDiff, azimuth_between, from_half_diff};
use crate::iso_grid::{CoarseSamples, IsoSamples};
use crate::lambda_table::lambda_cos_table;
use crate::merl::{self, PHI_D_RES, SAMPLES, THETA_D_RES, THETA_H_RES, bin_angles};
use crate::microfacet::{MicrofacetBrdf, Ndf, correlation, g2};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

pub(crate) use crate::lambda_table::LAMBDA_TABLE;

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
    /// The samples as a list: given for anisotropic sources, built on first use from the
    /// compact form for isotropic ones.
    samples: OnceLock<Vec<GridSample>>,
    /// The compact form of an isotropic source's samples.
    pub(crate) iso: Option<IsoSamples>,
}

impl GridSamples {
    /// Every valid sample of the source: from its MERL table when isotropic; for an anisotropic
    /// source the grid is laid at four azimuths φh ∈ {0°, 45°, 90°, 135°}, every second θd and
    /// φd bin, to keep the sample count that of one full grid.
    pub fn new(src: &dyn Brdf) -> Self {
        if src.is_isotropic() {
            return GridSamples {
                rotations: vec![0.0],
                samples: OnceLock::new(),
                iso: Some(IsoSamples::new(src)),
            };
        }
        let rotations: Vec<f64> = (0..4).map(|r| r as f64 * PI / 4.0).collect();
        let samples: Vec<GridSample> = (0..SAMPLES * rotations.len())
            .into_par_iter()
            .filter_map(|sr| {
                let (s, r) = (sr % SAMPLES, sr / SAMPLES);
                let (j, k) = (s / PHI_D_RES % THETA_D_RES, s % PHI_D_RES);
                if j % 2 == 1 || k % 2 == 1 {
                    return None;
                }
                let (wi, wo) = sample_directions(s, rotations[r]);
                if !(wi.z > 0.0 && wo.z > 0.0) {
                    return None;
                }
                let v = src.eval(wi, wo)?;
                Some(make_sample(s, r as u8, v, wi.z))
            })
            .collect();
        GridSamples {
            rotations,
            samples: OnceLock::from(samples),
            iso: None,
        }
    }

    /// A cheaper set for parameter searches: every `stride`-th (θh, θd) row holding samples,
    /// with all its φd bins, of an isotropic source; every `stride`-th sample otherwise.
    pub fn subsample(&self, stride: usize) -> GridSamples {
        if let Some(iso) = &self.iso {
            return GridSamples {
                rotations: self.rotations.clone(),
                samples: OnceLock::new(),
                iso: Some(iso.subsample(stride)),
            };
        }
        GridSamples {
            rotations: self.rotations.clone(),
            samples: OnceLock::from(
                self.samples()
                    .iter()
                    .step_by(stride.max(1))
                    .copied()
                    .collect::<Vec<_>>(),
            ),
            iso: None,
        }
    }

    /// About one (θh, θd) row in `stride` of an isotropic source such that every θh and every
    /// θd bin keeps its share: the rows with (θh bin + θd bin) ≡ 0 mod `stride`, the set on
    /// which per-bin F and ρd are solved. Anisotropic sets: [`Self::subsample`].
    pub fn diagonal(&self, stride: usize) -> GridSamples {
        match &self.iso {
            Some(iso) => GridSamples {
                rotations: self.rotations.clone(),
                samples: OnceLock::new(),
                iso: Some(iso.diagonal(stride)),
            },
            None => self.subsample(stride),
        }
    }

    /// The rows of an isotropic set with every fourth φd bin ([`CoarseGrid`]); `None` for an
    /// anisotropic one.
    pub fn coarse(&self) -> Option<CoarseGrid> {
        Some(CoarseGrid(self.iso.as_ref()?.coarse()))
    }

    /// The valid samples, in MERL bin order for each rotation. For an isotropic source they are
    /// built from the compact form on first use (x from ln(1 + x), to f32 precision).
    pub fn samples(&self) -> &[GridSample] {
        self.samples.get_or_init(|| {
            let iso = self
                .iso
                .as_ref()
                .expect("a set without a list is isotropic");
            iso.rows
                .iter()
                .flat_map(|&r| iso.row_samples(r as usize))
                .map(|(s, log_x)| GridSample {
                    bin: s as u32,
                    rot: 0,
                    i: (s / (PHI_D_RES * THETA_D_RES)) as u8,
                    j: (s / PHI_D_RES % THETA_D_RES) as u8,
                    x: log_x.map(|l| (l as f64).exp_m1() as f32),
                    log_x,
                })
                .collect()
        })
    }

    /// The first sample whose x = f_r cos θi is not finite or beyond ±[`MAX_X`].
    pub fn out_of_range(&self) -> Option<GridSample> {
        if let Some(iso) = &self.iso {
            return iso.data.out_of_range.map(|(s, x)| GridSample {
                bin: s as u32,
                rot: 0,
                i: (s / (PHI_D_RES * THETA_D_RES)) as u8,
                j: (s / PHI_D_RES % THETA_D_RES) as u8,
                x,
                log_x: [0.0; 3],
            });
        }
        self.samples()
            .iter()
            .find(|s| s.x.iter().any(|x| !(x.abs() <= MAX_X)))
            .copied()
    }

    /// The number of valid samples.
    pub fn len(&self) -> usize {
        match &self.iso {
            Some(iso) => iso.count,
            None => self.samples().len(),
        }
    }

    /// Whether there is no valid sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// (wi, wo) of a sample.
    pub fn directions(&self, s: &GridSample) -> (DVec3, DVec3) {
        sample_directions(s.bin as usize, self.rotations[s.rot as usize])
    }
}

fn make_sample(s: usize, rot: u8, v: Rgb, cos_i: f64) -> GridSample {
    let x = v.map(|f| (f * cos_i) as f32);
    GridSample {
        bin: s as u32,
        rot,
        i: (s / (PHI_D_RES * THETA_D_RES)) as u8,
        j: (s / PHI_D_RES % THETA_D_RES) as u8,
        x,
        log_x: x.map(ln_1p),
    }
}

/// e^y − 1 in f32 for y ≥ 0 (clamped to [0, 88]), to ~1.2e-7 relative: x recovered from the
/// grid's stored ln(1 + x) ([`ln_1p`]). Below y = 1/2 the series y + y²/2! + … + y⁸/8!
/// (remainder below y⁹/9! ≤ 5.4e-9 relative); above, 2ⁿ e^r − 1, n = ⌊y / ln 2 + ½⌋,
/// r = y − n ln 2 ∈ [−ln 2 / 2, ln 2 / 2] (ln 2 in two parts) and e^r to r⁷/7! (remainder
/// below 6e-9). No branch (both are computed and one selected), and no division: the series'
/// 1/k are constants (a division per term made this the cost of copying rows, 18 cycles a
/// value).
#[inline(always)]
pub fn exp_m1(y: f32) -> f32 {
    const LN2_HI: f32 = 0.693_145_75; // 0x3f317200: n · LN2_HI is exact for n < 2⁸
    const LN2_LO: f32 = 1.428_606_8e-6;
    /// 1/k for k = 0..8 (0 unused).
    const INV: [f32; 9] = [
        0.0,
        1.0,
        0.5,
        1.0 / 3.0,
        0.25,
        0.2,
        1.0 / 6.0,
        1.0 / 7.0,
        0.125,
    ];
    // max before min, not clamp: a NaN becomes 0, so n below is in range.
    #[allow(clippy::manual_clamp)]
    let y = y.max(0.0).min(88.0);
    // y (1 + y/2 (1 + y/3 (… (1 + y/8))))
    let mut small = 1.0 + y * INV[8];
    for k in (2..8).rev() {
        small = 1.0 + y * INV[k] * small;
    }
    small *= y;
    // SAFETY: y / ln 2 + ½ is finite and in [0.5, 127.5]: well inside i32.
    let n = unsafe { (y * std::f32::consts::LOG2_E + 0.5).to_int_unchecked::<i32>() };
    let r = (y - n as f32 * LN2_HI) - n as f32 * LN2_LO;
    // 1 + r (1 + r/2 (… (1 + r/7)))
    let mut e = 1.0 + r * INV[7];
    for k in (1..7).rev() {
        e = 1.0 + r * INV[k] * e;
    }
    let large = f32::from_bits(((n + 127) as u32) << 23) * e - 1.0;
    if y < 0.5 { small } else { large }
}

/// ln(1 + x) in f32 for x ≥ 0, to ~2e-7 relative: [`ln_1p_abs`] where 1 + x is exact enough;
/// below x = 1/16, where rounding 1 + x would cost relative accuracy, the series
/// x − x²/2 + x³/3 − x⁴/4 + x⁵/5 (error below x⁶/6 ≤ 1e-8, 1.6e-7 relative) is taken instead, so
/// that x is recovered from ln(1 + x) to f32 precision (the stored data). No branch (both are
/// computed and one selected).
#[inline(always)]
pub fn ln_1p(x: f32) -> f32 {
    let x = x.max(0.0);
    let small = x * (1.0 + x * (-0.5 + x * (1.0 / 3.0 + x * (-0.25 + x * 0.2))));
    if x < 0.0625 { small } else { ln_1p_abs(x) }
}

/// ln m = t·P(t), t = m − 1 ∈ [√½ − 1, √2 − 1): the coefficients of P, a degree-7 Chebyshev fit.
const LN_P: [f32; 8] = [
    0.999_999_94,
    -0.500_003_64,
    0.333_351_14,
    -0.249_700_68,
    0.198_985_44,
    -0.172_470_51,
    0.162_343_81,
    -0.101_341_79,
];

/// ln(1 + x) in f32 for x ≥ 0 to ~2e-7 absolute (relative above x = 1): exponent and mantissa
/// of y = 1 + x split, the mantissa brought into m ∈ [√½, √2) and ln m = t·P(t), t = m − 1, P a
/// degree-7 Chebyshev fit (max error 6e-8). For tiny x the rounding of 1 + x costs relative,
/// not absolute, accuracy: what the metric's model side needs, |ln(1 + x_model) − ln(1 + x)|
/// being a sum of absolute differences. No division and no branch: the metric spends most of
/// its time here and vectorises it, and libm's log1pf is several times slower.
#[inline(always)]
pub fn ln_1p_abs(x: f32) -> f32 {
    ln_positive(1.0 + x.max(0.0))
}

/// ln y in f32 for finite y > 0, to ~2e-7 absolute for y near 1 and 1.5e-7 relative
/// elsewhere: [`ln_1p_abs`]'s method.
#[inline(always)]
pub fn ln_positive(y: f32) -> f32 {
    const P: [f32; 8] = LN_P;
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

/// [`ln_1p_abs`] with fused multiply-adds (one rounding each: results differ from it in the
/// last bits). For the passes' kernels, compiled with FMA where the CPU has it; elsewhere
/// `mul_add` is exact but emulated, several times slower.
#[inline(always)]
pub fn ln_1p_fused(x: f32) -> f32 {
    ln_positive_fused(1.0 + x.max(0.0))
}

/// [`ln_positive`] with fused multiply-adds (see [`ln_1p_fused`]).
#[inline(always)]
pub fn ln_positive_fused(y: f32) -> f32 {
    let bits = y.to_bits();
    let m1 = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let up = (m1 > std::f32::consts::SQRT_2) as u32;
    let m = f32::from_bits(m1.to_bits() - (up << 23));
    let e = ((bits >> 23) & 0xff) as i32 - 127 + up as i32;
    let t = m - 1.0;
    let t2 = t * t;
    let t4 = t2 * t2;
    let p01 = LN_P[1].mul_add(t, LN_P[0]);
    let p23 = LN_P[3].mul_add(t, LN_P[2]);
    let p45 = LN_P[5].mul_add(t, LN_P[4]);
    let p67 = LN_P[7].mul_add(t, LN_P[6]);
    let p = p67.mul_add(t2, p45).mul_add(t4, p23.mul_add(t2, p01));
    (e as f32).mul_add(std::f32::consts::LN_2, t * p)
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
#[derive(Clone)]
pub struct IsoTables {
    /// D at each θh bin, in f32 as the passes use it.
    pub(crate) d32: [f32; THETA_H_RES],
    /// Λ(θ) cos θ as a function of μ = cos θ on [0, 1], uniform in μ: finite at μ = 0 where Λ
    /// diverges (GGX: α/2), smooth in μ (GGX: (sqrt(μ² + α²(1 − μ²)) − μ) / 2), so it
    /// interpolates well, and a bin's table coordinate is its cosine times a constant: no acos.
    pub(crate) lambda_cos: Box<[f32; LAMBDA_TABLE]>,
    /// F at each θd bin.
    pub(crate) fresnel: [Rgb; THETA_D_RES],
    /// ρd/π.
    pub(crate) diffuse: Rgb,
}

impl IsoTables {
    /// Tables of an isotropic model; `None` for an anisotropic one (use the direct path).
    pub fn new(model: &MicrofacetBrdf) -> Option<Self> {
        if !model.ndf.is_isotropic()
            || matches!(model.ndf, Ndf::Analytic(a) if a.rotation != 0.0 && a.alpha_x != a.alpha_y)
        {
            return None;
        }
        let d32 = std::array::from_fn(|i| {
            model
                .ndf
                .d(crate::geometry::spherical(bin_angles(i, 0, 0).theta_h, 0.0)) as f32
        });
        let lambda_cos = lambda_cos_table(&model.ndf);
        let fresnel =
            std::array::from_fn(|j| model.fresnel.eval(bin_angles(0, j, 0).theta_d.cos()));
        Some(IsoTables {
            d32,
            lambda_cos,
            fresnel,
            diffuse: model.diffuse.map(|k| k / PI),
        })
    }

    /// D per θh bin.
    #[cfg(feature = "gpu")]
    pub(crate) fn d_table(&self) -> &[f32] {
        &self.d32
    }

    /// Λ cos θ, uniform in cos θ over [0, 1].
    #[cfg(feature = "gpu")]
    pub(crate) fn lambda_cos_table(&self) -> &[f32] {
        &self.lambda_cos[..]
    }

    /// The same model with another Fresnel table.
    pub fn set_fresnel(&mut self, f: &[Rgb]) {
        self.fresnel.copy_from_slice(&f[..THETA_D_RES]);
    }

    /// D G2 / (4 cos θo) at a sample of θh bin `i` given by its directions (the list path).
    fn x_ideal_at(&self, wi: DVec3, wo: DVec3, i: usize) -> f64 {
        let lambda = |mu: f64| {
            let x = (mu * (LAMBDA_TABLE - 1) as f64).clamp(0.0, (LAMBDA_TABLE - 1) as f64);
            let k = (x as usize).min(LAMBDA_TABLE - 2);
            let (a, b) = (self.lambda_cos[k] as f64, self.lambda_cos[k + 1] as f64);
            (a + (x - k as f64) * (b - a)) / mu
        };
        let g = g2(
            lambda(wi.z),
            lambda(wo.z),
            correlation(azimuth_between(wi, wo)),
        );
        self.d32[i] as f64 * g / (4.0 * wo.z)
    }

    /// Σ over samples of Σ_c |ln(1 + x_model) − ln(1 + x_data)|.
    fn log_error_sum(&self, set: &GridSamples) -> f64 {
        if let Some(iso) = &set.iso {
            return iso.log_error_sum(self);
        }
        set.samples()
            .par_iter()
            .with_min_len(4096)
            .map(|s| {
                let (wi, wo) = set.directions(s);
                let ideal = self.x_ideal_at(wi, wo, s.i as usize);
                let f = self.fresnel[s.j as usize];
                log_diff(
                    std::array::from_fn(|c| f[c] * ideal + self.diffuse[c] * wi.z),
                    s,
                )
            })
            .sum()
    }

    /// F per θd bin for this model's D and G (see [`fresnel_average`]).
    pub fn fresnel_average(&self, set: &GridSamples) -> Vec<Rgb> {
        if let Some(iso) = &set.iso {
            let num = iso.fresnel_numerators(self);
            let den = iso.ideal_sums(self);
            return fresnel_from_sums(&num.into_iter().zip(den).collect::<Vec<_>>());
        }
        average_per_theta_d(set, |s| {
            let (wi, wo) = set.directions(s);
            self.x_ideal_at(wi, wo, s.i as usize)
        })
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
        .samples()
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

/// The errors of `model` with each of `fresnels` in place of its own Fresnel: on an isotropic
/// set one pass, which forms each row's G2 / (4 cos θo) once for all of them.
pub fn microfacet_errors(
    model: &MicrofacetBrdf,
    fresnels: &[Fresnel],
    set: &GridSamples,
) -> Vec<f64> {
    let with = |f: &Fresnel| MicrofacetBrdf {
        fresnel: f.clone(),
        ..model.clone()
    };
    match (&set.iso, IsoTables::new(model)) {
        (Some(iso), Some(tables)) => {
            let per_bin: Vec<[Rgb; THETA_D_RES]> = fresnels
                .iter()
                .map(|f| std::array::from_fn(|j| f.eval(bin_angles(0, j, 0).theta_d.cos())))
                .collect();
            iso.log_error_sums(&tables, &per_bin)
                .into_iter()
                .map(|e| e / (3 * set.len().max(1)) as f64)
                .collect()
        }
        _ => fresnels
            .iter()
            .map(|f| microfacet_error(&with(f), set))
            .collect(),
    }
}

/// The model with a Fresnel table averaged for its own D and G ([`fresnel_average`]), and
/// that model's error ([`microfacet_error`]): the two passes of a least-squares step, sharing
/// G2 on an isotropic set.
pub fn fresnel_and_error(model: &MicrofacetBrdf, set: &GridSamples) -> (Vec<Rgb>, f64) {
    if let (Some(iso), Some(tables)) = (&set.iso, IsoTables::new(model)) {
        let (f, e) = iso.fresnel_and_error_sum(&tables);
        return (f, e / (3 * set.len().max(1)) as f64);
    }
    let f = fresnel_average(model, set);
    let with = MicrofacetBrdf {
        fresnel: crate::fresnel::Fresnel::Table(crate::fresnel::FresnelTable::on_merl_bins(
            f.clone(),
        )),
        ..model.clone()
    };
    let e = microfacet_error(&with, set);
    (f, e)
}

/// F per θd bin in [0, 1] and the diffuse albedo ρd solved for a model's D and G
/// ([`crate::diffuse`]; `irls` reweighted steps towards the metric's L1 minimum), and the error
/// of the model with them; `None` unless both the set and the model are isotropic (the diffuse
/// lobe is fitted on the isotropic grid only).
pub fn fresnel_diffuse_and_error(
    model: &MicrofacetBrdf,
    set: &GridSamples,
    irls: usize,
) -> Option<(Vec<Rgb>, Rgb, f64)> {
    let (iso, tables) = (set.iso.as_ref()?, IsoTables::new(model)?);
    let (f, q, e) = iso.fresnel_diffuse_and_error_sum(&tables, irls);
    Some((f, q.map(|q| q * PI), e / (3 * set.len().max(1)) as f64))
}

/// The rows of an isotropic set with every fourth φd bin ([`GridSamples::coarse`]): a
/// quarter of its samples, every (θh, θd) row kept. The analytic fits' α search and bracket
/// run on such rows; with a diffuse lobe, on those of the final steps' rows, every model's
/// F / ρd solve and the tabulated NDF's refinement.
pub struct CoarseGrid(CoarseSamples);

impl CoarseGrid {
    /// The mean error on these rows of `model` with its F (and with `diffuse` its ρd) solved
    /// on them: with `diffuse` a plain weighted least-squares solve
    /// ([`fresnel_diffuse_and_error`] without a reweighted step), without it the Fresnel
    /// average ([`fresnel_and_error`]). `None` for a model that is not isotropic.
    pub fn error(&self, model: &MicrofacetBrdf, diffuse: bool) -> Option<f64> {
        let tables = IsoTables::new(model)?;
        let e = match diffuse {
            true => self.0.fresnel_diffuse_and_error_sum(&tables, 0).2,
            false => self.0.fresnel_and_error_sum(&tables).1,
        };
        Some(e / (3 * self.0.count.max(1)) as f64)
    }

    /// F per θd bin, ρd and the mean error on these rows of `model` with `irls` reweighted
    /// steps, as [`fresnel_diffuse_and_error`] gives them. `None` for a model that is not
    /// isotropic.
    pub fn fresnel_diffuse_and_error(
        &self,
        model: &MicrofacetBrdf,
        irls: usize,
    ) -> Option<(Vec<Rgb>, Rgb, f64)> {
        let tables = IsoTables::new(model)?;
        let (f, q, e) = self.0.fresnel_diffuse_and_error_sum(&tables, irls);
        Some((f, q.map(|q| q * PI), e / (3 * self.0.count.max(1)) as f64))
    }

    /// The rows themselves.
    pub(crate) fn rows(&self) -> &CoarseSamples {
        &self.0
    }
}

/// Error of an isotropic model given as tables (the parameter searches' inner loop).
pub fn tables_error(tables: &IsoTables, set: &GridSamples) -> f64 {
    tables.log_error_sum(set) / (3 * set.len().max(1)) as f64
}

#[inline]
fn log_diff(x: Rgb, s: &GridSample) -> f64 {
    (0..3)
        .map(|c| (ln_1p_abs(x[c] as f32) - s.log_x[c]).abs())
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
        .samples()
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

    /// x recovered from the stored ln(1 + x): e^y − 1 within 2e-7 of libm's relatively for
    /// y from 1e-9 to 88 (1.2e-7 measured), and x from [`ln_1p`] within 3e-6 relatively over
    /// the stored range (2.0e-6 measured: ln_1p's relative error in ln(1 + x) grows by
    /// ln(1 + x) (1 + x) / x, at most 28 below 1e12).
    #[test]
    fn exp_m1_inverts_ln_1p() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let y = 1e-9f32 * 1.0002f32.powi(k);
            if y > 88.0 {
                break;
            }
            let (a, b) = (super::exp_m1(y) as f64, (y as f64).exp_m1());
            worst = worst.max((a - b).abs() / b);
        }
        println!("e^y − 1 worst {worst:e}");
        assert!(worst < 2e-7, "e^y − 1: worst error {worst}");
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if x > super::MAX_X {
                break;
            }
            let back = super::exp_m1(super::ln_1p(x)) as f64;
            worst = worst.max((back - x as f64).abs() / x as f64);
        }
        println!("x worst {worst:e}");
        assert!(worst < 3e-6, "x: worst error {worst}");
        assert_eq!(super::exp_m1(0.0), 0.0);
    }

    /// The model side's logarithm: within 2e-7 of libm's absolutely below x = 1, relatively
    /// above (1 + x rounds to f32: 2⁻²⁴ ≈ 6e-8, plus the polynomial's 6e-8).
    #[test]
    fn absolute_ln_1p_matches_libm() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if !x.is_finite() {
                break;
            }
            let (a, b) = (super::ln_1p_abs(x) as f64, (x as f64).ln_1p());
            worst = worst.max((a - b).abs() / b.max(1.0));
        }
        assert!(worst < 2e-7, "worst error {worst}");
    }

    /// The fused variants to the same bound as [`absolute_ln_1p_matches_libm`], and ln y for
    /// y from 2⁻⁶⁴ to 2⁶⁴ to 1.5e-7 of max(|ln y|, 1): the polynomial's 6e-8, the f32 rounding
    /// of e ln 2 + t P(t) (6e-8 relative), and one rounding of the exponent's product.
    #[test]
    fn fused_logs_match_libm() {
        let mut worst = 0.0f64;
        for k in 0..200_000 {
            let x = 1e-9f32 * 1.0002f32.powi(k);
            if !x.is_finite() {
                break;
            }
            let (a, b) = (super::ln_1p_fused(x) as f64, (x as f64).ln_1p());
            worst = worst.max((a - b).abs() / b.max(1.0));
        }
        assert!(worst < 2e-7, "ln(1 + x): worst error {worst}");
        let mut worst = 0.0f64;
        for k in -64_000..64_000 {
            let y = 2f64.powf(k as f64 * 1e-3) as f32;
            let (a, b) = (super::ln_positive_fused(y) as f64, (y as f64).ln());
            worst = worst.max((a - b).abs() / b.abs().max(1.0));
        }
        assert!(worst < 1.5e-7, "ln y: worst error {worst}");
    }
}
