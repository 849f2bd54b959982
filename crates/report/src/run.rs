//! A whole report: each input opened, fitted, rendered and compared in turn (an input that
//! fails is told to the caller and skipped), the N sweep of the first inputs reported, then the
//! database's mean ΔE images, the plots and `index.html`.

use crate::config::ReportConfig;
use crate::error::{ReportError, Result};
use crate::material::{MaterialReport, report_material};
use crate::progress::Progress;
use crate::scenes::{self, Lighting, SphereRenderer};
use crate::sky::Sky;
use crate::sweep::{self, SweepPoint};
use crate::{delta_e, false_colour, html, plots, subject};
use facet_fit::FitConfig;
use facet_fit::fitting::CoatSearch;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_gpu::Gpu;
use std::collections::HashSet;
use std::path::Path;
use std::time::Instant;

/// What a report made.
pub struct Outcome {
    /// The materials reported, in the inputs' order.
    pub materials: Vec<MaterialReport>,
    /// The points of the N sweep.
    pub sweep: Vec<SweepPoint>,
    /// How many inputs could not be reported.
    pub failed: usize,
    /// The path of the page written.
    pub index: std::path::PathBuf,
}

/// Reports `inputs` (what `facet fit` takes, or fit JSONs) into the folder `out` and its
/// [`IMG`](crate::IMG) subfolder, which must exist: the spheres rendered on `gpu` under `sky`, the fits
/// made with `config`, the page's run time counted from `started`. Each material's failure is
/// told through `progress` and the others go on; when none is reported, no page is written
/// ([`ReportError::NothingReported`]).
pub fn report(
    gpu: &Gpu,
    inputs: &[String],
    out: &Path,
    sky: &Sky,
    config: &ReportConfig,
    started: Instant,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome> {
    let mut renderer = SphereRenderer::new(gpu, config.side, config.env_spp, sky);
    let cfg = config.fit_config();
    let mut library = None;
    progress(Progress::Start { len: inputs.len() });
    let (mut materials, mut stems, mut failed) = (Vec::new(), HashSet::new(), 0);
    for input in inputs {
        progress(Progress::Step(input));
        let done = subject::open(input, &cfg, &mut library).and_then(|s| {
            let stem = unique_stem(&s.fit.record.name, &mut stems);
            report_material(&mut renderer, &s, &stem, out)
        });
        match done {
            Ok(r) => materials.push(r),
            // The readers' and the steps' errors name the input; the others still go on.
            Err(e) => {
                failed += 1;
                progress(Progress::Failed(e));
            }
        }
        progress(Progress::Done);
    }
    progress(Progress::Finish);
    if materials.is_empty() {
        return Err(ReportError::NothingReported { failed });
    }
    // The sweep fits again only inputs that were reported.
    let reported: Vec<String> = materials.iter().map(|r| r.input.clone()).collect();
    // The sweep times the single layer's fit against N: no coat is searched.
    let single = FitConfig {
        coat: CoatSearch::Off,
        ..cfg
    };
    let sweep = run_sweep(&reported, config.sweep, &single, &mut library, progress)?;
    let info = html::PageInfo {
        adapter: gpu.describe(),
        side: config.side,
        env_spp: config.env_spp,
        resolution: config.fit_resolution,
        coat: config.coat_words(),
        env: sky.name.clone(),
        seconds: 0.0,
        version: env!("CARGO_PKG_VERSION"),
    };
    let index = write_page(out, info, &materials, &sweep, started)?;
    Ok(Outcome {
        materials,
        sweep,
        failed,
        index,
    })
}

/// A file stem for `name`, unique among `taken` (-2, -3, ... on a repeat).
fn unique_stem(name: &str, taken: &mut HashSet<String>) -> String {
    let base = facet_fit::io::input::safe_file_stem(name);
    let mut stem = base.clone();
    for k in 2.. {
        if taken.insert(stem.clone()) {
            break;
        }
        stem = format!("{base}-{k}");
    }
    stem
}

/// The N sweep of the first `k` inputs, a stage of its own for `progress`.
fn run_sweep(
    inputs: &[String],
    k: usize,
    cfg: &FitConfig,
    library: &mut Option<NbrdfLibrary>,
    progress: &mut dyn FnMut(Progress),
) -> Result<Vec<SweepPoint>> {
    let chosen = &inputs[..k.min(inputs.len())];
    progress(Progress::Start { len: chosen.len() });
    let mut points = Vec::new();
    for input in chosen {
        progress(Progress::Step(&format!("N sweep: {input}")));
        points.extend(sweep::sweep_input(input, cfg, library)?);
        progress(Progress::Done);
    }
    progress(Progress::Finish);
    Ok(points)
}

/// The database's mean ΔE images, the scale, the sweep plot and index.html (its path), the run
/// time in `info` taken from `started` now.
fn write_page(
    out: &Path,
    info: html::PageInfo,
    reports: &[MaterialReport],
    sweep: &[SweepPoint],
    started: Instant,
) -> Result<std::path::PathBuf> {
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        for k in 0..scenes::N_MODELS {
            let images: Vec<_> = reports.iter().filter_map(|r| r.de[l][k].as_ref()).collect();
            if let Some(mean) = delta_e::DeltaE::mean_of(&images) {
                false_colour::write_png(&mean, &out.join(html::mean_de_file(*lighting, k)))?;
            }
        }
    }
    plots::write_scale(&out.join(plots::SCALE_FILE))?;
    if !sweep.is_empty() {
        plots::write_sweep_plot(sweep, &out.join(plots::SWEEP_FILE))?;
    }
    let info = html::PageInfo {
        seconds: started.elapsed().as_secs_f64(),
        ..info
    };
    let page = html::page(&info, reports, sweep);
    let index = out.join("index.html");
    std::fs::write(&index, page).map_err(ReportError::write(&index))?;
    Ok(index)
}

/// The mean ΔE2000 and ΔE_ITP per model over the set and the noise floor's mean and median,
/// one line each, per lighting.
pub fn means_lines(reports: &[MaterialReport]) -> Vec<String> {
    let means = html::set_means(reports);
    let mut lines = Vec::new();
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        for (d, name) in ["ΔE", "ΔE_ITP"].iter().enumerate() {
            let v: Vec<String> = scenes::Variant::MODELS
                .iter()
                .zip(means[l])
                .map(|(m, v)| {
                    let v = v.map(|v| v.both()[d]);
                    format!(
                        "{} {}",
                        m.key(),
                        v.map_or("–".into(), |v| format!("{v:.3}"))
                    )
                })
                .collect();
            lines.push(format!(
                "mean {name} ({}): {}",
                lighting.key(),
                v.join(", ")
            ));
        }
    }
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        let floors = html::floor_stats(reports)[l];
        lines.push(format!(
            "noise floor ({}): ΔE mean {:.3} median {:.3}, ΔE_ITP mean {:.3} median {:.3}",
            lighting.key(),
            floors[0].0,
            floors[0].1,
            floors[1].0,
            floors[1].1
        ));
    }
    lines
}
