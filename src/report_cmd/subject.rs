//! One input of the report, opened and fitted: a measurement (everything `facet fit` takes) is
//! fitted here; a fit JSON is read, and has no measurement to render.

use anyhow::{Context, Result};
use facet_fit::FitConfig;
use facet_fit::model::material::FittedMaterial;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::{InputSpec, Residence};
use std::sync::Arc;
use std::time::Instant;

/// A material of the report.
pub struct Subject {
    /// The input as given.
    pub input: String,
    /// The fit (made here, or read from the JSON).
    pub fit: Arc<FittedMaterial>,
    /// Whether there is a measurement to render and compare against (false for a fit JSON:
    /// its models are compared with its tabulated model).
    pub measured: bool,
    /// Wall time of the fit made here (opening the source included), ms; a fit JSON's
    /// recorded total.
    pub fit_ms: f64,
}

/// Opens `input` and fits it with `cfg` (a fit JSON is read instead).
pub fn open(input: &str, cfg: &FitConfig, library: &mut Option<NbrdfLibrary>) -> Result<Subject> {
    let spec = InputSpec::parse(input);
    if let InputSpec::Fit(path) = &spec {
        let fit = FittedMaterial::load(path).with_context(|| input.to_owned())?;
        let fit_ms = fit.record.timings_ms.total;
        return Ok(Subject {
            input: input.to_owned(),
            fit: Arc::new(fit),
            measured: false,
            fit_ms,
        });
    }
    let t = Instant::now();
    let fit = fit_input(&spec, input, cfg, library)?;
    Ok(Subject {
        input: input.to_owned(),
        fit: Arc::new(fit),
        measured: true,
        fit_ms: t.elapsed().as_secs_f64() * 1e3,
    })
}

/// The fit of the source `spec` (`input` as given) with `cfg`.
pub fn fit_input(
    spec: &InputSpec,
    input: &str,
    cfg: &FitConfig,
    library: &mut Option<NbrdfLibrary>,
) -> Result<FittedMaterial> {
    let src = spec
        .open(None, library, Residence::Read)
        .with_context(|| input.to_owned())?;
    facet_fit::fit_material(&*src, input, cfg).with_context(|| format!("fitting {input}"))
}
