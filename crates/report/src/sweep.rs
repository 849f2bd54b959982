//! Run time against error: the same fit at N = 32, 64, 90 and 128 polar nodes (the power
//! iteration's quadrature), each timed and its three models' errors recorded. The source is
//! tabulated on the MERL grid once first, so that the times are the fit's, not a neural
//! proxy's evaluation (about a second, the same at every N).

use crate::error::{ReportError, Result};
use facet_fit::FitConfig;
use facet_fit::model::metric::Metric;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::{InputSpec, Residence};
use std::time::Instant;

/// The resolutions of the sweep.
pub const RESOLUTIONS: [usize; 4] = [32, 64, 90, 128];

/// One fit of the sweep.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// The material's input as given.
    pub material: String,
    /// N.
    pub resolution: usize,
    /// Wall time of the fit of the tabulated source, seconds.
    pub seconds: f64,
    /// The power iteration's share of it (the extraction and its tables), seconds.
    pub extract_seconds: f64,
    /// The metric the fit minimised, the errors' metric.
    pub metric: Metric,
    /// The error of the tabulated, GGX and Beckmann models.
    pub errors: [Option<f64>; 3],
}

/// The sweep of one input (not a fit JSON, which has no source to fit, nor an anisotropic
/// source, which has no MERL table: they give no points).
pub fn sweep_input(
    input: &str,
    cfg: &FitConfig,
    library: &mut Option<NbrdfLibrary>,
) -> Result<Vec<SweepPoint>> {
    let spec = InputSpec::parse(input);
    if matches!(spec, InputSpec::Fit(_)) {
        return Ok(Vec::new());
    }
    let src = spec.open(None, library, Residence::Read)?;
    if !src.is_isotropic() {
        return Ok(Vec::new());
    }
    let table = MerlBrdf::from_table(src.name(), src.merl_table().into_owned())
        .map_err(|e| ReportError::Other(format!("{input}: {e}")))?;
    let mut points = Vec::new();
    for n in RESOLUTIONS {
        let mut cfg = *cfg;
        cfg.extract.resolution = n;
        let t = Instant::now();
        let fit = facet_fit::fit_material(&table, input, &cfg).map_err(|source| {
            ReportError::Fitting {
                input: input.to_owned(),
                n: Some(n),
                source,
            }
        })?;
        let r = &fit.record;
        points.push(SweepPoint {
            material: input.to_owned(),
            resolution: n,
            seconds: t.elapsed().as_secs_f64(),
            extract_seconds: r.timings_ms.extract / 1e3,
            metric: r.metric,
            errors: [
                r.tabulated.error,
                r.ggx.as_ref().map(|p| p.error),
                r.beckmann.as_ref().map(|p| p.error),
            ],
        });
    }
    Ok(points)
}
