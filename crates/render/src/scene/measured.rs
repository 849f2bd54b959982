//! Measured materials: a surface whose BRDF is the measurement itself, not a model fitted to
//! it.
//!
//! - **MERL-grid tables** — a MERL `.binary`, `nbrdf:NAME`, or anything else
//!   [`InputSpec`] opens (an `analytic:` spec, a fit JSON) sampled onto the MERL grid — are
//!   evaluated by trilinear interpolation in MERL's (√θh, θd, φd) coordinates on the table's
//!   [`filled`](MerlTable::filled) samples, and importance-sampled by the visible normals of a
//!   fit's tabulated NDF (Dupuy & Jakob 2018 sample their measurements the same way): the fit
//!   named beside the measurement, or one the caller makes after loading
//!   ([`Scene::fit_measured`]). Loading never fits.
//! - **RGL `.bsdf` files** are evaluated and sampled by their own stored warps, as Mitsuba 3's
//!   `measured` plugin does; they need no fit.

use crate::error::RenderError;
use crate::scene::Scene;

use facet_brdf::Brdf;
use facet_brdf::model::material::FittedMaterial;
use facet_brdf::model::merl_grid::{MAX_X, MerlTable, bin_of};
use facet_brdf::sources::nbrdf::NbrdfLibrary;
use facet_brdf::sources::rgl::RglBsdf;
use facet_brdf::sources::{InputSpec, Residence};
use std::collections::HashMap;
use std::fmt::Display;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A measurement as the renderer holds it.
pub enum Measurement {
    /// A table on the MERL grid, its missing samples filled ([`MerlTable::filled`]).
    Merl(MerlTable),
    /// An RGL `.bsdf` file.
    Rgl(Box<RglBsdf>),
}

impl Measurement {
    /// The measurement of an opened source: an RGL file as itself (read again from its path),
    /// any other isotropic source sampled onto the MERL grid and [filled](MerlTable::filled).
    pub fn of(spec: &InputSpec, src: &dyn Brdf) -> Result<Self, String> {
        if let InputSpec::Rgl(p) = spec {
            return RglBsdf::open(p)
                .map(|b| Measurement::Rgl(Box::new(b)))
                .map_err(|e| e.to_string());
        }
        if !src.is_isotropic() {
            return Err(
                "an anisotropic source has no MERL table (the MERL grid is isotropic)".into(),
            );
        }
        // The fitter's bound on what a source may give, checked here too: a table rendered
        // with a fit given beside it is never fitted.
        let table = src.merl_table();
        if let Some((s, x)) = table.first_beyond_max_x() {
            let (i, j, k) = bin_of(s);
            return Err(format!(
                "f cos θi = {x:.3e} at bin ({i}, {j}, {k}): past {MAX_X:e}, the largest a source \
                 may give (`facet fit` refuses it too)"
            ));
        }
        Ok(Measurement::Merl(table.filled()))
    }
}

impl std::fmt::Debug for Measurement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Measurement::Merl(t) => write!(f, "Measurement::Merl({t:?})"),
            Measurement::Rgl(b) => write!(f, "Measurement::Rgl({})", b.name()),
        }
    }
}

/// A material rendered as its measurement.
#[derive(Clone)]
pub struct MeasuredMaterial {
    /// The measurement as named: a path, or `nbrdf:NAME` / `analytic:SPEC`.
    pub source: String,
    /// The file it was read from (`None` for the embedded proxies and analytic specs).
    pub path: Option<PathBuf>,
    /// The data, shared by every material that names the same source.
    pub data: Arc<Measurement>,
    /// The fit whose tabulated NDF samples a MERL-grid table: the one named beside it, or the
    /// caller's ([`Scene::fit_measured`]). `None` for a `.bsdf`, which samples by its own
    /// warps, and for a table loaded without a fit until the caller fits it.
    pub fit: Option<Arc<FittedMaterial>>,
    /// The opened source of a MERL-grid table loaded without a fit: what the caller fits
    /// (`None` once it has a fit, and for a `.bsdf`).
    pub unfitted: Option<Arc<dyn Brdf + Send>>,
}

impl std::fmt::Debug for MeasuredMaterial {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MeasuredMaterial")
            .field("source", &self.source)
            .field("path", &self.path)
            .field("data", &self.data)
            .field("fit", &self.fit)
            .field(
                "unfitted",
                &self.unfitted.as_ref().map(|s| s.name().to_owned()),
            )
            .finish()
    }
}

impl MeasuredMaterial {
    /// Opens the measurement `source` (a path relative to `base`, or `nbrdf:NAME` from
    /// `nbrdf`, else `$FACET_NBRDF`, else the embedded proxies). A MERL-grid table without a
    /// `fit` keeps its opened source in [`unfitted`](Self::unfitted) for the caller to fit
    /// ([`Scene::fit_measured`]); a `fit` given with a `.bsdf` is not needed and not kept.
    pub fn open(
        source: &str,
        base: &Path,
        fit: Option<Arc<FittedMaterial>>,
        nbrdf: Option<&Path>,
    ) -> Result<Self, RenderError> {
        let spec = match InputSpec::parse(source) {
            InputSpec::Fit(p) => InputSpec::Fit(base.join(p)),
            InputSpec::Rgl(p) => InputSpec::Rgl(base.join(p)),
            InputSpec::Merl(p) => InputSpec::Merl(base.join(p)),
            other => other,
        };
        let path = spec.path().map(Path::to_path_buf);
        let named = named(path.as_deref(), source);
        // An error that names the file already (the readers' do) is not prefixed twice.
        let fail = |e: &dyn std::fmt::Display| {
            let message = e.to_string();
            let prefix = format!("{}: ", named.display());
            RenderError::input(&named, message.strip_prefix(&prefix).unwrap_or(&message))
        };
        if let InputSpec::Rgl(p) = &spec {
            let bsdf = RglBsdf::open(p).map_err(|e| fail(&e))?;
            return Ok(MeasuredMaterial {
                source: source.to_owned(),
                path,
                data: Arc::new(Measurement::Rgl(Box::new(bsdf))),
                fit: None,
                unfitted: None,
            });
        }
        let mut library: Option<NbrdfLibrary> = None;
        let src = spec
            .open(nbrdf, &mut library, Residence::Read)
            .map_err(|e| fail(&e))?;
        let data = Measurement::of(&spec, &*src).map_err(|e| fail(&e))?;
        let unfitted = fit.is_none().then(|| Arc::from(src));
        Ok(MeasuredMaterial {
            source: source.to_owned(),
            path,
            data: Arc::new(data),
            fit,
            unfitted,
        })
    }

    /// The file or name its errors name.
    fn named(&self) -> PathBuf {
        named(self.path.as_deref(), &self.source)
    }
}

/// The file a measurement was read from, or its name (shown escaped: it may hold terminal
/// escapes), for its errors.
fn named(path: Option<&Path>, source: &str) -> PathBuf {
    path.map_or_else(
        || PathBuf::from(source.escape_debug().to_string()),
        Path::to_path_buf,
    )
}

impl Scene {
    /// Gives every MERL-grid measurement loaded without a fit the one `fit` makes of its source
    /// (`fit(source, brdf)`, e.g. facet-fit's `fit_material` with `FitConfig::SINGLE_LAYER`),
    /// once per source however many materials name it. The renderer never fits: this is the
    /// caller's step, to be shown with its time. Returns how many sources were fitted.
    pub fn fit_measured<E: Display>(
        &mut self,
        mut fit: impl FnMut(&str, &dyn Brdf) -> Result<FittedMaterial, E>,
    ) -> Result<usize, RenderError> {
        let mut done: HashMap<*const (), Arc<FittedMaterial>> = HashMap::new();
        for m in self
            .materials
            .iter_mut()
            .filter_map(|m| m.measured.as_mut())
        {
            let Some(src) = m.unfitted.take() else {
                continue;
            };
            let key = Arc::as_ptr(&src) as *const ();
            let f = match done.get(&key) {
                Some(f) => f.clone(),
                None => {
                    let f = fit(&m.source, &*src).map_err(|e| {
                        RenderError::input(m.named(), format!("fitting its sampling NDF: {e}"))
                    })?;
                    let f = Arc::new(f);
                    done.insert(key, f.clone());
                    f
                }
            };
            m.fit = Some(f);
        }
        Ok(done.len())
    }

    /// The sources of the MERL-grid measurements still without a fit (what
    /// [`fit_measured`](Self::fit_measured) would fit), each once.
    pub fn unfitted_measurements(&self) -> Vec<&str> {
        let mut seen = Vec::<*const ()>::new();
        let mut names = Vec::new();
        for m in self.materials.iter().filter_map(|m| m.measured.as_ref()) {
            if let Some(src) = &m.unfitted {
                let key = Arc::as_ptr(src) as *const ();
                if !seen.contains(&key) {
                    seen.push(key);
                    names.push(m.source.as_str());
                }
            }
        }
        names
    }
}
