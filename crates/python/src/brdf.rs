//! `facet_brdf.Brdf` and `facet_brdf.load`: any source `facet fit` reads, evaluated on arrays
//! of directions over all cores.

use crate::arrays::directions;
use crate::error::facet_err;
use crate::merl::{SHAPE, file_bytes, table_array};
use facet_fit::Brdf;
use facet_fit::export::rgl::{BsdfResolution, write_rgl};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::rgl::RglBsdf;
use facet_fit::sources::{InputSpec, Residence};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyArray4};
use numpy::{PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Pairs per rayon task of [`PyBrdf::eval`]: large enough that scheduling is noise, small
/// enough that 2 to 16 cores share 10⁴ pairs.
const CHUNK: usize = 256;

/// A BRDF: measured (MERL, RGL `.bsdf`, a neural proxy), analytic, or a fit's model.
#[pyclass(name = "Brdf", module = "facet_brdf", frozen)]
pub struct PyBrdf {
    /// The source.
    pub brdf: Arc<dyn Brdf + Send>,
    /// Where it came from, as the caller named it (`facet fit`'s INPUT, `from_merl`, a fit's
    /// model): the fit record's `source`, and the `.bsdf` description.
    pub input: String,
}

impl PyBrdf {
    /// Wraps a source named `input`.
    pub fn new(brdf: Arc<dyn Brdf + Send>, input: impl Into<String>) -> Self {
        PyBrdf {
            brdf,
            input: input.into(),
        }
    }
}

/// f_r of `brdf` on each pair, three values a pair; NaN where `eval` returns `None`.
pub fn eval_pairs(brdf: &dyn Brdf, wi: &[glam::DVec3], wo: &[glam::DVec3]) -> Vec<f64> {
    let mut out = vec![0.0; 3 * wi.len()];
    out.par_chunks_mut(3 * CHUNK)
        .zip(wi.par_chunks(CHUNK).zip(wo.par_chunks(CHUNK)))
        .for_each(|(out, (wi, wo))| {
            for ((f, &wi), &wo) in out.chunks_exact_mut(3).zip(wi).zip(wo) {
                f.copy_from_slice(&brdf.eval(wi, wo).unwrap_or([f64::NAN; 3]));
            }
        });
    out
}

#[pymethods]
impl PyBrdf {
    /// The source's name (a file's stem, a proxy's name, `<fit>-ggx`, ...).
    #[getter]
    fn name(&self) -> &str {
        self.brdf.name()
    }

    /// Where the source came from, as it was named (`load`'s `source`, `"from_merl"`, ...).
    #[getter]
    fn source(&self) -> &str {
        &self.input
    }

    /// Whether f_r is invariant under rotation about the normal.
    #[getter]
    fn is_isotropic(&self) -> bool {
        self.brdf.is_isotropic()
    }

    /// f_r(wi, wo) per RGB channel, without the cosine: an (N, 3) float64 array for `wi`, `wo`
    /// of shape (N, 3) in the local frame (z the normal, directions pointing away from the
    /// surface; they are used as given, not normalised). NaN where the source has no value: a
    /// direction at or below the horizon, a missing MERL sample. Runs on all cores
    /// (`RAYON_NUM_THREADS` limits them) with the GIL released.
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let wi = directions(wi, "wi")?;
        let wo = directions(wo, "wo")?;
        if wi.len() != wo.len() {
            return Err(facet_err(format!(
                "wi has {} directions, wo {}: eval takes pairs",
                wi.len(),
                wo.len()
            )));
        }
        let brdf = &*self.brdf;
        let out = py.allow_threads(|| eval_pairs(brdf, &wi, &wo));
        let n = wi.len();
        Ok(Array2::from_shape_vec((n, 3), out)
            .expect("3 values a pair")
            .into_pyarray(py))
    }

    /// The source sampled on the MERL grid, as `from_merl` takes it: f_r (the file's values
    /// times its scales) in an array of shape (3, 90, 90, 180) (channel, θh, θd, φd bins),
    /// negative (−1) where missing. A MERL source gives its own samples; any other is sampled at
    /// the bins' lower edges, as `facet convert IN OUT.binary` does.
    fn to_merl<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray4<f64>> {
        let brdf = &*self.brdf;
        py.allow_threads(|| table_array(&brdf.merl_table()))
            .into_pyarray(py)
    }

    /// Writes the source by `path`'s extension, as `facet convert` writes it: `.binary` (the
    /// MERL table of `to_merl`) or `.bsdf` (RGL, RGB, at convert's standard resolution; it is
    /// read back to check it). An existing file is replaced (atomically).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let brdf = &*self.brdf;
        let input = &self.input;
        py.allow_threads(|| save(brdf, input, &path))
    }

    fn __repr__(&self) -> String {
        format!(
            "facet_brdf.Brdf({:?}, source={:?})",
            self.brdf.name(),
            self.input
        )
    }
}

/// [`PyBrdf::save`] without the GIL.
fn save(brdf: &dyn Brdf, input: &str, path: &Path) -> PyResult<()> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("binary") => brdf.merl_table().write(path).map_err(facet_err),
        Some("bsdf") => {
            // The description `facet convert` writes.
            let description = format!(
                "{} written by facet {} from {input}",
                brdf.name(),
                env!("CARGO_PKG_VERSION"),
            );
            write_rgl(path, brdf, BsdfResolution::standard(), &description).map_err(facet_err)?;
            RglBsdf::open(path).map_err(facet_err)?;
            Ok(())
        }
        _ => Err(facet_err(format!(
            "{}: the extension says the format: .binary (MERL) or .bsdf (RGL); a fit's JSON is \
             Fit.save's",
            path.display()
        ))),
    }
}

/// Opens `source` as `facet fit` does ([`InputSpec::parse`]), the GIL released.
pub fn open(py: Python<'_>, source: &str, nbrdf: Option<PathBuf>) -> PyResult<PyBrdf> {
    let spec = InputSpec::parse(source);
    let brdf = py.allow_threads(|| {
        let nbrdf = NbrdfLibrary::override_path(nbrdf.as_deref());
        // Read into memory, not mapped: a Python session may outlive the file's contents.
        spec.open(nbrdf.as_deref(), &mut None, Residence::Read)
    });
    Ok(PyBrdf::new(Arc::from(brdf.map_err(facet_err)?), source))
}

/// A source, as `facet fit INPUT` names it: a MERL `.binary` (any name but the others), an
/// RGL `.bsdf`, `nbrdf:NAME` (a neural proxy of the MERL database; `nbrdf` is the proxies'
/// file, default `$FACET_NBRDF`, else the embedded ones), `analytic:SPEC` (e.g.
/// `analytic:ggx?alpha=0.2&f0=0.04`) or a fit `.json` (its tabulated model, under its coat
/// when it kept one). Raises FacetError naming the file when it cannot be read.
#[pyfunction]
#[pyo3(signature = (source, nbrdf = None))]
pub fn load(py: Python<'_>, source: PathBuf, nbrdf: Option<PathBuf>) -> PyResult<PyBrdf> {
    open(py, &source.to_string_lossy(), nbrdf)
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
