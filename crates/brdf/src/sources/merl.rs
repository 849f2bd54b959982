//! MERL isotropic BRDF files (Matusik et al. 2003): reader and writer, and the measurement as a
//! BRDF source. The grid and its lookups are [`crate::model::merl_grid`]'s.
//!
//! File layout: three little-endian `i32` dimensions (90, 90, 180) followed by 3·n `f64`
//! values, all red then all green then all blue, sample index
//! `φd_bin + 180 (θd_bin + 90 θh_bin)`. A stored value times the channel scale
//! (1, 1.15, 1.66) / 1500 is f_r; a negative value marks a missing sample.
//! Sample (i, j, k) sits at the bin's lower edge: θh = (i/90)² π/2, θd = j/90 · π/2, φd = k/180 · π.

use crate::error::BrdfError;
use crate::io::mapped_file::MappedFile;
use crate::model::brdf::Brdf;
use crate::model::geometry::from_half_diff;
use crate::model::merl_grid::{
    HEADER_BYTES, MAX_STORED, MIN_VALID_SAMPLES, MerlTable, PHI_D_RES, SAMPLES, Stored,
    THETA_D_RES, THETA_H_RES, bin_angles, bin_of, stored,
};
use crate::model::rgb::Rgb;
use crate::numerics::interp::fill_missing;
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;
use std::io::Write;
use std::path::Path;

impl MerlTable {
    /// Reads and validates a MERL `.binary` file into memory.
    pub fn read(path: &Path) -> Result<Self, BrdfError> {
        if let Some(table) = Self::read_standard(path, false)? {
            return Ok(table);
        }
        Self::parse(
            path,
            &crate::io::input::read(path, crate::io::input::Cap::MERL)?,
        )
    }

    /// Maps and validates a MERL `.binary` file: the fast way for a short-lived process, as
    /// [`MerlTable::read`] in all else (the same errors; a file that is not standard, and any
    /// system without `mmap`, is read). The file must not be truncated or rewritten in place
    /// while the table lives: a read of the lost part would fault (see `mapped_file.rs`).
    /// Replacing it by a rename, as [`MerlTable::write`] does, is safe.
    pub fn map(path: &Path) -> Result<Self, BrdfError> {
        if let Some(table) = Self::read_standard(path, true)? {
            return Ok(table);
        }
        Self::parse(
            path,
            &crate::io::input::read(path, crate::io::input::Cap::MERL)?,
        )
    }

    /// A file of exactly the standard size with the standard header, mapped (`map`) or read
    /// straight into the table (one 35 MB buffer, not a byte copy beside it); `None` for any
    /// other file, which [`MerlTable::parse`] then reads and explains.
    fn read_standard(path: &Path, map: bool) -> Result<Option<Self>, BrdfError> {
        use std::io::Read;
        let (mut file, len) = crate::io::input::open(path, crate::io::input::Cap::MERL)?;
        if len != HEADER_BYTES + (3 * 8 * SAMPLES) as u64 {
            return Ok(None);
        }
        let io = |e| BrdfError::io(path, e);
        let mut header = [0u8; HEADER_BYTES as usize];
        let raw = match map.then(|| MappedFile::map(&file, len as usize)).flatten() {
            Some(m) => {
                header.copy_from_slice(&m.bytes()[..HEADER_BYTES as usize]);
                Stored::Mapped(m)
            }
            None => {
                let mut raw = vec![[0u8; 8]; 3 * SAMPLES];
                crate::io::huge_pages::advise(&mut raw);
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
        // Read without `input::read`: said to a recording here, with the bytes it holds.
        let values: &[u8] = bytemuck::cast_slice(raw.values());
        crate::io::input::note_read(path, &[&header, values]);
        Ok(Some(MerlTable { raw }))
    }

    /// Validates the bytes of a MERL file; `path` names it in errors.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, BrdfError> {
        let bad = |problem: String| BrdfError::Merl {
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
            let (i, j, k) = bin_of(s);
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
    pub fn write(&self, path: &Path) -> Result<(), BrdfError> {
        crate::io::output::write_atomically(path, |tmp| {
            let mut file = std::io::BufWriter::new(std::fs::File::create(tmp)?);
            for d in [THETA_H_RES, THETA_D_RES, PHI_D_RES] {
                file.write_all(&(d as i32).to_le_bytes())?;
            }
            file.write_all(bytemuck::cast_slice(self.raw.values()))?;
            file.into_inner().map_err(|e| e.into_error())?.sync_all()
        })
        .map_err(|e| BrdfError::io(path, e))
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
    pub fn open(path: &Path) -> Result<Self, BrdfError> {
        Self::named(path, MerlTable::read(path)?)
    }

    /// Maps a MERL `.binary` file ([`MerlTable::map`]: faster, for a short-lived process; the
    /// file must not be truncated in place while the source lives).
    pub fn map(path: &Path) -> Result<Self, BrdfError> {
        Self::named(path, MerlTable::map(path)?)
    }

    /// The table of the file at `path`, named after the file's stem.
    fn named(path: &Path, table: MerlTable) -> Result<Self, BrdfError> {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Self::from_table(name, table).map_err(|problem| BrdfError::Merl {
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
                let (i, j, k) = bin_of(s);
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
