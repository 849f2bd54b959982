//! MERL isotropic BRDF files (Matusik et al. 2003): reader, writer, nearest and interpolated
//! lookups.
//!
//! File layout: three little-endian `i32` dimensions (90, 90, 180) followed by 3·n `f64`
//! values, all red then all green then all blue, sample index
//! `φd_bin + 180 (θd_bin + 90 θh_bin)`. A stored value times the channel scale
//! (1, 1.15, 1.66) / 1500 is f_r; a negative value marks a missing sample.
//! Sample (i, j, k) sits at the bin's lower edge: θh = (i/90)² π/2, θd = j/90 · π/2, φd = k/180 · π.

use crate::brdf::{Brdf, Rgb};
use crate::error::FitError;
use crate::geometry::{HalfDiff, from_half_diff, to_half_diff};
use crate::mapped_file::MappedFile;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::io::Write;
use std::path::Path;

/// θh bins of a MERL file.
pub const THETA_H_RES: usize = 90;
/// θd bins of a MERL file.
pub const THETA_D_RES: usize = 90;
/// φd bins of a MERL file (over [0, π): reciprocity gives the rest).
pub const PHI_D_RES: usize = 180;
/// Samples per channel.
pub const SAMPLES: usize = THETA_H_RES * THETA_D_RES * PHI_D_RES;
/// f_r = stored value × `SCALE[channel]`.
pub const SCALE: Rgb = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
const HEADER_BYTES: u64 = 12;
/// The fewest valid samples a source may hold to be fitted ([`MerlBrdf::from_table`] refuses a
/// table with fewer, the fit any source with fewer on the grid). With a diffuse lobe the fit
/// solves, per channel, F on each of the 90 θd bins and ρd, beside α: below these 92 unknowns
/// every model can match the samples exactly, and the errors it reports say nothing. (Every
/// pass runs on fewer: the extraction needs one backscattering sample.)
pub const MIN_VALID_SAMPLES: usize = THETA_D_RES + 2;
/// The largest stored value read as a measurement (f_r ≈ 7·10⁸ sr⁻¹, past any mirror-like
/// MERL material): larger ones would overflow the extraction's sums.
pub const MAX_STORED: f64 = 1e12;

/// Flat index of bin (θh, θd, φd).
pub const fn index(i: usize, j: usize, k: usize) -> usize {
    k + PHI_D_RES * (j + THETA_D_RES * i)
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

/// Continuous bin coordinates (sample centres at integers) of a Rusinkiewicz pair.
fn bin_coords(c: HalfDiff) -> [f64; 3] {
    [
        (c.theta_h.max(0.0) / FRAC_PI_2).sqrt() * THETA_H_RES as f64,
        c.theta_d.max(0.0) / FRAC_PI_2 * THETA_D_RES as f64,
        c.phi_d.rem_euclid(PI) / PI * PHI_D_RES as f64, // reciprocity: φd and φd + π are one bin
    ]
}

/// The raw samples of a MERL file, exactly as stored.
pub struct MerlTable {
    raw: Stored,
}

/// A table's 3 · SAMPLES values, channel-major as in the file, each as its eight little-endian
/// bytes (the file's own encoding, which a mapped file's unaligned values keep).
enum Stored {
    Owned(Vec<[u8; 8]>),
    /// A standard MERL file mapped whole: the values follow its 12-byte header.
    Mapped(MappedFile),
}

impl Stored {
    fn values(&self) -> &[[u8; 8]] {
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
fn stored(raw: &[[u8; 8]], at: usize) -> f64 {
    f64::from_le_bytes(raw[at])
}

impl MerlTable {
    /// Reads and validates a MERL `.binary` file into memory.
    pub fn read(path: &Path) -> Result<Self, FitError> {
        if let Some(table) = Self::read_standard(path, false)? {
            return Ok(table);
        }
        Self::parse(path, &crate::input::read(path, crate::input::Cap::MERL)?)
    }

    /// Maps and validates a MERL `.binary` file: the fast way for a short-lived process, as
    /// [`MerlTable::read`] in all else (the same errors; a file that is not standard, and any
    /// system without `mmap`, is read). The file must not be truncated or rewritten in place
    /// while the table lives: a read of the lost part would fault (see `mapped_file.rs`).
    /// Replacing it by a rename, as [`MerlTable::write`] does, is safe.
    pub fn map(path: &Path) -> Result<Self, FitError> {
        if let Some(table) = Self::read_standard(path, true)? {
            return Ok(table);
        }
        Self::parse(path, &crate::input::read(path, crate::input::Cap::MERL)?)
    }

    /// A file of exactly the standard size with the standard header, mapped (`map`) or read
    /// straight into the table (one 35 MB buffer, not a byte copy beside it); `None` for any
    /// other file, which [`MerlTable::parse`] then reads and explains.
    fn read_standard(path: &Path, map: bool) -> Result<Option<Self>, FitError> {
        use std::io::Read;
        let (mut file, len) = crate::input::open(path, crate::input::Cap::MERL)?;
        if len != HEADER_BYTES + (3 * 8 * SAMPLES) as u64 {
            return Ok(None);
        }
        let io = |e| FitError::io(path, e);
        let mut header = [0u8; HEADER_BYTES as usize];
        let raw = match map.then(|| MappedFile::map(&file, len as usize)).flatten() {
            Some(m) => {
                header.copy_from_slice(&m.bytes()[..HEADER_BYTES as usize]);
                Stored::Mapped(m)
            }
            None => {
                let mut raw = vec![[0u8; 8]; 3 * SAMPLES];
                crate::huge_pages::advise(&mut raw);
                file.read_exact(&mut header).map_err(io)?;
                file.read_exact(bytemuck::cast_slice_mut(&mut raw))
                    .map_err(io)?;
                // One byte more would be a file that grew while read: the general path
                // explains it.
                if file.read(&mut [0u8]).map_err(io)? != 0 {
                    return Ok(None);
                }
                Stored::Owned(raw)
            }
        };
        let dims: [i32; 3] = std::array::from_fn(|d| {
            i32::from_le_bytes(header[4 * d..4 * d + 4].try_into().unwrap())
        });
        if dims != [THETA_H_RES as i32, THETA_D_RES as i32, PHI_D_RES as i32] {
            return Ok(None);
        }
        // In parallel, chunk by chunk without a branch per value, so that the scan vectorises.
        let out_of_range = |c: &[[u8; 8]]| {
            c.iter().fold(false, |bad, v| {
                bad | !(f64::from_le_bytes(*v) <= MAX_STORED)
            })
        };
        if raw
            .values()
            .par_chunks(1 << 16)
            .any(|c| c.chunks(1024).any(out_of_range))
        {
            return Ok(None); // the general path names the sample
        }
        Ok(Some(MerlTable { raw }))
    }

    /// Validates the bytes of a MERL file; `path` names it in errors.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, FitError> {
        let bad = |problem: String| FitError::Merl {
            path: path.to_owned(),
            problem,
        };
        let len = bytes.len() as u64;
        if len == 0 {
            return Err(bad("the file is empty".into()));
        }
        if len < HEADER_BYTES {
            return Err(bad(format!(
                "truncated header: {len} bytes, a header needs 12"
            )));
        }
        let dims: [i32; 3] = std::array::from_fn(|d| {
            i32::from_le_bytes(bytes[4 * d..4 * d + 4].try_into().unwrap())
        });
        if dims.iter().any(|&d| d <= 0) {
            return Err(bad(format!(
                "dimensions {dims:?} in the header are not positive"
            )));
        }
        // i32 dimensions: the product and the byte count fit in u128 whatever the header says.
        let n = dims.iter().map(|&d| d as u128).product::<u128>();
        let expected = HEADER_BYTES as u128 + 3 * 8 * n;
        let len = len as u128;
        if len < expected {
            return Err(bad(format!(
                "truncated: header {}×{}×{} needs {expected} bytes, the file has {len}",
                dims[0], dims[1], dims[2]
            )));
        }
        if len > expected {
            return Err(bad(format!(
                "oversized: header {}×{}×{} needs {expected} bytes, the file has {} more",
                dims[0],
                dims[1],
                dims[2],
                len - expected
            )));
        }
        if dims != [THETA_H_RES as i32, THETA_D_RES as i32, PHI_D_RES as i32] {
            return Err(bad(format!(
                "dimensions {}×{}×{} are not the standard 90×90×180 layout",
                dims[0], dims[1], dims[2]
            )));
        }
        let raw: Vec<[u8; 8]> = bytemuck::cast_slice(&bytes[HEADER_BYTES as usize..]).to_vec();
        // Missing samples are negative, whatever their size; a valid one is at most MAX_STORED.
        if let Some(at) = (0..raw.len()).position(|at| !(stored(&raw, at) <= MAX_STORED)) {
            let v = stored(&raw, at);
            let (c, s) = (at / SAMPLES, at % SAMPLES);
            let (i, j, k) = (
                s / (PHI_D_RES * THETA_D_RES),
                s / PHI_D_RES % THETA_D_RES,
                s % PHI_D_RES,
            );
            return Err(bad(format!(
                "sample {s} of channel {} (θh bin {i}, θd bin {j}, φd bin {k}) is {:e}",
                ["red", "green", "blue"][c],
                v,
            ) + &if v.is_finite() {
                format!(", above the {MAX_STORED:e} a measured value can be")
            } else {
                String::new()
            }));
        }
        Ok(MerlTable {
            raw: Stored::Owned(raw),
        })
    }

    /// Writes the table as a MERL file. The file is written beside its destination and renamed
    /// into place, so a failed write never leaves a half-written file.
    pub fn write(&self, path: &Path) -> Result<(), FitError> {
        let tmp = path.with_extension("binary.partial");
        let result = (|| {
            let mut file = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
            for d in [THETA_H_RES, THETA_D_RES, PHI_D_RES] {
                file.write_all(&(d as i32).to_le_bytes())?;
            }
            file.write_all(bytemuck::cast_slice(self.raw.values()))?;
            file.into_inner().map_err(|e| e.into_error())?.sync_all()?;
            std::fs::rename(&tmp, path)
        })();
        result.map_err(|e| {
            let _ = std::fs::remove_file(&tmp);
            FitError::io(path, e)
        })
    }

    /// Samples any BRDF at the bin lower edges; below the horizon and where the source has no
    /// value the sample is marked missing (−1).
    pub fn sample<B: Brdf + ?Sized>(brdf: &B) -> Self {
        let mut raw = vec![(-1.0f64).to_le_bytes(); 3 * SAMPLES];
        let values: Vec<Option<Rgb>> = (0..SAMPLES)
            .into_par_iter()
            .map(|s| {
                let (i, j, k) = (
                    s / (PHI_D_RES * THETA_D_RES),
                    s / PHI_D_RES % THETA_D_RES,
                    s % PHI_D_RES,
                );
                let (wi, wo) = from_half_diff(bin_angles(i, j, k));
                if wi.z <= 0.0 || wo.z <= 0.0 {
                    return None;
                }
                brdf.eval(wi, wo)
            })
            .collect();
        for (s, v) in values.into_iter().enumerate() {
            if let Some(v) = v {
                for c in 0..3 {
                    raw[c * SAMPLES + s] = (v[c] / SCALE[c]).to_le_bytes();
                }
            }
        }
        MerlTable {
            raw: Stored::Owned(raw),
        }
    }

    /// The stored values of channel `c` (0 red, 1 green, 2 blue) in flat bin order, as
    /// little-endian bytes: f_r is a value times `SCALE[c]`, negative where missing.
    pub(crate) fn channel(&self, c: usize) -> &[[u8; 8]] {
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

    /// The number of samples that hold no valid value.
    pub fn missing_count(&self) -> usize {
        (0..SAMPLES).filter(|&s| self.value_at(s).is_none()).count()
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
        let x = bin_coords(to_half_diff(wi, wo));
        let axis = |v: f64, n: usize| {
            let v = v.clamp(0.0, (n - 1) as f64);
            let i0 = (v as usize).min(n - 2);
            (i0, i0 + 1, v - i0 as f64)
        };
        let (h0, h1, th) = axis(x[0], THETA_H_RES);
        let (d0, d1, td) = axis(x[1], THETA_D_RES);
        let p0 = (x[2] as usize).min(PHI_D_RES - 1);
        let (p1, tp) = ((p0 + 1) % PHI_D_RES, x[2] - p0 as f64);
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
                        (0..3).for_each(|c| sum[c] += w * v[c]);
                        wsum += w;
                    }
                }
            }
        }
        (wsum > 0.0).then(|| sum.map(|s| s / wsum))
    }
}

/// A MERL measurement as a BRDF source.
pub struct MerlBrdf {
    name: String,
    table: MerlTable,
    /// f(o, o) per θh bin: the θd = 0 samples averaged over φd, missing bins filled by linear
    /// interpolation between their valid neighbours.
    backscatter: Vec<Rgb>,
}

impl MerlBrdf {
    /// Reads a MERL `.binary` file into memory.
    pub fn open(path: &Path) -> Result<Self, FitError> {
        Self::named(path, MerlTable::read(path)?)
    }

    /// Maps a MERL `.binary` file ([`MerlTable::map`]: faster, for a short-lived process; the
    /// file must not be truncated in place while the source lives).
    pub fn map(path: &Path) -> Result<Self, FitError> {
        Self::named(path, MerlTable::map(path)?)
    }

    /// The table of the file at `path`, named after the file's stem.
    fn named(path: &Path, table: MerlTable) -> Result<Self, FitError> {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Self::from_table(name, table).map_err(|problem| FitError::Merl {
            path: path.to_owned(),
            problem,
        })
    }

    /// Wraps a table; fails if the table has no backscattering sample at all, or fewer than
    /// [`MIN_VALID_SAMPLES`] valid samples.
    pub fn from_table(name: impl Into<String>, table: MerlTable) -> Result<Self, String> {
        let slice: Vec<Option<Rgb>> = (0..THETA_H_RES)
            .map(|i| {
                let valid: Vec<Rgb> = (0..PHI_D_RES)
                    .filter_map(|k| table.value(i, 0, k))
                    .collect();
                (!valid.is_empty()).then(|| {
                    let n = valid.len() as f64;
                    std::array::from_fn(|c| valid.iter().map(|v| v[c]).sum::<f64>() / n)
                })
            })
            .collect();
        // The valid samples with both directions above the horizon (the fit's grid), the first
        // `up_to` of them: a measured table holds MIN_VALID_SAMPLES in its first row.
        let valid = |up_to: usize| {
            let seen = |s: usize| {
                let (i, j, k) = (
                    s / (PHI_D_RES * THETA_D_RES),
                    s / PHI_D_RES % THETA_D_RES,
                    s % PHI_D_RES,
                );
                let (wi, wo) = from_half_diff(bin_angles(i, j, k));
                wi.z > 0.0 && wo.z > 0.0
            };
            (0..SAMPLES)
                .filter(|&s| table.value_at(s).is_some() && seen(s))
                .take(up_to)
                .count()
        };
        let Some(backscatter) = fill_missing(&slice) else {
            return Err(format!(
                "no valid backscattering sample (θd = 0) among its {} valid samples above the \
                 horizon",
                valid(SAMPLES)
            ));
        };
        let n = valid(MIN_VALID_SAMPLES);
        if n < MIN_VALID_SAMPLES {
            return Err(format!(
                "{n} valid sample{} above the horizon; a source needs at least \
                 {MIN_VALID_SAMPLES} to be fitted (F on each of the {THETA_D_RES} θd bins and ρd \
                 per channel, and α)",
                if n == 1 { "" } else { "s" }
            ));
        }
        Ok(MerlBrdf {
            name: name.into(),
            table,
            backscatter,
        })
    }

    /// The table read.
    pub fn table(&self) -> &MerlTable {
        &self.table
    }
}

/// Fills `None` entries by linear interpolation between the nearest valid neighbours (constant
/// beyond the ends). `None` if nothing is valid.
pub(crate) fn fill_missing(v: &[Option<Rgb>]) -> Option<Vec<Rgb>> {
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

impl Brdf for MerlBrdf {
    fn name(&self) -> &str {
        &self.name
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        self.table.lookup_interpolated(wi, wo)
    }

    fn backscatter(&self, theta: f64, _phi: f64) -> Option<Rgb> {
        // θd = 0 samples sit at integer sqrt-θh coordinates; interpolate linearly between them.
        let last = THETA_H_RES - 1;
        let x = (theta.max(0.0) / FRAC_PI_2).sqrt() * THETA_H_RES as f64;
        if x > last as f64 {
            // Past the last sample (88°) hold f cos θ constant: f(o,o) grows like 1/cos θ at
            // grazing angles (G1 ∝ cos θ there), while f cos θ tends to a finite limit.
            let theta_last = bin_angles(last, 0, 0).theta_h;
            let scale = theta_last.cos() / theta.cos().max(1e-6);
            return Some(self.backscatter[last].map(|v| v * scale));
        }
        let i0 = (x as usize).min(THETA_H_RES - 2);
        let t = x - i0 as f64;
        let (a, b) = (self.backscatter[i0], self.backscatter[i0 + 1]);
        Some(std::array::from_fn(|c| a[c] + t * (b[c] - a[c])))
    }

    fn merl_table(&self) -> std::borrow::Cow<'_, MerlTable> {
        std::borrow::Cow::Borrowed(&self.table)
    }
}
