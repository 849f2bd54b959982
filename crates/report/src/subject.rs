//! One input of the report, opened and fitted: a measurement (everything `facet fit` takes) is
//! tabulated and fitted here; a fit JSON is read, and has no measurement to render.

use crate::error::{ReportError, Result};
use facet_fit::Brdf;
use facet_fit::FitConfig;
use facet_fit::model::material::FittedMaterial;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::{InputSpec, Residence};
use facet_render::scene::Measurement;
use std::sync::Arc;
use std::time::Instant;

/// A material of the report.
pub struct Subject {
    /// The input as given.
    pub input: String,
    /// The fit (made here, or read from the JSON).
    pub fit: Arc<FittedMaterial>,
    /// The measurement to render and compare against (`None` for a fit JSON, whose models are
    /// compared with its tabulated model, and for an anisotropic source).
    pub measurement: Option<Arc<Measurement>>,
    /// Wall time of the fit made here (opening and tabulating the source excluded), ms; a fit
    /// JSON's recorded total.
    pub fit_ms: f64,
}

/// Opens `input` and fits it with `cfg` (a fit JSON is read instead). An isotropic source is
/// tabulated on the MERL grid once: the fit is made from that table and the table, filled, is
/// the measurement rendered, so that a neural proxy is evaluated once, not twice. An RGL file
/// is fitted and rendered as itself; an anisotropic source has no table and is not rendered.
pub fn open(input: &str, cfg: &FitConfig, library: &mut Option<NbrdfLibrary>) -> Result<Subject> {
    let spec = InputSpec::parse(input);
    if let InputSpec::Fit(path) = &spec {
        let fit = FittedMaterial::load(path)?;
        let fit_ms = fit.record.timings_ms.total;
        return Ok(Subject {
            input: input.to_owned(),
            fit: Arc::new(fit),
            measurement: None,
            fit_ms,
        });
    }
    let src = spec.open(None, library, Residence::Read)?;
    let fitted = |src: &dyn Brdf| -> Result<(FittedMaterial, f64)> {
        let t = Instant::now();
        let fit =
            facet_fit::fit_material(src, input, cfg).map_err(|source| ReportError::Fitting {
                input: input.to_owned(),
                n: None,
                source,
            })?;
        Ok((fit, t.elapsed().as_secs_f64() * 1e3))
    };
    let ((fit, fit_ms), measurement) = if matches!(spec, InputSpec::Rgl(_)) || !src.is_isotropic() {
        (fitted(&*src)?, Measurement::of(&spec, &*src).ok())
    } else {
        let table = src.merl_table().into_owned();
        let tabulated = MerlBrdf::from_table(src.name(), table.clone())
            .map_err(|e| ReportError::Other(format!("{input}: {e}")))?;
        (fitted(&tabulated)?, Some(Measurement::Merl(table.filled())))
    };
    Ok(Subject {
        input: input.to_owned(),
        fit: Arc::new(fit),
        measurement: measurement.map(Arc::new),
        fit_ms,
    })
}
