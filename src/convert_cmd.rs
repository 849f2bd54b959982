//! `facet convert IN OUT`: a material from one format to another, chosen by OUT's extension.

use anyhow::{Context, Result, bail};
use clap::Args;
use facet_fit::export::rgl::{BsdfResolution, write_rgl};
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::io::input::same_file;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::rgl::RglBsdf;
use facet_fit::sources::{InputSpec, Residence};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Args)]
pub struct ConvertArgs {
    /// The material: a MERL .binary, an RGL .bsdf, a fit .json (its tabulated model, under its
    /// coat when it kept one), `nbrdf:NAME` or `analytic:SPEC`.
    pub input: String,
    /// Where to write it, by extension: `.binary` (MERL, sampled at the bins), `.bsdf` (RGL,
    /// RGB, isotropic materials), `.json` (a fit of the input, as `facet fit` writes).
    pub output: PathBuf,
    /// Replace OUT when it exists (default: refuse).
    #[arg(long)]
    pub force: bool,
    /// The .bsdf grids: θi slices, the sample space's side and the VNDF's side, each 2 to
    /// 1024 (default 24 64 64: 1.9 MiB).
    #[arg(long, num_args = 3, value_names = ["THETA_I", "SAMPLE", "VNDF"])]
    pub bsdf_resolution: Option<Vec<usize>>,
    /// Neural proxy file for `nbrdf:` inputs (default: `$FACET_NBRDF`, else the embedded
    /// MERL-100 proxies).
    #[arg(long)]
    pub nbrdf: Option<PathBuf>,
}

/// The formats `facet convert` writes.
enum Target {
    Merl,
    Bsdf,
    Fit,
}

fn target(path: &Path) -> Result<Target> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("binary") => Ok(Target::Merl),
        Some("bsdf") => Ok(Target::Bsdf),
        Some("json") => Ok(Target::Fit),
        _ => bail!(
            "{}: the output's extension says its format: .binary (MERL), .bsdf (RGL) or .json (a fit)",
            path.display()
        ),
    }
}

pub fn run(args: &ConvertArgs) -> Result<ExitCode> {
    let out = &args.output;
    let kind = target(out)?;
    let input_path = Path::new(&args.input);
    if !args.input.contains(':') && same_file(input_path, out) {
        bail!("{}: the output would replace the input", out.display());
    }
    if out.exists() && !args.force {
        bail!("{}: exists; pass --force to replace it", out.display());
    }
    if out.is_dir() {
        bail!("{}: is a folder", out.display());
    }
    let res = match &args.bsdf_resolution {
        None => BsdfResolution::standard(),
        Some(v) => {
            let r = BsdfResolution {
                theta_i: v[0],
                sample: v[1],
                vndf: v[2],
                ..BsdfResolution::standard()
            };
            r.validate()
                .map_err(|e| anyhow::anyhow!("--bsdf-resolution: {e}"))?;
            r
        }
    };
    let t = Instant::now();
    let mut library: Option<NbrdfLibrary> = None;
    let src = InputSpec::parse(&args.input).open(
        args.nbrdf.as_deref(),
        &mut library,
        Residence::Mapped,
    )?;
    let load_ms = t.elapsed().as_secs_f64() * 1e3;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::output::folder(dir, "OUT's folder")?;
    }
    let t = Instant::now();
    match kind {
        Target::Merl => {
            let table = src.merl_table();
            table.write(out)?;
            println!(
                "{}: MERL table of {} ({} of {} bins missing), {:.0} ms",
                out.display(),
                args.input,
                table.missing_count(),
                facet_fit::model::merl_grid::SAMPLES,
                load_ms + t.elapsed().as_secs_f64() * 1e3
            );
        }
        Target::Bsdf => {
            let description = format!(
                "{} written by facet {} from {}",
                src.name(),
                env!("CARGO_PKG_VERSION"),
                args.input
            );
            let written = write_rgl(out, src.as_ref(), res, &description)?;
            let write_ms = t.elapsed().as_secs_f64() * 1e3;
            // What landed on disk reads back.
            RglBsdf::open(out)?;
            println!(
                "{}: RGL .bsdf ({} × {}² samples, {:.2} MiB, sample space: {} NDF) in \
                 {write_ms:.0} ms; its error against {} on the MERL grid: {:.5}{}",
                out.display(),
                res.theta_i,
                res.sample,
                written.bytes as f64 / (1 << 20) as f64,
                written.sample_space,
                args.input,
                written.error,
                if written.missing > 0 {
                    format!(
                        " ({} nodes without a source value, written as 0)",
                        written.missing
                    )
                } else {
                    String::new()
                }
            );
        }
        Target::Fit => {
            let fit = fit_material(src.as_ref(), &args.input, &FitConfig::isotropic())
                .with_context(|| args.input.clone())?;
            fit.save(out)?;
            let r = &fit.record;
            println!(
                "{}: fit of {} (tabulated error {:.5}), {:.0} ms",
                out.display(),
                args.input,
                r.tabulated.error.unwrap_or(f64::NAN),
                t.elapsed().as_secs_f64() * 1e3
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
