//! `facet_brdf.fit` and `facet_brdf.Fit`: the fit `facet fit` runs, its record as a dict, its
//! models as `Brdf`s, its exports.

use crate::brdf::{PyBrdf, open};
use crate::error::facet_err;
use facet_fit::export::{ExportOptions, KindRequest, ModelRequest, Target, export};
use facet_fit::extract::Stopping;
use facet_fit::fitting::{CoatSearch, FitConfig, Models, fit_material};
use facet_fit::metric::Metric;
use facet_fit::model::fresnel_curves::FresnelChoice;
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_fit::model::microfacet::Ndf;
use facet_fit::numerics::quadrature::Quadrature;
use numpy::ndarray::ArrayD;
use numpy::{IntoPyArray, PyArrayDyn, PyArrayMethods};
use pyo3::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Most (θ, φ) directions of an anisotropic extraction (`facet fit`'s limit).
const MAX_ANISO_DIRECTIONS: usize = 65536;

/// The options of `facet fit`, as `fit`'s keywords give them.
pub struct FitOptions<'a> {
    /// `model`: `all`, `tabulated`, `ggx` or `beckmann`.
    pub model: &'a str,
    /// `aniso`.
    pub aniso: bool,
    /// `resolution`: polar nodes, 2 to 4096.
    pub resolution: Option<usize>,
    /// `phi_resolution`: azimuthal nodes of an anisotropic fit, 1 to 1024.
    pub phi_resolution: usize,
    /// `iterations`: a fixed number of power iterations, 1 to 10000.
    pub iterations: Option<usize>,
    /// `tolerance`, 1e-15 to 1.
    pub tolerance: f64,
    /// `quadrature`.
    pub quadrature: &'a str,
    /// `no_diffuse`.
    pub no_diffuse: bool,
    /// `no_refine`.
    pub no_refine: bool,
    /// `fresnel`.
    pub fresnel: &'a str,
    /// `coat`: `auto`, `always` or `off`.
    pub coat: &'a str,
    /// `metric`: `perceptual` or `log`; `None` as `facet fit` chooses.
    pub metric: Option<&'a str>,
}

/// A whole number in `lo..=hi`, `name` naming it.
fn in_range(name: &str, v: usize, lo: usize, hi: usize) -> PyResult<usize> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(facet_err(format!("{name}: {v} is outside {lo} to {hi}")))
    }
}

/// `value` as one of `names`, `name` naming the option.
fn choice<T: Copy>(name: &str, value: &str, names: &[(&str, T)]) -> PyResult<T> {
    names
        .iter()
        .find(|(n, _)| *n == value)
        .map(|&(_, t)| t)
        .ok_or_else(|| {
            let list: Vec<&str> = names.iter().map(|(n, _)| *n).collect();
            facet_err(format!(
                "{name}: `{value}` is not one of {}",
                list.join(", ")
            ))
        })
}

impl FitOptions<'_> {
    /// The configuration `facet fit` builds from the same options (`FitArgs::config` in
    /// `src/fit_cmd.rs`, step for step; `tests/test_fit.py` compares the records).
    pub fn config(&self) -> PyResult<FitConfig> {
        let mut cfg = if self.aniso {
            FitConfig::anisotropic()
        } else {
            FitConfig::isotropic()
        };
        if let Some(n) = self.resolution {
            cfg.extract.resolution = in_range("resolution", n, 2, 4096)?;
        }
        let metric = self
            .metric
            .map(|m| {
                choice(
                    "metric",
                    m,
                    &[("perceptual", Metric::Perceptual), ("log", Metric::Log)],
                )
            })
            .transpose()?;
        cfg.metric = match metric {
            Some(m) => m,
            None if self.no_diffuse || self.aniso => Metric::Log,
            None => Metric::Perceptual,
        };
        cfg.diffuse &= !self.no_diffuse;
        cfg.refine &= !self.no_refine && cfg.diffuse;
        let coat = choice(
            "coat",
            self.coat,
            &[
                ("auto", CoatSearch::Auto),
                ("always", CoatSearch::Always),
                ("off", CoatSearch::Off),
            ],
        )?;
        if cfg.diffuse && !self.aniso {
            cfg.coat = coat;
        }
        cfg.fresnel = choice(
            "fresnel",
            self.fresnel,
            &[
                ("table", FresnelChoice::Table),
                ("conductor", FresnelChoice::Conductor),
                ("dielectric", FresnelChoice::Dielectric),
                ("schlick", FresnelChoice::Schlick),
            ],
        )?;
        if cfg.fresnel != FresnelChoice::Table && (!cfg.diffuse || self.aniso) {
            return Err(facet_err(
                "fresnel other than table needs the diffuse lobe (not no_diffuse or aniso)",
            ));
        }
        if self.aniso {
            cfg.extract.phi_resolution = in_range("phi_resolution", self.phi_resolution, 1, 1024)?;
            let dirs = cfg.extract.resolution * cfg.extract.phi_resolution;
            if dirs > MAX_ANISO_DIRECTIONS {
                return Err(facet_err(format!(
                    "resolution {} × phi_resolution {} = {dirs} directions; aniso takes at most \
                     {MAX_ANISO_DIRECTIONS}",
                    cfg.extract.resolution, cfg.extract.phi_resolution
                )));
            }
        }
        if !(1e-15..=1.0).contains(&self.tolerance) {
            return Err(facet_err(format!(
                "tolerance: {} is outside [1e-15, 1]",
                self.tolerance
            )));
        }
        cfg.extract.stopping = match self.iterations {
            Some(m) => Stopping::Fixed(in_range("iterations", m, 1, 10_000)?),
            None => Stopping::Converge {
                tolerance: self.tolerance,
                max_iterations: 10_000,
            },
        };
        cfg.extract.quadrature = choice(
            "quadrature",
            self.quadrature,
            &[
                ("uniform-theta", Quadrature::UniformTheta),
                ("sqrt-midpoint", Quadrature::SqrtMidpoint),
                ("gauss-legendre-sqrt", Quadrature::GaussLegendreSqrt),
            ],
        )?;
        let only = |tabulated, ggx, beckmann| Models {
            tabulated,
            ggx,
            beckmann,
        };
        cfg.models = choice(
            "model",
            self.model,
            &[
                ("all", Models::ALL),
                ("tabulated", only(true, false, false)),
                ("ggx", only(false, true, false)),
                ("beckmann", only(false, false, true)),
            ],
        )?;
        Ok(cfg)
    }
}

/// A fit: the record `facet fit` writes as JSON, and its models.
#[pyclass(name = "Fit", module = "facet_brdf", frozen)]
pub struct PyFit {
    /// The fit.
    pub fit: Arc<FittedMaterial>,
}

#[pymethods]
impl PyFit {
    /// The fitted material's name (the source's).
    #[getter]
    fn name(&self) -> &str {
        &self.fit.record.name
    }

    /// The fit JSON `facet fit` writes, as a dict (the same serialisation, read by `json`).
    #[getter]
    fn record<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = serde_json::to_string(&self.fit.record).map_err(facet_err)?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The record as the JSON text `facet fit` writes (pretty-printed, as in the file).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.fit.record).map_err(facet_err)
    }

    /// One of the fit's models as a Brdf: `tabulated` (the extracted NDF), `ggx` or `beckmann`;
    /// with `coated=True` the same model of the base under the clear coat the fit kept.
    /// Raises FacetError for a model the fit did not fit, or a coat it did not keep.
    #[pyo3(signature = (model = "tabulated", *, coated = false))]
    fn model(&self, model: &str, coated: bool) -> PyResult<PyBrdf> {
        let choice = ModelChoice::parse(model).ok_or_else(|| {
            facet_err(format!(
                "model: `{model}` is not one of tabulated, ggx, beckmann"
            ))
        })?;
        let name = &self.fit.record.name;
        let missing = || facet_err(format!("{name}: the fit has no {model} model"));
        let input = format!("fit:{name}:{model}");
        if coated {
            let c = self
                .fit
                .coated
                .as_ref()
                .ok_or_else(|| facet_err(format!("{name}: the fit kept no coat")))?;
            let m = c.model(choice).ok_or_else(missing)?;
            return Ok(PyBrdf::new(Arc::new(m), input + ":coated"));
        }
        let m = self.fit.model(choice).ok_or_else(missing)?;
        Ok(PyBrdf::new(Arc::new(m.clone()), input))
    }

    /// Writes the record as `facet fit` does (pretty JSON, atomically); `load` reads it back.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let fit = &self.fit;
        py.allow_threads(|| fit.save(&path)).map_err(facet_err)
    }

    /// The tabulated NDF D(θ, φ) (per steradian, as extracted: the tables CSV's `ndf_d`) at
    /// polar angles `theta` (radians; a number or an array, whose shape the result takes).
    #[pyo3(signature = (theta, phi = 0.0))]
    fn ndf<'py>(
        &self,
        py: Python<'py>,
        theta: &Bound<'py, PyAny>,
        phi: f64,
    ) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
        let Ndf::Tabulated(ndf) = &self.fit.tabulated.ndf else {
            unreachable!("the tabulated model has a tabulated NDF")
        };
        let theta = crate::arrays::contiguous_f64(theta)?;
        let d: ArrayD<f64> = theta.readonly().as_array().mapv(|t| ndf.base_d(t, phi));
        Ok(d.into_pyarray(py))
    }

    /// The fit exported for a renderer as `facet export` writes it: (the file's text, what it
    /// approximates as a dict). `target`: `mitsuba`, `pbrt` or `gltf`; `model`: `ggx`,
    /// `beckmann` or `best`; `kind`: `auto`, `conductor` or `plastic`; `coat`: export the clear
    /// coat where the fit kept one (a Mitsuba export then names a `.bsdf` table, written into
    /// `table_dir`, which it then needs).
    #[pyo3(signature = (target = "mitsuba", model = "ggx", *, kind = "auto", coat = false, table_dir = None))]
    fn export<'py>(
        &self,
        py: Python<'py>,
        target: &str,
        model: &str,
        kind: &str,
        coat: bool,
        table_dir: Option<PathBuf>,
    ) -> PyResult<(String, Bound<'py, PyAny>)> {
        let options = ExportOptions {
            target: choice(
                "target",
                target,
                &[
                    ("mitsuba", Target::Mitsuba),
                    ("pbrt", Target::Pbrt),
                    ("gltf", Target::Gltf),
                ],
            )?,
            model: choice(
                "model",
                model,
                &[
                    ("ggx", ModelRequest::Ggx),
                    ("beckmann", ModelRequest::Beckmann),
                    ("best", ModelRequest::Best),
                ],
            )?,
            kind: choice(
                "kind",
                kind,
                &[
                    ("auto", KindRequest::Auto),
                    ("conductor", KindRequest::Conductor),
                    ("plastic", KindRequest::Plastic),
                ],
            )?,
            coat,
        };
        let fit = &self.fit;
        let label = format!("{}.json", self.fit.record.name);
        let exported = py
            .allow_threads(|| export(fit, Path::new(&label), &options))
            .map_err(facet_err)?;
        if let Some(table) = &exported.table {
            let dir = table_dir.ok_or_else(|| {
                facet_err(format!(
                    "{}: the coated export names the table {}; pass table_dir to write it (or \
                     coat=False)",
                    self.fit.record.name, table.name
                ))
            })?;
            let path = dir.join(&table.name);
            facet_fit::io::output::write_bytes_atomically(&path, &table.bytes)
                .map_err(|e| facet_err(format!("{}: {e}", path.display())))?;
        }
        let report = serde_json::to_string(&exported.report).map_err(facet_err)?;
        let report = py.import("json")?.call_method1("loads", (report,))?;
        Ok((exported.text, report))
    }

    /// The fit as the dict of a Mitsuba 3 BSDF, for `mitsuba.load_dict`: `facet export`'s
    /// Mitsuba file (`roughconductor` or `roughplastic` from the `model` fit, GGX by default)
    /// read into a dict. It approximates the fit as that file's comment states (a physical
    /// Fresnel curve for the F table, Mitsuba's own diffuse term under a plastic, its
    /// shadowing-masking): `export("mitsuba", model)[1]` is that statement as a dict. With
    /// `coat=True` a fit that kept a coat becomes a `measured` BSDF on a `.bsdf` table written
    /// into `table_dir`.
    #[pyo3(signature = (model = "ggx", *, kind = "auto", coat = false, table_dir = None))]
    fn to_mitsuba<'py>(
        &self,
        py: Python<'py>,
        model: &str,
        kind: &str,
        coat: bool,
        table_dir: Option<PathBuf>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (text, _) = self.export(py, "mitsuba", model, kind, coat, table_dir.clone())?;
        py.import("facet_brdf._mitsuba")?
            .call_method1("xml_to_dict", (text, table_dir))
    }

    fn __repr__(&self) -> String {
        let r = &self.fit.record;
        let py = |v: Option<f64>| v.map_or("None".to_owned(), |v| format!("{v:.6}"));
        format!(
            "facet_brdf.Fit({:?}, tabulated_error={}, ggx_alpha={}, coat={})",
            r.name,
            py(r.tabulated.error),
            py(r.ggx.as_ref().map(|p| p.alpha_x)),
            if r.coat.is_some() { "True" } else { "False" }
        )
    }
}

/// Fits a source as `facet fit` does, with the GIL released: `source` is anything `load`
/// takes (its string is then the record's `source`, as on the command line) or a Brdf. The
/// keywords are `facet fit`'s options. `backend`: `cpu` or `auto` (the CPU: this package is
/// built without facet-fit's GPU backend; `gpu` raises FacetError).
#[pyfunction]
#[pyo3(signature = (
    source, *, aniso = false, coat = "auto", backend = "cpu", model = "all", resolution = None,
    phi_resolution = 64, iterations = None, tolerance = 1e-9, quadrature = "gauss-legendre-sqrt",
    no_diffuse = false, no_refine = false, fresnel = "table", metric = None, nbrdf = None
))]
#[allow(clippy::too_many_arguments)]
pub fn fit(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    aniso: bool,
    coat: &str,
    backend: &str,
    model: &str,
    resolution: Option<usize>,
    phi_resolution: usize,
    iterations: Option<usize>,
    tolerance: f64,
    quadrature: &str,
    no_diffuse: bool,
    no_refine: bool,
    fresnel: &str,
    metric: Option<&str>,
    nbrdf: Option<PathBuf>,
) -> PyResult<PyFit> {
    match backend {
        "cpu" | "auto" => {}
        "gpu" => {
            return Err(facet_err(
                "backend gpu: this build of facet_brdf fits on the CPU only (the `facet` \
                 command has the GPU backend)",
            ));
        }
        other => {
            return Err(facet_err(format!(
                "backend: `{other}` is not one of auto, gpu, cpu"
            )));
        }
    }
    let cfg = FitOptions {
        model,
        aniso,
        resolution,
        phi_resolution,
        iterations,
        tolerance,
        quadrature,
        no_diffuse,
        no_refine,
        fresnel,
        coat,
        metric,
    }
    .config()?;
    let (brdf, load_ms) = match source.downcast::<PyBrdf>() {
        Ok(b) => {
            let b = b.get();
            (PyBrdf::new(b.brdf.clone(), b.input.clone()), 0.0)
        }
        Err(_) => {
            let path: PathBuf = source.extract()?;
            let t = Instant::now();
            let b = open(py, &path.to_string_lossy(), nbrdf)?;
            (b, t.elapsed().as_secs_f64() * 1e3)
        }
    };
    let src = &*brdf.brdf;
    let input = &brdf.input;
    let mut fit = py
        .allow_threads(|| fit_material(src, input, &cfg))
        .map_err(facet_err)?;
    // As `facet fit` records the reading of its input.
    fit.record.timings_ms.load = load_ms;
    fit.record.timings_ms.total += load_ms;
    Ok(PyFit { fit: Arc::new(fit) })
}
