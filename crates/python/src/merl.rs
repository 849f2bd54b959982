//! MERL tables as NumPy arrays: `Brdf.to_merl` and `facet_brdf.from_merl`.
//!
//! The array holds f_r, the file's stored values times its scales (1, 1.15, 1.66) / 1500, so
//! that it can be compared with `Brdf.eval`; negative values mark missing samples, as in the
//! file. Through an array and back a value may move by one unit in the last place (the scale
//! is multiplied in and divided out).

use crate::brdf::PyBrdf;
use crate::error::facet_err;
use facet_fit::model::merl_grid::{MerlTable, PHI_D_RES, SAMPLES, SCALE, THETA_D_RES, THETA_H_RES};
use facet_fit::sources::merl::MerlBrdf;
use numpy::ndarray::Array4;
use numpy::{PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// The array's shape: channel, θh, θd and φd bins (the file's order).
const SHAPE: [usize; 4] = [3, THETA_H_RES, THETA_D_RES, PHI_D_RES];

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
fn file_bytes(values: &[f64]) -> Vec<u8> {
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

/// A MERL measurement from an array shaped like `Brdf.to_merl`'s: (3, 90, 90, 180) f_r values
/// (channel, θh, θd, φd bins; f_r, not the file's stored values), negative where a sample is
/// missing. It is evaluated as a MERL file is (interpolated between bins). Raises FacetError
/// for another shape, a NaN, an infinite or too large value, or a table the fitter cannot use
/// (no backscattering sample, fewer than 92 valid samples).
#[pyfunction]
#[pyo3(signature = (array, name = "from_merl"))]
pub fn from_merl(py: Python<'_>, array: &Bound<'_, PyAny>, name: &str) -> PyResult<PyBrdf> {
    let arr = crate::arrays::contiguous_f64(array)?;
    if arr.shape() != SHAPE {
        return Err(facet_err(format!(
            "from_merl: an array of shape (3, 90, 90, 180) is needed, not {:?}",
            arr.shape()
        )));
    }
    let ro = arr.readonly();
    let bytes = file_bytes(ro.as_slice()?);
    let label = format!("<array {name}>");
    let src = py.allow_threads(|| {
        let table = MerlTable::parse(Path::new(&label), &bytes).map_err(facet_err)?;
        MerlBrdf::from_table(name, table)
            .map_err(|problem| facet_err(format!("{label}: {problem}")))
    })?;
    Ok(PyBrdf::new(Arc::new(src), "from_merl"))
}
