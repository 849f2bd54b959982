//! Measured materials: a surface whose BRDF is the measurement itself, not a model fitted to
//! it.
//!
//! - **MERL-grid tables** — a MERL `.binary`, `nbrdf:NAME`, or anything else
//!   [`InputSpec`] opens (an `analytic:` spec, a fit JSON) sampled onto the MERL grid — are
//!   evaluated by trilinear interpolation in MERL's (√θh, θd, φd) coordinates on the table's
//!   [`filled`](MerlTable::filled) samples, and importance-sampled by the visible normals of a
//!   fit's tabulated NDF: the fit named beside the measurement, or one made from it on load
//!   (Dupuy & Jakob 2018 sample their measurements the same way).
//! - **RGL `.bsdf` files** are evaluated and sampled by their own stored warps, as Mitsuba 3's
//!   `measured` plugin does; they need no fit.

use crate::error::RenderError;

use facet_fit::model::material::FittedMaterial;
use facet_fit::model::merl_grid::{MAX_X, MerlTable, bin_of};
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::rgl::RglBsdf;
use facet_fit::sources::{InputSpec, Residence};
use facet_fit::{Brdf, FitConfig};
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
#[derive(Clone, Debug)]
pub struct MeasuredMaterial {
    /// The measurement as named: a path, or `nbrdf:NAME` / `analytic:SPEC`.
    pub source: String,
    /// The file it was read from (`None` for the embedded proxies and analytic specs).
    pub path: Option<PathBuf>,
    /// The data, shared by every material that names the same source.
    pub data: Arc<Measurement>,
    /// The fit whose tabulated NDF samples a MERL-grid table (`None` for a `.bsdf`, which
    /// samples by its own warps).
    pub fit: Option<Arc<FittedMaterial>>,
}

impl MeasuredMaterial {
    /// Opens the measurement `source` (a path relative to `base`, or `nbrdf:NAME` from
    /// `nbrdf`, else `$FACET_NBRDF`, else the embedded proxies) and, for a MERL-grid table
    /// without a `fit`, fits it ([`FitConfig::SINGLE_LAYER`]). A `fit` given with a `.bsdf` is
    /// not needed and not kept.
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
        // A name (not a file) is shown escaped: it may hold terminal escapes.
        let named =
            (path.clone()).unwrap_or_else(|| PathBuf::from(source.escape_debug().to_string()));
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
            });
        }
        let mut library: Option<NbrdfLibrary> = None;
        let src = spec
            .open(nbrdf, &mut library, Residence::Read)
            .map_err(|e| fail(&e))?;
        let data = Measurement::of(&spec, &*src).map_err(|e| fail(&e))?;
        let fit = match fit {
            Some(f) => f,
            // The fit only samples the measurement: no coat is searched.
            None => Arc::new(
                facet_fit::fit_material(&*src, source, &FitConfig::SINGLE_LAYER)
                    .map_err(|e| fail(&format!("fitting its sampling NDF: {e}")))?,
            ),
        };
        Ok(MeasuredMaterial {
            source: source.to_owned(),
            path,
            data: Arc::new(data),
            fit: Some(fit),
        })
    }
}
