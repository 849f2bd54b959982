//! NumPy arrays in and out: any array-like of directions made a C-contiguous float64 array.

use crate::error::facet_err;
use glam::DVec3;
use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// `obj` as `numpy.ascontiguousarray(obj, dtype=float64)`: lists, other dtypes and strided
/// views are accepted and copied once.
pub fn contiguous_f64<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let np = obj.py().import("numpy")?;
    let arr = np.call_method1("ascontiguousarray", (obj, np.getattr("float64")?))?;
    Ok(arr.downcast_into::<PyArrayDyn<f64>>()?)
}

/// An (N, 3) array of directions, `what` naming it in errors.
pub fn directions(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<DVec3>> {
    let arr = contiguous_f64(obj)?;
    let shape = arr.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(facet_err(format!(
            "{what}: an array of shape (N, 3) is needed, not {shape:?}"
        )));
    }
    let ro = arr.readonly();
    let v = ro.as_slice()?;
    Ok(v.chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect())
}
