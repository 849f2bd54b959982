//! `facet merge`: shards of one render (`facet render --samples A..B`) joined into the render of
//! all their samples, written as `facet render` writes one.

use anyhow::{Result, bail};
use clap::Args;
use facet_fit::io::input::same_file;
use facet_render::Image;
use facet_render::output::merge::{Part, merge};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Args, Clone, Debug)]
#[command(allow_negative_numbers = true)]
pub struct MergeArgs {
    /// The parts: EXRs written by `facet render` (shards of --samples A..B, whole renders, or
    /// earlier merges), in any order. They must be of one scene with the same settings and seed,
    /// their sample ranges apart.
    #[arg(required = true, value_name = "PART.exr")]
    pub parts: Vec<PathBuf>,
    /// Output image; the PNG and the EXR are both written, with this stem.
    #[arg(long, default_value = "out/merged.png")]
    pub out: PathBuf,
    /// Merge the parts' variances too: PART.variance.exr beside each part (`facet render
    /// --variance`) into STEM.variance.exr.
    #[arg(long)]
    pub variance: bool,
    /// PNG exposure in stops, -64 to 64 (the EXR is always linear).
    #[arg(long, default_value_t = 0.0, value_parser = crate::args::stops)]
    pub exposure: f32,
}

pub fn run(args: &MergeArgs) -> Result<ExitCode> {
    let parts = args
        .parts
        .iter()
        .map(|p| read_part(p, args.variance))
        .collect::<Result<Vec<_>>>()?;
    let merged = merge(&parts)?;
    let (png, exr) = crate::render_cmd::outputs(&args.out);
    let var = args
        .variance
        .then(|| crate::render_cmd::variance_output(&args.out));
    let read: Vec<PathBuf> = parts
        .iter()
        .flat_map(|p| {
            [
                Some(p.path.clone()),
                p.variance.as_ref().map(|_| variance_of(&p.path)),
            ]
        })
        .flatten()
        .collect();
    for o in [Some(&png), Some(&exr), var.as_ref()].into_iter().flatten() {
        if let Some(i) = read.iter().find(|i| same_file(i, o)) {
            bail!(
                "{}: the output would replace the part {}; choose another --out",
                o.display(),
                i.display()
            );
        }
    }
    if let Some(dir) = png.parent().filter(|d| !d.as_os_str().is_empty()) {
        crate::output::folder(dir, "--out")?;
    }
    merged.image.write_png(&png, args.exposure)?;
    merged.image.write_shard_exr(&exr, &merged.record)?;
    println!(
        "merged {} part(s): samples {} ({} spp), seed {}",
        parts.len(),
        merged.record.ranges_text(),
        merged.record.count(),
        merged.record.seed
    );
    if merged.record.samples.len() > 1 || merged.record.samples[0][0] != 0 {
        eprintln!(
            "notice: the parts hold the samples {} only: an estimate of {} spp, not one render \
             from 0",
            merged.record.ranges_text(),
            merged.record.count()
        );
    }
    println!("wrote {} and {}", png.display(), exr.display());
    if let (Some(v), Some(path)) = (&merged.variance, &var) {
        v.write_shard_exr(path, &merged.variance_record())?;
        println!("wrote {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// PART.variance.exr, beside PART.exr.
fn variance_of(part: &Path) -> PathBuf {
    part.with_extension("variance.exr")
}

/// A part and, with `variance`, the variance beside it.
fn read_part(path: &Path, variance: bool) -> Result<Part> {
    let image = Image::read_shard_exr(path)?;
    let variance = if variance {
        let v = variance_of(path);
        if !v.exists() {
            bail!(
                "{}: no {} beside it (render the parts with --variance, or merge without it)",
                path.display(),
                v.display()
            );
        }
        Some(Image::read_shard_exr(&v)?)
    } else {
        None
    };
    Ok(Part {
        path: path.to_owned(),
        image,
        variance,
    })
}
