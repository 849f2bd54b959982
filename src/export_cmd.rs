//! `facet export`: a fit's analytic model as a Mitsuba 3 `<bsdf>`, a pbrt-v4 material or a
//! glTF 2.0 material, with what it approximates written inside.

use anyhow::{Result, bail};
use clap::{Args, ValueEnum};
use facet_fit::export::{ExportOptions, KindRequest, ModelRequest, Target, export};
use facet_fit::io::input::same_file;
use facet_fit::model::material::FittedMaterial;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TargetArg {
    /// Mitsuba 3 XML: a `roughconductor` or `roughplastic` `<bsdf>` (`mi.load_file`, `<include>`);
    /// a coated fit as a `measured` `<bsdf>` and the coated model tabulated in NAME.coated.bsdf
    /// beside it.
    Mitsuba,
    /// pbrt-v4: a `conductor` or `coateddiffuse` MakeNamedMaterial (Include it, then
    /// NamedMaterial).
    Pbrt,
    /// glTF 2.0 (.gltf): one metallic-roughness material, with KHR_materials_ior, _specular and
    /// _anisotropy where they apply.
    Gltf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// The GGX fit.
    Ggx,
    /// The Beckmann fit (Mitsuba only; pbrt and glTF have only GGX and take the GGX fit).
    Beckmann,
    /// The fit of lower error among those the target has.
    Best,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum KindArg {
    /// A conductor when the fit's mean Schlick F0 is at least 0.2, or when ρd ≤ 0.01 and the
    /// conductor Fresnel's error is below 0.9 × the dielectric's (a coloured F); else a plastic.
    Auto,
    /// A conductor: η, k per channel (glTF: metallic, F0 as base colour); ρd is dropped.
    Conductor,
    /// A diffuse base ρd under a dielectric interface of the fitted η.
    Plastic,
}

#[derive(Args)]
pub struct ExportArgs {
    /// A fit JSON written by `facet fit`.
    pub fit: PathBuf,
    /// The renderer to write for.
    #[arg(long, value_enum)]
    pub to: TargetArg,
    /// The output file (default: the fit's file name with .xml, .pbrt or .gltf, in the current
    /// folder). An existing file is kept unless --force.
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// Which analytic fit to export.
    #[arg(long, value_enum, default_value = "ggx")]
    pub model: ModelArg,
    /// Export as a conductor or a plastic.
    #[arg(long, value_enum, default_value = "auto")]
    pub kind: KindArg,
    /// Replace the output file when it exists (never the fit itself).
    #[arg(long)]
    pub force: bool,
    /// Export the single layer of a fit that kept a clear coat (default: the coat over its
    /// base; for Mitsuba, tabulated).
    #[arg(long)]
    pub no_coat: bool,
}

impl ExportArgs {
    fn options(&self) -> ExportOptions {
        ExportOptions {
            target: match self.to {
                TargetArg::Mitsuba => Target::Mitsuba,
                TargetArg::Pbrt => Target::Pbrt,
                TargetArg::Gltf => Target::Gltf,
            },
            model: match self.model {
                ModelArg::Ggx => ModelRequest::Ggx,
                ModelArg::Beckmann => ModelRequest::Beckmann,
                ModelArg::Best => ModelRequest::Best,
            },
            kind: match self.kind {
                KindArg::Auto => KindRequest::Auto,
                KindArg::Conductor => KindRequest::Conductor,
                KindArg::Plastic => KindRequest::Plastic,
            },
            coat: !self.no_coat,
        }
    }
}

/// `--out`, or the fit's file stem with the target's extension in the current folder.
pub fn output_path(fit: &Path, out: Option<&Path>, target: Target) -> PathBuf {
    match out {
        Some(o) => o.to_owned(),
        None => {
            let stem = fit
                .file_stem()
                .map(|s| facet_fit::io::input::safe_file_stem(&s.to_string_lossy()))
                .unwrap_or_else(|| "material".into());
            PathBuf::from(format!("{stem}.{}", target.extension()))
        }
    }
}

pub fn run(args: &ExportArgs) -> Result<ExitCode> {
    let options = args.options();
    let out = output_path(&args.fit, args.out.as_deref(), options.target);
    let fit = FittedMaterial::load(&args.fit)?;
    if same_file(&args.fit, &out) {
        bail!(
            "{}: the output would replace the fit it is exported from; choose another --out",
            out.display()
        );
    }
    if out.is_dir() {
        bail!("--out {}: is a folder, not a file", out.display());
    }
    if out.exists() && !args.force {
        bail!(
            "{}: exists; --force replaces it, or choose another --out",
            out.display()
        );
    }
    let exported = export(&fit, &args.fit, &options)?;
    let table = exported
        .table
        .as_ref()
        .map(|t| (out.with_file_name(&t.name), t))
        .map(|(path, t)| check_table_path(&path, &out, args).map(|()| (path, t)))
        .transpose()?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::output::folder(dir, "--out")?;
    }
    // The table first: the file that names it is written only once it is there. A table made
    // here is taken back if the file that names it cannot be written.
    let made = table.as_ref().filter(|(path, _)| !path.exists());
    if let Some((path, t)) = &table {
        write(path, &t.bytes)?;
    }
    if let Err(e) = write(&out, exported.text.as_bytes()) {
        if let Some((path, _)) = made {
            let _ = std::fs::remove_file(path);
        }
        return Err(e);
    }
    println!("{}", exported.report.summary());
    match &table {
        Some((path, _)) => println!("wrote {} and {}", out.display(), path.display()),
        None => println!("wrote {}", out.display()),
    }
    Ok(ExitCode::SUCCESS)
}

/// The table a coated Mitsuba export names, at `path` beside the output: never the fit, an
/// existing file only with --force.
fn check_table_path(path: &Path, out: &Path, args: &ExportArgs) -> Result<()> {
    if path == out {
        bail!(
            "--out {}: is the name of the coat's table the export writes beside it; choose another --out",
            out.display()
        );
    }
    if same_file(&args.fit, path) {
        bail!(
            "{}: the coat's table would replace the fit it is exported from; export it from another folder or with another --out",
            path.display()
        );
    }
    if path.is_dir() {
        bail!("{}: the coat's table's name is a folder", path.display());
    }
    if path.exists() && !args.force {
        bail!(
            "{}: exists (the coat's table named by the export); --force replaces it",
            path.display()
        );
    }
    Ok(())
}

/// `bytes` at `path` through a temporary file renamed into place, as `facet fit` writes its
/// JSON.
fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    facet_fit::io::output::write_bytes_atomically(path, bytes).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot write: {}",
            path.display(),
            facet_fit::io::input::io_problem(&e)
        )
    })
}
