//! The MERL grid (Matusik et al. 2003) and a table of samples on it: the bins, their angles,
//! the stored values with their channel scales, and nearest and interpolated lookups.
//! Reading and writing MERL files is [`crate::sources::merl`]'s.
//!
//! Sample index `φd_bin + 180 (θd_bin + 90 θh_bin)`. A stored value times the channel scale
//! (1, 1.15, 1.66) / 1500 is f_r; a negative value marks a missing sample.
//! Sample (i, j, k) sits at the bin's lower edge: θh = (i/90)² π/2, θd = j/90 · π/2, φd = k/180 · π.

use crate::io::mapped_file::MappedFile;
use crate::model::geometry::{HalfDiff, to_half_diff};
use crate::model::rgb::Rgb;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// θh bins of a MERL file.
pub const THETA_H_RES: usize = 90;
/// θd bins of a MERL file.
pub const THETA_D_RES: usize = 90;
/// φd bins of a MERL file (over [0, π): reciprocity gives the rest).
pub const PHI_D_RES: usize = 180;
/// Samples per channel.
pub const SAMPLES: usize = THETA_H_RES * THETA_D_RES * PHI_D_RES;

/// The largest x = f_r cos θi a source may give: a GGX mirror of α = 10⁻⁴ at its peak stays
/// below 10⁹; beyond 10¹² the f32 sums over the MERL grid's 1.5·10⁶ samples (the Fresnel
/// average, the metric) would overflow, and the renderer's f32 products with radiance too, so
/// the fitter and the renderer's readers refuse such values with the value named.
pub const MAX_X: f32 = 1e12;
/// f_r = stored value × `SCALE[channel]`.
pub const SCALE: Rgb = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// Bytes of a MERL file's header (three `i32` dimensions) before the values.
pub(crate) const HEADER_BYTES: u64 = 12;
/// The fewest valid samples a source may hold to be fitted
/// ([`crate::sources::merl::MerlBrdf::from_table`] refuses a table with fewer, the fit any
/// source with fewer on the grid). With a diffuse lobe the fit solves, per channel, F on each of
/// the 90 θd bins and ρd, beside α: below these 92 unknowns every model can match the samples
/// exactly, and the errors it reports say nothing. (Every pass runs on fewer: the extraction
/// needs one backscattering sample.)
pub const MIN_VALID_SAMPLES: usize = THETA_D_RES + 2;
/// The largest stored value read as a measurement (f_r ≈ 7·10⁸ sr⁻¹, past any mirror-like
/// MERL material): larger ones would overflow the extraction's sums.
pub const MAX_STORED: f64 = 1e12;

/// Flat index of bin (θh, θd, φd).
pub const fn index(i: usize, j: usize, k: usize) -> usize {
    k + PHI_D_RES * (j + THETA_D_RES * i)
}

/// The bin (θh, θd, φd) of flat index `s`: [`index`]'s inverse.
pub const fn bin_of(s: usize) -> (usize, usize, usize) {
    (
        s / (PHI_D_RES * THETA_D_RES),
        s / PHI_D_RES % THETA_D_RES,
        s % PHI_D_RES,
    )
}

/// Angles of the sample in bin (i, j, k): its lower edge.
pub fn bin_angles(i: usize, j: usize, k: usize) -> HalfDiff {
    let u = i as f64 / THETA_H_RES as f64;
    HalfDiff {
        theta_h: u * u * FRAC_PI_2,
        phi_h: 0.0,
        theta_d: j as f64 / THETA_D_RES as f64 * FRAC_PI_2,
        phi_d: k as f64 / PHI_D_RES as f64 * PI,
    }
}

/// `from_half_diff(bin_angles(i, j, k))`, the same values bit for bit, from sines and cosines
/// computed once per axis: the coat search evaluates its lobe at millions of bin corners.
pub fn bin_directions(i: usize, j: usize, k: usize) -> (DVec3, DVec3) {
    static TRIG: std::sync::OnceLock<[Vec<(f64, f64)>; 3]> = std::sync::OnceLock::new();
    let [h, d, p] = TRIG.get_or_init(|| {
        let axis =
            |n: usize, angle: &dyn Fn(usize) -> f64| (0..n).map(|x| angle(x).sin_cos()).collect();
        [
            axis(THETA_H_RES, &|i| bin_angles(i, 0, 0).theta_h),
            axis(THETA_D_RES, &|j| bin_angles(0, j, 0).theta_d),
            axis(PHI_D_RES, &|k| bin_angles(0, 0, k).phi_d),
        ]
    });
    let ((sh, ch), (sd, cd), (sp, cp)) = (h[i], d[j], p[k]);
    // d = spherical(θd, φd), rotated by θh about y (φh = 0); ωo mirrors ωi about h.
    let v = DVec3::new(sd * cp, sd * sp, cd);
    let wi = DVec3::new(ch * v.x + sh * v.z, v.y, -sh * v.x + ch * v.z);
    let half = DVec3::new(sh, 0.0, ch);
    (wi, 2.0 * wi.dot(half) * half - wi)
}

/// Continuous bin coordinates (sample centres at integers) of a Rusinkiewicz pair.
fn bin_coords(c: HalfDiff) -> [f64; 3] {
    [
        (c.theta_h.max(0.0) / FRAC_PI_2).sqrt() * THETA_H_RES as f64,
        c.theta_d.max(0.0) / FRAC_PI_2 * THETA_D_RES as f64,
        c.phi_d.rem_euclid(PI) / PI * PHI_D_RES as f64, // reciprocity: φd and φd + π are one bin
    ]
}

/// Where a pair (ωi, ωo) falls on the grid, in the sqrt-θh, θd, φd bin coordinates: the lower
/// corner of the 8 samples [`MerlTable::lookup_interpolated`] weighs, and the fractions
/// towards the upper one (φd wraps with period π).
#[derive(Clone, Copy, Debug)]
pub struct GridPoint {
    lower: [u8; 3],
    fraction: [f64; 3],
}

impl GridPoint {
    /// The place of (wi, wo).
    pub fn of(wi: DVec3, wo: DVec3) -> Self {
        let x = bin_coords(to_half_diff(wi, wo));
        let axis = |v: f64, n: usize| {
            let v = v.clamp(0.0, (n - 1) as f64);
            let i0 = (v as usize).min(n - 2);
            (i0, v - i0 as f64)
        };
        let (h0, th) = axis(x[0], THETA_H_RES);
        let (d0, td) = axis(x[1], THETA_D_RES);
        let p0 = (x[2] as usize).min(PHI_D_RES - 1);
        // Every bin index is below 256 (`PHI_D_RES` = 180 is the largest).
        GridPoint {
            lower: [h0 as u8, d0 as u8, p0 as u8],
            fraction: [th, td, x[2] - p0 as f64],
        }
    }
}

/// The raw samples of a MERL file, exactly as stored.
pub struct MerlTable {
    pub(crate) raw: Stored,
}

/// A table's 3 · SAMPLES values, channel-major as in the file, each as its eight little-endian
/// bytes (the file's own encoding, which a mapped file's unaligned values keep).
pub(crate) enum Stored {
    Owned(Vec<[u8; 8]>),
    /// A standard MERL file mapped whole: the values follow its 12-byte header.
    Mapped(MappedFile),
}

impl Stored {
    pub(crate) fn values(&self) -> &[[u8; 8]] {
        match self {
            Stored::Owned(v) => v,
            Stored::Mapped(m) => bytemuck::cast_slice(&m.bytes()[HEADER_BYTES as usize..]),
        }
    }
}

impl Clone for MerlTable {
    fn clone(&self) -> Self {
        MerlTable {
            raw: Stored::Owned(self.raw.values().to_vec()),
        }
    }
}

impl PartialEq for MerlTable {
    /// The values compared as numbers (−0 = 0), however each table holds them.
    fn eq(&self, other: &Self) -> bool {
        let (a, b) = (self.raw.values(), other.raw.values());
        a.iter()
            .zip(b)
            .all(|(a, b)| f64::from_le_bytes(*a) == f64::from_le_bytes(*b))
    }
}

impl std::fmt::Debug for MerlTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let held = match self.raw {
            Stored::Owned(_) => "in memory",
            Stored::Mapped(_) => "mapped",
        };
        write!(
            f,
            "MerlTable({} samples, {} missing, {held})",
            SAMPLES,
            self.missing_count()
        )
    }
}

/// The stored value at flat position `at` (channel-major).
#[inline(always)]
pub(crate) fn stored(raw: &[[u8; 8]], at: usize) -> f64 {
    f64::from_le_bytes(raw[at])
}

impl MerlTable {
    /// Samples f_r(wi, wo) at the bin lower edges; below the horizon and where `f` has no
    /// value the sample is marked missing (−1). [`MerlTable::sample`] samples a BRDF.
    pub fn from_fn(f: impl Fn(DVec3, DVec3) -> Option<Rgb> + Sync) -> Self {
        Self::from_fn_where(|_, _, _| true, f)
    }

    /// [`MerlTable::from_fn`] on the bins (θh, θd, φd) = (i, j, k) that `keep` names; the
    /// others are missing.
    pub fn from_fn_where(
        keep: impl Fn(usize, usize, usize) -> bool + Sync,
        f: impl Fn(DVec3, DVec3) -> Option<Rgb> + Sync,
    ) -> Self {
        Self::from_bins(|i, j, k| {
            if !keep(i, j, k) {
                return None;
            }
            let (wi, wo) = bin_directions(i, j, k);
            if wi.z <= 0.0 || wo.z <= 0.0 {
                return None;
            }
            f(wi, wo)
        })
    }

    /// A table of the values `f` gives each bin (θh, θd, φd) = (i, j, k); missing where `None`.
    pub fn from_bins(f: impl Fn(usize, usize, usize) -> Option<Rgb> + Sync) -> Self {
        let mut raw = vec![(-1.0f64).to_le_bytes(); 3 * SAMPLES];
        // One θh row of the three channels at a time, written where it is computed.
        const ROW: usize = THETA_D_RES * PHI_D_RES;
        let (red, rest) = raw.split_at_mut(SAMPLES);
        let (green, blue) = rest.split_at_mut(SAMPLES);
        let rows = red.par_chunks_mut(ROW).zip(green.par_chunks_mut(ROW));
        rows.zip(blue.par_chunks_mut(ROW))
            .enumerate()
            .for_each(|(i, ((r, g), b))| {
                for s in 0..ROW {
                    let (j, k) = (s / PHI_D_RES, s % PHI_D_RES);
                    if let Some(v) = f(i, j, k) {
                        r[s] = (v[0] / SCALE[0]).to_le_bytes();
                        g[s] = (v[1] / SCALE[1]).to_le_bytes();
                        b[s] = (v[2] / SCALE[2]).to_le_bytes();
                    }
                }
            });
        MerlTable {
            raw: Stored::Owned(raw),
        }
    }

    /// The stored values of channel `c` (0 red, 1 green, 2 blue) in flat bin order, as
    /// little-endian bytes: f_r is a value times `SCALE[c]`, negative where missing.
    pub fn channel(&self, c: usize) -> &[[u8; 8]] {
        &self.raw.values()[c * SAMPLES..(c + 1) * SAMPLES]
    }

    /// The values to change, copied into memory first if the table is a mapped file (which is
    /// never written).
    fn values_mut(&mut self) -> &mut [[u8; 8]] {
        if let Stored::Mapped(m) = &self.raw {
            let owned = bytemuck::cast_slice(&m.bytes()[HEADER_BYTES as usize..]).to_vec();
            self.raw = Stored::Owned(owned);
        }
        match &mut self.raw {
            Stored::Owned(v) => v,
            Stored::Mapped(_) => unreachable!("copied just above"),
        }
    }

    /// f_r of bin (i, j, k), or `None` if the sample is missing.
    #[inline]
    pub fn value(&self, i: usize, j: usize, k: usize) -> Option<Rgb> {
        self.value_at(index(i, j, k))
    }

    /// f_r of flat sample `s`, or `None` if the sample is missing.
    #[inline]
    pub fn value_at(&self, s: usize) -> Option<Rgb> {
        let raw = self.raw.values();
        let r = [
            stored(raw, s),
            stored(raw, SAMPLES + s),
            stored(raw, 2 * SAMPLES + s),
        ];
        if r.iter().any(|&v| v < 0.0) {
            return None;
        }
        Some([r[0] * SCALE[0], r[1] * SCALE[1], r[2] * SCALE[2]])
    }

    /// Marks flat sample `s` as missing.
    pub fn mark_missing(&mut self, s: usize) {
        let raw = self.values_mut();
        for c in 0..3 {
            raw[c * SAMPLES + s] = (-1.0f64).to_le_bytes();
        }
    }

    /// Scales sample `s` by a per-channel factor (for noise experiments).
    pub fn scale_sample(&mut self, s: usize, factor: Rgb) {
        let raw = self.values_mut();
        for (c, f) in factor.iter().enumerate() {
            let v = stored(raw, c * SAMPLES + s);
            if v >= 0.0 {
                raw[c * SAMPLES + s] = (v * f).to_le_bytes();
            }
        }
    }

    /// The first valid sample whose x = f_r cos θi is not finite or beyond ±[`MAX_X`] (θi of
    /// its bin's incoming direction): (flat sample, x). The fitter refuses such a source on its
    /// grid; a renderer reading the table checks it here.
    pub fn first_beyond_max_x(&self) -> Option<(usize, f64)> {
        (0..SAMPLES)
            .into_par_iter()
            .find_first(|&s| self.x_beyond(s).is_some())
            .map(|s| (s, self.x_beyond(s).expect("found above")))
    }

    fn x_beyond(&self, s: usize) -> Option<f64> {
        let v = self.value_at(s)?;
        let (i, j, k) = bin_of(s);
        let cos_i = bin_directions(i, j, k).0.z.max(0.0);
        v.iter()
            .map(|f| f * cos_i)
            .find(|x| !(x.abs() <= f64::from(MAX_X)))
    }

    /// The number of samples that hold no valid value.
    pub fn missing_count(&self) -> usize {
        (0..SAMPLES).filter(|&s| self.value_at(s).is_none()).count()
    }

    /// The table a renderer reads: each missing sample takes the value interpolated along θd
    /// between the valid samples of its (θh, φd) line, held constant past the first and last
    /// of them — the rule the fit fills its Fresnel curve by — so that an interpolated lookup
    /// near the horizon or a gap blends measured values instead of dropping corners. A line with
    /// no valid sample stays missing.
    pub fn filled(&self) -> MerlTable {
        let mut out = self.clone();
        if self.missing_count() == 0 {
            return out;
        }
        let raw = out.values_mut();
        for i in 0..THETA_H_RES {
            for k in 0..PHI_D_RES {
                let line: Vec<Option<Rgb>> =
                    (0..THETA_D_RES).map(|j| self.value(i, j, k)).collect();
                if line.iter().all(Option::is_some) {
                    continue;
                }
                let Some(filled) = crate::numerics::interp::fill_missing(&line) else {
                    continue;
                };
                for (j, v) in filled
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| line[*j].is_none())
                {
                    for c in 0..3 {
                        raw[c * SAMPLES + index(i, j, k)] = (v[c] / SCALE[c]).to_le_bytes();
                    }
                }
            }
        }
        out
    }

    /// MERL's own lookup: the bin containing the angles (sqrt mapping on θh, φd folded by
    /// reciprocity), indices clamped to the table.
    pub fn lookup_nearest(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        let x = bin_coords(to_half_diff(wi, wo));
        let clamp = |v: f64, n: usize| (v as usize).min(n - 1);
        self.value(
            clamp(x[0], THETA_H_RES),
            clamp(x[1], THETA_D_RES),
            clamp(x[2], PHI_D_RES),
        )
    }

    /// Trilinear interpolation between the samples around (wi, wo), in the sqrt-θh, θd, φd
    /// bin coordinates; φd wraps with period π; missing corners are left out and the weights of
    /// the others renormalised.
    pub fn lookup_interpolated(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        self.interpolate_less(&GridPoint::of(wi, wo), |_, _, _| 0.0)
    }

    /// [`MerlTable::lookup_interpolated`] at a pair already placed on the grid, of the table
    /// less `g` sampled at the same bins (θh, θd, φd) = (i, j, k): the interpolation of
    /// value − g(bin). A sharp lobe known in closed form, subtracted on the grid before
    /// interpolating, leaves a remainder that interpolates as well as the rest of the table.
    pub fn interpolate_less(
        &self,
        at: &GridPoint,
        g: impl Fn(usize, usize, usize) -> f64,
    ) -> Option<Rgb> {
        let [h0, d0, p0] = at.lower.map(usize::from);
        let [th, td, tp] = at.fraction;
        let (h1, d1, p1) = (h0 + 1, d0 + 1, (p0 + 1) % PHI_D_RES);
        let mut sum = [0.0; 3];
        let mut wsum = 0.0;
        for (i, wi) in [(h0, 1.0 - th), (h1, th)] {
            for (j, wj) in [(d0, 1.0 - td), (d1, td)] {
                for (k, wk) in [(p0, 1.0 - tp), (p1, tp)] {
                    let w = wi * wj * wk;
                    if w <= 0.0 {
                        continue;
                    }
                    if let Some(v) = self.value(i, j, k) {
                        let g = g(i, j, k);
                        (0..3).for_each(|c| sum[c] += w * (v[c] - g));
                        wsum += w;
                    }
                }
            }
        }
        (wsum > 0.0).then(|| sum.map(|s| s / wsum))
    }
}
