//! Run time against error: the same fit at N = 32, 64, 90 and 128 polar nodes (the power
//! iteration's quadrature), each timed and its three models' errors recorded.

use super::subject::fit_input;
use anyhow::Result;
use facet_fit::FitConfig;
use facet_fit::sources::InputSpec;
use facet_fit::sources::nbrdf::NbrdfLibrary;
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
    /// Wall time of the fit (opening the source excluded), seconds.
    pub seconds: f64,
    /// The error metric of the tabulated, GGX and Beckmann models.
    pub errors: [Option<f64>; 3],
}

/// The sweep of one input (not a fit JSON, which has no source to fit: it gives no points).
pub fn sweep_input(
    input: &str,
    cfg: &FitConfig,
    library: &mut Option<NbrdfLibrary>,
) -> Result<Vec<SweepPoint>> {
    let spec = InputSpec::parse(input);
    if matches!(spec, InputSpec::Fit(_)) {
        return Ok(Vec::new());
    }
    let mut points = Vec::new();
    for n in RESOLUTIONS {
        let mut cfg = *cfg;
        cfg.extract.resolution = n;
        let t = Instant::now();
        let fit = fit_input(&spec, input, &cfg, library)?;
        let r = &fit.record;
        points.push(SweepPoint {
            material: input.to_owned(),
            resolution: n,
            seconds: t.elapsed().as_secs_f64(),
            errors: [
                r.tabulated.error,
                r.ggx.as_ref().map(|p| p.error),
                r.beckmann.as_ref().map(|p| p.error),
            ],
        });
    }
    Ok(points)
}
