//! MERL: the 35 MB table is mutated in place (header, length, a few values) and restored.

use crate::ggx_table;
use crate::harness::{SplitMix64, Target, refused, save_dir};
use crate::mutate::BYTES;
use facet_fit::model::merl_grid::{MAX_STORED, MerlTable, SAMPLES};
use facet_oracles::merl_sane;
use std::fmt::Write as _;
use std::path::PathBuf;

const MERL_DIMS: [i32; 13] = [
    0,
    -1,
    1,
    2,
    89,
    90,
    91,
    180,
    181,
    8100,
    1_458_000,
    i32::MAX,
    i32::MIN,
];

const MERL_VALUES: [f64; 16] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    MAX_STORED,
    1.000_000_000_000_1e12,
    1e308,
    f64::MAX,
    f64::MIN,
    -0.0,
    0.0,
    -1.0,
    5e-324,
    f64::MIN_POSITIVE,
    1e-300,
    -1e300,
    1.0,
];

pub struct Merl {
    pub path: PathBuf,
    /// The valid file, plus bytes appended by a case.
    pub bytes: Vec<u8>,
    valid_len: usize,
    /// How much of `bytes` the case feeds.
    len: usize,
    /// A small table (tiny dimensions) fed instead, when set.
    small: Option<Vec<u8>>,
    /// Bytes overwritten by the case: (offset, original).
    saved: Vec<(usize, Vec<u8>)>,
    /// Values written by the case: (flat index, value), checked against the table on Ok.
    written: Vec<(usize, f64)>,
    recipe: String,
}

impl Merl {
    /// `tag` keeps apart the files of two tests that build one at once.
    pub fn new(tag: &str) -> Self {
        let dir = save_dir();
        let file = dir.join(format!("ggx-0.2-{tag}.binary"));
        ggx_table().write(&file).unwrap();
        let bytes = std::fs::read(&file).unwrap();
        std::fs::remove_file(&file).unwrap();
        Merl {
            path: dir.join("mutated.binary"),
            valid_len: bytes.len(),
            len: bytes.len(),
            bytes,
            small: None,
            saved: Vec::new(),
            written: Vec::new(),
            recipe: String::new(),
        }
    }

    fn overwrite(&mut self, at: usize, new: &[u8]) {
        self.saved
            .push((at, self.bytes[at..at + new.len()].to_vec()));
        self.bytes[at..at + new.len()].copy_from_slice(new);
    }

    /// Value `index` (flat, channel-major) overwritten; its original is restored afterwards.
    fn write_value(&mut self, index: usize, v: f64) {
        self.overwrite(12 + 8 * index, &v.to_le_bytes());
        self.written.retain(|w| w.0 != index); // the last write is what the file holds
        self.written.push((index, v));
    }
}

impl Target for Merl {
    fn mutate(&mut self, rng: &mut SplitMix64) -> String {
        let mut log = String::new();
        match rng.below(20) {
            // The header: dimensions replaced, swapped, or bytes flipped.
            0..=4 => {
                for _ in 0..1 + rng.below(2) {
                    match rng.below(3) {
                        0 => {
                            let (d, v) = (rng.below(3), rng.pick(&MERL_DIMS));
                            self.overwrite(4 * d, &v.to_le_bytes());
                            let _ = write!(log, " dimension {d} = {v};");
                        }
                        1 => {
                            let (a, b) = (rng.below(3), rng.below(3));
                            let (x, y) = (
                                self.bytes[4 * a..4 * a + 4].to_vec(),
                                self.bytes[4 * b..4 * b + 4].to_vec(),
                            );
                            self.overwrite(4 * a, &y);
                            self.overwrite(4 * b, &x);
                            let _ = write!(log, " dimensions {a} and {b} swapped;");
                        }
                        _ => {
                            let (at, bit) = (rng.below(12), rng.below(8));
                            let flipped = self.bytes[at] ^ (1 << bit);
                            self.overwrite(at, &[flipped]);
                            let _ = write!(log, " flip bit {bit} of byte {at};");
                        }
                    }
                }
            }
            // The length: truncated (anywhere, or by a few bytes) or extended.
            5..=7 => match rng.below(3) {
                0 => {
                    self.len = rng.below(self.valid_len);
                    let _ = write!(log, " truncated to {} bytes;", self.len);
                }
                1 => {
                    self.len = self.valid_len - rng.pick(&[1, 4, 7, 8, 12, 24, 25]);
                    let _ = write!(log, " truncated to {} bytes;", self.len);
                }
                _ => {
                    let n = rng.pick(&[1, 7, 8, 16, 24, 100]);
                    let fill = rng.pick(&BYTES);
                    self.bytes.resize(self.valid_len + n, fill);
                    self.len = self.bytes.len();
                    let _ = write!(log, " {n} bytes {fill:#04x} appended;");
                }
            },
            // A few values: interesting ones, or a bit of the stored one flipped.
            8..=16 => {
                for _ in 0..1 + rng.below(4) {
                    let index = match rng.below(4) {
                        0 => rng.pick(&[
                            0,
                            SAMPLES - 1,
                            SAMPLES,
                            2 * SAMPLES - 1,
                            2 * SAMPLES,
                            3 * SAMPLES - 1,
                        ]),
                        _ => rng.below(3 * SAMPLES),
                    };
                    let v = if rng.percent(60) {
                        rng.pick(&MERL_VALUES)
                    } else {
                        let at = 12 + 8 * index;
                        let old = f64::from_le_bytes(self.bytes[at..at + 8].try_into().unwrap());
                        // Bits 52..63: the exponent and the sign.
                        f64::from_bits(old.to_bits() ^ (1 << (52 + rng.below(12))))
                    };
                    self.write_value(index, v);
                    let _ = write!(log, " value {index} = {v:e};");
                }
            }
            // A small file: tiny dimensions, a body of about the size they need.
            _ => {
                let dims: [i32; 3] = std::array::from_fn(|_| rng.pick(&[-1, 0, 1, 2, 3, 90, 180]));
                let n: i64 = dims.iter().map(|&d| d as i64).product();
                let body = match rng.below(3) {
                    0 => (24 * n.max(0)) as usize,
                    1 => ((24 * n).max(0) as usize).saturating_sub(8),
                    _ => rng.below(200),
                }
                .min(1 << 20);
                let mut small: Vec<u8> = dims.iter().flat_map(|d| d.to_le_bytes()).collect();
                small.extend((0..body).map(|_| rng.next() as u8));
                let _ = write!(
                    log,
                    " small file: dimensions {dims:?}, {body} bytes of values;"
                );
                self.small = Some(small);
            }
        }
        self.recipe = format!("ggx?alpha=0.2 sampled and written as MERL, then{log}");
        self.recipe.clone()
    }

    fn call(&mut self) -> Result<bool, String> {
        let bytes = self.small.as_deref().unwrap_or(&self.bytes[..self.len]);
        let table = match MerlTable::parse(&self.path, bytes) {
            Ok(t) => t,
            Err(e) => return refused(&self.path, e),
        };
        // Only the standard layout is accepted (a small file never is); every stored value as
        // read: NaN, ∞ and values above MAX_STORED refused.
        merl_sane(bytes, table, &self.written)?;
        Ok(true)
    }

    fn input(&self) -> Vec<u8> {
        match &self.small {
            Some(small) => small.clone(),
            None => self.recipe.clone().into_bytes(),
        }
    }

    fn restore(&mut self) {
        for (at, old) in self.saved.drain(..).rev() {
            self.bytes[at..at + old.len()].copy_from_slice(&old);
        }
        self.bytes.truncate(self.valid_len);
        self.len = self.valid_len;
        self.small = None;
        self.written.clear();
    }
}
