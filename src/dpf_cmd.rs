//! `facet dpf`: one DPF query from the tables, or the nine levels written as EXR slices.

use crate::fit_cmd::BackendArg;
use anyhow::{Context, Result, bail};
use clap::Args;
use facet_fit::extract::{ExtractConfig, extract_isotropic};
use facet_fit::model::material::FittedMaterial;
use facet_fit::model::microfacet::Ndf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::{InputSpec, Residence};
use facet_glint::dpf::{DpfConfig, DpfPyramid, LEVELS_DEG, dpf, query_directions};
use facet_gpu::Gpu;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct DpfArgs {
    /// The NDF: `analytic:beckmann?alpha=0.1`, a fit .json (its tabulated NDF), or any input of
    /// `facet fit` (its NDF is extracted first).
    #[arg(long)]
    ndf: String,
    /// Cone half-angle γ in degrees, (0, 90].
    #[arg(long, value_parser = crate::args::degrees)]
    gamma: Option<f64>,
    /// Polar angle of ωo in degrees, [0, 90].
    #[arg(long, value_parser = crate::args::degrees)]
    theta_o: Option<f64>,
    /// Polar angle of ωi in degrees, [0, 90].
    #[arg(long, value_parser = crate::args::degrees)]
    theta_i: Option<f64>,
    /// φo − φi in degrees, -360 to 360; 180 is the mirror configuration.
    #[arg(long, value_parser = crate::args::degrees)]
    dphi: Option<f64>,
    /// Where the tables are built: auto (any adapter, else the CPU), gpu, or cpu (no adapter is
    /// touched).
    #[arg(long, value_enum, default_value = "auto")]
    backend: BackendArg,
    /// Print the query's result as JSON.
    #[arg(long)]
    json: bool,
    /// Write the nine levels as EXR slices into DIR (one file per level: θo slices side by
    /// side, each Δφ across and θi down).
    #[arg(long)]
    write: Option<PathBuf>,
    /// Table cells: preview (12×12×24) or standard (32×32×64).
    #[arg(long, default_value = "standard")]
    resolution: String,
    /// Neural proxy file for `nbrdf:` inputs (default: `$FACET_NBRDF`, else the embedded ones).
    #[arg(long)]
    nbrdf: Option<PathBuf>,
}

fn ndf_of(spec: &str, nbrdf: &Option<PathBuf>) -> Result<Ndf> {
    let input = InputSpec::parse(spec);
    match &input {
        InputSpec::Analytic(rest) => Ok(facet_fit::model::analytic::parse_analytic(rest)?.ndf),
        InputSpec::Fit(path) => Ok(FittedMaterial::load(path)?.tabulated.ndf),
        _ => {
            let path = NbrdfLibrary::override_path(nbrdf.as_deref());
            let src = input.open(path.as_deref(), &mut None, Residence::Mapped)?;
            let ex = extract_isotropic(src.as_ref(), &ExtractConfig::isotropic())?;
            Ok(Ndf::Tabulated(Arc::new(ex.ndf)))
        }
    }
}

/// Builds the listed levels on the GPU (`auto`: when there is one, else on the CPU).
fn build(
    ndf: &Ndf,
    cfg: DpfConfig,
    which: &[usize],
    backend: BackendArg,
) -> Result<(DpfPyramid, String)> {
    if backend != BackendArg::Cpu {
        match Gpu::new() {
            Ok(gpu) => match facet_glint::gpu::build_levels(&gpu, ndf, cfg, which) {
                Ok(g) => return Ok((g.pyramid, gpu.describe())),
                Err(e) if backend == BackendArg::Auto => {
                    eprintln!("notice: GPU build failed ({e}); building on the CPU")
                }
                Err(e) => return Err(e).context("--backend gpu"),
            },
            Err(e) if backend == BackendArg::Auto => {
                eprintln!("notice: {e}; building on the CPU")
            }
            Err(e) => return Err(e).context("--backend gpu"),
        }
    }
    Ok((DpfPyramid::build_levels(ndf, cfg, which), "cpu".into()))
}

pub fn run(args: &DpfArgs) -> Result<ExitCode> {
    let cfg = match args.resolution.as_str() {
        "preview" => DpfConfig::preview(),
        "standard" => DpfConfig::standard(),
        other => bail!("--resolution {other}: use preview or standard"),
    };
    let ndf = ndf_of(&args.ndf, &args.nbrdf).with_context(|| format!("--ndf {}", args.ndf))?;
    if let Some(dir) = &args.write {
        let t = std::time::Instant::now();
        let (pyramid, backend) = build(&ndf, cfg, &[0, 1, 2, 3, 4, 5, 6, 7, 8], args.backend)?;
        crate::output::folder(dir, "--write")?;
        for table in pyramid.levels.iter().flatten() {
            let path = dir.join(format!(
                "dpf-gamma{:02}.exr",
                table.gamma.to_degrees().round() as u32
            ));
            write_level(&path, table)?;
        }
        println!(
            "wrote {} levels ({}×{}×{} cells each) to {} in {:.1} s on {backend}",
            LEVELS_DEG.len(),
            cfg.n_theta,
            cfg.n_theta,
            cfg.n_dphi,
            dir.display(),
            t.elapsed().as_secs_f64()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let (Some(g), Some(to), Some(ti), Some(dp)) =
        (args.gamma, args.theta_o, args.theta_i, args.dphi)
    else {
        bail!(
            "give --gamma, --theta-o, --theta-i and --dphi (degrees) for a query, or --write DIR"
        );
    };
    let in_range = (0.0..=90.0).contains(&to)
        && (0.0..=90.0).contains(&ti)
        && g > 0.0
        && g <= 90.0
        && dp.is_finite();
    if !in_range {
        bail!("angles out of range: θo, θi in [0, 90], γ in (0, 90], Δφ finite");
    }
    let (levels, _) = DpfPyramid::levels_for(g.to_radians());
    let (pyramid, backend) = build(&ndf, cfg, &levels, args.backend)?;
    let p_table = pyramid.lookup(
        to.to_radians(),
        ti.to_radians(),
        dp.to_radians(),
        g.to_radians(),
    );
    let (wi, wo) = query_directions(to.to_radians(), ti.to_radians(), dp.to_radians());
    let p_direct = dpf(&ndf, wi, wo, g.to_radians());
    if args.json {
        let v = serde_json::json!({
            "ndf": args.ndf, "gamma_deg": g, "theta_o_deg": to, "theta_i_deg": ti, "dphi_deg": dp,
            "p": p_table, "p_direct": p_direct, "levels_deg": levels.map(|k| LEVELS_DEG[k]),
            "cells": [cfg.n_theta, cfg.n_theta, cfg.n_dphi], "backend": backend,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!(
            "P(θo = {to}°, θi = {ti}°, Δφ = {dp}°, γ = {g}°) = {p_table:.6e} from the tables ({backend}); {p_direct:.6e} by direct integration"
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// One level as a float EXR: θo slices side by side, Δφ across and θi down, P in R, G and B.
fn write_level(path: &Path, t: &facet_glint::dpf::DpfTable) -> Result<()> {
    let (nt, np) = (t.config.n_theta, t.config.n_dphi);
    let (w, h) = (nt * np, nt);
    exr::prelude::write_rgb_file(path, w, h, |x, y| {
        let (o, p) = (x / np, x % np);
        let v = t.values[(o * nt + y) * np + p];
        (v, v, v)
    })
    .with_context(|| format!("writing {}", path.display()))
}
