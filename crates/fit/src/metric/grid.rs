//! The MERL grid as a set of valid samples, and microfacet models evaluated on it.
//!
//! The Fresnel average and the error metric both run over every valid sample of a source on
//! the MERL grid (bin lower edges, both directions above the horizon, the sample present).
//! Isotropic sources are held in a compact row form (`iso/`), and isotropic
//! microfacet models take a fast path there: D depends only on the θh bin, F only on the θd
//! bin and Λ only on cos θ, so each is a small table; `tests/grid.rs` checks it against the
//! direct evaluation.

use crate::metric::Metric;
use crate::metric::fast_log::{ln_1p, ln_1p_abs};
use crate::metric::iso::{CoarseSamples, IsoSamples, median_x};
use crate::metric::iso_tables::{IsoTables, MAX_X, fresnel_from_sums};
use crate::model::brdf::Brdf;
use crate::model::fresnel::{Fresnel, FresnelTable};
use crate::model::geometry::{HalfDiff, from_half_diff};
use crate::model::merl_grid::{MerlTable, PHI_D_RES, SAMPLES, THETA_D_RES, bin_angles, bin_of};
use crate::model::microfacet::MicrofacetBrdf;
use crate::model::rgb::Rgb;
use crate::numerics::stats::median_in_place;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::OnceLock;

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
    /// ln(1 + x/ε) per channel, ε of the set's metric ([`GridSamples::scale`] = 1/ε).
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
    /// 1/ε of the metric the samples are stored for ([`Metric`]): `log_x` is ln(1 + x/ε).
    scale: f32,
}

impl GridSamples {
    /// Every valid sample of the source: from its MERL table when isotropic; for an anisotropic
    /// source the grid is laid at four azimuths φh ∈ {0°, 45°, 90°, 135°}, every second θd and
    /// φd bin, to keep the sample count that of one full grid.
    pub fn new(src: &dyn Brdf) -> Self {
        Self::for_metric(src, Metric::Log)
    }

    /// [`Self::new`] in the space of `metric`: its errors are that metric's.
    pub fn for_metric(src: &dyn Brdf, metric: Metric) -> Self {
        if src.is_isotropic() {
            return Self::from_table(&src.merl_table(), metric);
        }
        // An anisotropic source: sampled once, the floor from its samples' median.
        let mut set = Self::anisotropic(src);
        if metric != Metric::Log {
            let mut samples = set
                .samples
                .take()
                .expect("an anisotropic set holds its list");
            let mut xs: Vec<f64> = samples.iter().flat_map(|s| s.x.map(f64::from)).collect();
            set.scale = 1.0 / metric.floor(|| median_in_place(&mut xs));
            for s in &mut samples {
                s.log_x = s.x.map(|x| ln_1p(x * set.scale));
            }
            set.samples = OnceLock::from(samples);
        }
        set
    }

    /// The samples of an isotropic source's MERL table, in the space of `metric`.
    pub fn from_table(table: &MerlTable, metric: Metric) -> Self {
        let scale = 1.0 / metric.floor(|| median_x(table));
        GridSamples {
            rotations: vec![0.0],
            samples: OnceLock::new(),
            iso: Some(IsoSamples::new(table, scale)),
            scale,
        }
    }

    /// The samples of an anisotropic source in the paper's metric (ε = 1).
    fn anisotropic(src: &dyn Brdf) -> Self {
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
                Some(make_sample(s, r as u8, v, wi.z, 1.0))
            })
            .collect();
        GridSamples {
            rotations,
            samples: OnceLock::from(samples),
            iso: None,
            scale: 1.0,
        }
    }

    /// 1/ε of the metric the samples are stored for.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// A cheaper set for parameter searches: every `stride`-th (θh, θd) row holding samples,
    /// with all its φd bins, of an isotropic source; every `stride`-th sample otherwise.
    pub fn subsample(&self, stride: usize) -> GridSamples {
        if let Some(iso) = &self.iso {
            return GridSamples {
                rotations: self.rotations.clone(),
                samples: OnceLock::new(),
                iso: Some(iso.subsample(stride)),
                scale: self.scale,
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
            scale: self.scale,
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
                scale: self.scale,
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
    /// built from the compact form on first use (x from ln(1 + x/ε), to f32 precision).
    pub fn samples(&self) -> &[GridSample] {
        let eps = 1.0 / self.scale as f64;
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
                    x: log_x.map(|l| ((l as f64).exp_m1() * eps) as f32),
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

fn make_sample(s: usize, rot: u8, v: Rgb, cos_i: f64, scale: f32) -> GridSample {
    let x = v.map(|f| (f * cos_i) as f32);
    GridSample {
        bin: s as u32,
        rot,
        i: (s / (PHI_D_RES * THETA_D_RES)) as u8,
        j: (s / PHI_D_RES % THETA_D_RES) as u8,
        x,
        log_x: x.map(|x| ln_1p(x * scale)),
    }
}

fn sample_directions(s: usize, phi_h: f64) -> (DVec3, DVec3) {
    let (i, j, k) = bin_of(s);
    let a = bin_angles(i, j, k);
    from_half_diff(HalfDiff { phi_h, ..a })
}

impl IsoTables {
    /// Σ over samples of Σ_c |ln(1 + x_model) − ln(1 + x_data)|.
    fn log_error_sum(&self, set: &GridSamples) -> f64 {
        if let Some(iso) = &set.iso {
            return iso.log_error_sum(self);
        }
        let log_diff_of = |s: &GridSample| {
            let (wi, wo) = set.directions(s);
            let ideal = self.x_ideal_at(wi, wo, s.i as usize);
            let f = self.fresnel[s.j as usize];
            log_diff(
                std::array::from_fn(|c| f[c] * ideal + self.diffuse[c] * wi.z),
                s,
                set.scale,
            )
        };
        let parts: Vec<f64> = set
            .samples()
            .par_chunks(CHUNK)
            .map(|chunk| chunk.iter().map(log_diff_of).sum())
            .collect();
        parts.into_iter().sum()
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

/// Samples per task of the passes over a grid's samples. Fixed, with each task's sum taken in
/// order and the tasks' sums in order, so that a sum does not depend on the thread schedule and
/// a fit is the same, bit for bit, run to run.
const CHUNK: usize = 4096;

/// The error metric of the design notes: mean over valid samples and channels of
/// |ln(1 + x_model) − ln(1 + x_data)|, x = f_r cos θi. Samples where the model has no value
/// are left out.
pub fn error_metric(model: &dyn Brdf, set: &GridSamples) -> f64 {
    let parts: Vec<(f64, usize)> = set
        .samples()
        .par_chunks(CHUNK)
        .map(|chunk| {
            chunk
                .iter()
                .filter_map(|s| x_direct(model, set, s).map(|x| log_diff(x, s, set.scale)))
                .fold((0.0, 0), |(a, n), e| (a + e, n + 1))
        })
        .collect();
    let (sum, count) = parts
        .into_iter()
        .fold((0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    sum / (3 * count.max(1)) as f64
}

/// [`error_metric`] of a microfacet model, through its tables when it is isotropic.
pub fn microfacet_error(model: &MicrofacetBrdf, set: &GridSamples) -> f64 {
    error_with(model, IsoTables::new(model).as_ref(), set)
}

/// [`microfacet_error`] with the model's tables given.
fn error_with(model: &MicrofacetBrdf, tables: Option<&IsoTables>, set: &GridSamples) -> f64 {
    let Some(tables) = tables.filter(|_| set.rotations.len() == 1) else {
        return error_metric(model, set);
    };
    tables.log_error_sum(set) / (3 * set.len().max(1)) as f64
}

/// A microfacet model and, when it is isotropic, its tables: reduced once, then read by every
/// pass a fit asks of it (the functions of this module reduce the model they are given on
/// each call).
#[derive(Clone)]
pub struct GridModel {
    /// The model.
    pub model: MicrofacetBrdf,
    /// Its tables; `None` for an anisotropic model, which the passes evaluate directly.
    pub tables: Option<IsoTables>,
}

impl GridModel {
    /// Reduces `model` to its tables.
    pub fn new(model: MicrofacetBrdf) -> Self {
        let tables = IsoTables::new(&model);
        GridModel { model, tables }
    }

    /// The model with F per θd bin (a table on the MERL bins) and the diffuse albedo ρd: D and
    /// Λ are kept, F and ρd/π tabulated as [`IsoTables::new`] tabulates them.
    pub fn with_fresnel(&self, f: &[Rgb], diffuse: Rgb) -> Self {
        let model = MicrofacetBrdf {
            fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.to_vec())),
            diffuse,
            ..self.model.clone()
        };
        let tables = self.tables.as_ref().map(|t| t.with_model_fresnel(&model));
        GridModel { model, tables }
    }

    /// [`microfacet_error`].
    pub fn error(&self, set: &GridSamples) -> f64 {
        error_with(&self.model, self.tables.as_ref(), set)
    }

    /// [`fresnel_average`].
    pub fn fresnel_average(&self, set: &GridSamples) -> Vec<Rgb> {
        average_with(&self.model, self.tables.as_ref(), set)
    }

    /// [`fresnel_and_error`].
    pub fn fresnel_and_error(&self, set: &GridSamples) -> (Vec<Rgb>, f64) {
        fresnel_and_error_with(&self.model, self.tables.as_ref(), set)
    }

    /// [`fresnel_diffuse_and_error`].
    pub fn fresnel_diffuse_and_error(
        &self,
        set: &GridSamples,
        irls: usize,
    ) -> Option<(Vec<Rgb>, Rgb, f64)> {
        let (iso, tables) = (set.iso.as_ref()?, self.tables.as_ref()?);
        let (f, q, e) = iso.fresnel_diffuse_and_error_sum(tables, irls);
        Some((f, q.map(|q| q * PI), e / (3 * set.len().max(1)) as f64))
    }
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
    fresnel_and_error_with(model, IsoTables::new(model).as_ref(), set)
}

/// [`fresnel_and_error`] with the model's tables given.
fn fresnel_and_error_with(
    model: &MicrofacetBrdf,
    tables: Option<&IsoTables>,
    set: &GridSamples,
) -> (Vec<Rgb>, f64) {
    if let (Some(iso), Some(tables)) = (&set.iso, tables) {
        let (f, e) = iso.fresnel_and_error_sum(tables);
        return (f, e / (3 * set.len().max(1)) as f64);
    }
    let f = average_with(model, tables, set);
    let with = MicrofacetBrdf {
        fresnel: Fresnel::Table(FresnelTable::on_merl_bins(f.clone())),
        ..model.clone()
    };
    let e = microfacet_error(&with, set);
    (f, e)
}

/// F per θd bin in [0, 1] and the diffuse albedo ρd solved for a model's D and G
/// ([`crate::fitting::diffuse`]; `irls` reweighted steps towards the metric's L1 minimum), and the error
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
        Some(self.tables_error(&IsoTables::new(model)?, diffuse))
    }

    /// [`CoarseGrid::error`] of a model reduced to its tables.
    pub fn tables_error(&self, tables: &IsoTables, diffuse: bool) -> f64 {
        let e = match diffuse {
            true => self.0.fresnel_diffuse_and_error_sum(tables, 0).2,
            false => self.0.fresnel_and_error_sum(tables).1,
        };
        e / (3 * self.0.count.max(1)) as f64
    }

    /// F per θd bin, ρd and the mean error on these rows of `model` with `irls` reweighted
    /// steps, as [`fresnel_diffuse_and_error`] gives them. `None` for a model that is not
    /// isotropic.
    pub fn fresnel_diffuse_and_error(
        &self,
        model: &MicrofacetBrdf,
        irls: usize,
    ) -> Option<(Vec<Rgb>, Rgb, f64)> {
        Some(self.tables_fresnel_diffuse_and_error(&IsoTables::new(model)?, irls))
    }

    /// [`CoarseGrid::fresnel_diffuse_and_error`] of a model reduced to its tables.
    pub fn tables_fresnel_diffuse_and_error(
        &self,
        tables: &IsoTables,
        irls: usize,
    ) -> (Vec<Rgb>, Rgb, f64) {
        let (f, q, e) = self.0.fresnel_diffuse_and_error_sum(tables, irls);
        (f, q.map(|q| q * PI), e / (3 * self.0.count.max(1)) as f64)
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

/// Σ_c |ln(1 + x_c/ε) − ln(1 + x_data,c/ε)| of a sample, `scale` = 1/ε.
#[inline]
fn log_diff(x: Rgb, s: &GridSample, scale: f32) -> f64 {
    (0..3)
        .map(|c| (ln_1p_abs(x[c] as f32 * scale) - s.log_x[c]).abs())
        .sum::<f32>() as f64
}

/// Fresnel per θd bin and channel: F_j = Σ x_data / Σ x_ideal over the valid samples of bin j,
/// x_ideal = D G2 / (4 cos θo) of `model` (its own Fresnel and diffuse term are ignored). This
/// is the mean of f / f_ideal weighted by x_ideal, which keeps noisy tails (tiny f_ideal) from
/// dominating. Bins without samples are filled by interpolation.
pub fn fresnel_average(model: &MicrofacetBrdf, set: &GridSamples) -> Vec<Rgb> {
    average_with(model, IsoTables::new(model).as_ref(), set)
}

/// [`fresnel_average`] with the model's tables given.
fn average_with(model: &MicrofacetBrdf, tables: Option<&IsoTables>, set: &GridSamples) -> Vec<Rgb> {
    match tables.filter(|_| set.rotations.len() == 1) {
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
    let parts: Vec<Acc> = set
        .samples()
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut acc: Acc = vec![([0.0; 3], 0.0); THETA_D_RES];
            for s in chunk {
                let xi = ideal(s);
                if xi.is_finite() && xi > 0.0 {
                    let a = &mut acc[s.j as usize];
                    (0..3).for_each(|c| a.0[c] += s.x[c] as f64);
                    a.1 += xi;
                }
            }
            acc
        })
        .collect();
    let acc = parts
        .into_iter()
        .reduce(|mut a, b| {
            for (x, y) in a.iter_mut().zip(b) {
                (0..3).for_each(|c| x.0[c] += y.0[c]);
                x.1 += y.1;
            }
            a
        })
        .unwrap_or_else(|| vec![([0.0; 3], 0.0); THETA_D_RES]);
    fresnel_from_sums(&acc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::microfacet::{AnalyticNdf, Ndf, NdfKind};

    /// A model's tables with a new F and ρd are the tables of the model with them: D and Λ
    /// depend on the NDF alone, so keeping them is exact.
    #[test]
    fn a_grid_model_with_new_fresnel_has_the_tables_of_that_model() {
        let ndf = Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.3));
        let m = GridModel::new(MicrofacetBrdf::ideal("m", ndf));
        let f: Vec<Rgb> = (0..THETA_D_RES)
            .map(|j| [0.5, 0.6, 0.01 * j as f64])
            .collect();
        let with = m.with_fresnel(&f, [0.1, 0.2, 0.3]);
        let direct = IsoTables::new(&with.model).unwrap();
        let kept = with.tables.as_ref().unwrap();
        assert_eq!(kept.d32, direct.d32);
        assert_eq!(kept.lambda_cos[..], direct.lambda_cos[..]);
        assert_eq!(kept.fresnel, direct.fresnel);
        assert_eq!(kept.diffuse, direct.diffuse);
    }
}
