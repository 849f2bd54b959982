//! MERL tables as NumPy arrays and back, for `Brdf.to_merl` and `facet_brdf.from_merl`.
//!
//! The array holds f_r, the file's stored values times its scales (1, 1.15, 1.66) / 1500, so
//! that it can be compared with `Brdf.eval`; negative values mark missing samples, as in the
//! file. Through an array and back a value may move by one unit in the last place (the scale
//! is multiplied in and divided out).

use facet_fit::model::merl_grid::{MerlTable, PHI_D_RES, SAMPLES, SCALE, THETA_D_RES, THETA_H_RES};
use numpy::ndarray::Array4;

/// The array's shape: channel, θh, θd and φd bins (the file's order).
pub const SHAPE: [usize; 4] = [3, THETA_H_RES, THETA_D_RES, PHI_D_RES];

/// The table as f_r, −1 where a channel's sample is missing.
pub fn table_array(table: &MerlTable) -> Array4<f64> {
    let mut v = Vec::with_capacity(3 * SAMPLES);
    for (c, scale) in SCALE.iter().enumerate() {
        v.extend(table.channel(c).iter().map(|b| {
            let stored = f64::from_le_bytes(*b);
            if stored < 0.0 { -1.0 } else { stored * scale }
        }));
    }
    Array4::from_shape_vec(SHAPE, v).expect("3 channels of SAMPLES values")
}

/// The bytes of the MERL file holding `values` (f_r, channel-major), for
/// [`MerlTable::parse`]: the array is checked by the file reader's own predicate.
pub fn file_bytes(values: &[f64]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(12 + 8 * values.len());
    for d in [THETA_H_RES, THETA_D_RES, PHI_D_RES] {
        bytes.extend((d as i32).to_le_bytes());
    }
    for (c, chunk) in values.chunks_exact(SAMPLES).enumerate() {
        for &f in chunk {
            let stored = if f < 0.0 { -1.0 } else { f / SCALE[c] };
            bytes.extend(stored.to_le_bytes());
        }
    }
    bytes
}
