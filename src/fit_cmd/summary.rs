//! The table of a sweep of fits — printed by `facet fit`, written as `summary.csv` — and
//! `facet fit --summary DIR…`, which prints and writes the table that one run over all the
//! inputs prints, from the fits and shard manifests ([`super::shard`]) in the folders.
//!
//! `summary.csv`, one row per fit in the printed table's order, numbers in full precision
//! (the shortest text that reads back as the same f64), an empty field where the table prints
//! `-`:
//! `material, json, iterations, tab_err, tab_rho_d_r, tab_rho_d_g, tab_rho_d_b, ggx_alpha_x,
//! ggx_alpha_y, ggx_err, ggx_moments_err, beckmann_alpha_x, beckmann_alpha_y, beckmann_err,
//! coat_alpha, coat_weight, coat_err, total_ms` (the coat's columns empty where the fit kept
//! none; `coat_err` is the coated tabulated model's error); then a row `median` with the medians
//! of the error columns (the medians line's figures) and of `total_ms`. The timing, the only column that changes from run to run, is
//! last.

use super::shard::{Manifest, Shard};
use anyhow::{Context, Result, anyhow, bail};
use facet_fit::FitError;
use facet_fit::io::input::{Cap, read_to_string, same_file};
use facet_fit::model::material::{FitRecord, FittedMaterial, ParamRecord};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The file name of the table in `--out`.
pub const SUMMARY_CSV: &str = "summary.csv";

/// One fit of a sweep: its record and the name of the JSON it was written to.
pub struct FitRow {
    /// The fit's file name in its folder.
    pub json: String,
    /// The fit.
    pub record: FitRecord,
}

/// The table: one line per fit.
pub fn print_summary(rows: &[FitRow]) {
    if rows.is_empty() {
        return;
    }
    let mut out = std::io::stdout().lock();
    let _ = writeln!(
        out,
        "{:<28} {:>5} {:>9} {:>17}  {:>17} {:>8}  {:>17} {:>8}  {:>8}  {:>8}",
        "material",
        "iters",
        "tab err",
        "tab ρd",
        "ggx αx/αy",
        "ggx err",
        "beckmann αx/αy",
        "beck err",
        "coat err",
        "ms"
    );
    for FitRow { record: r, .. } in rows {
        let param = |p: &Option<ParamRecord>| match p {
            Some(p) => (
                format!("{:.4}/{:.4}", p.alpha_x, p.alpha_y),
                format!("{:.4}", p.error),
            ),
            None => ("-".into(), "-".into()),
        };
        let (ga, ge) = param(&r.ggx);
        let (ba, be) = param(&r.beckmann);
        let te = r.tabulated.error.map_or("-".into(), |e| format!("{e:.4}"));
        let kd = r.tabulated.diffuse;
        let kd = if r.diffuse_lobe {
            format!("{:.3}/{:.3}/{:.3}", kd[0], kd[1], kd[2])
        } else {
            "-".into()
        };
        let ce = r
            .coat
            .as_ref()
            .map_or("-".into(), |c| format!("{:.4}", c.error));
        let _ = writeln!(
            out,
            "{:<28} {:>5} {:>9} {:>17}  {:>17} {:>8}  {:>17} {:>8}  {:>8}  {:>8.1}",
            r.name, r.iterations, te, kd, ga, ge, ba, be, ce, r.timings_ms.total
        );
    }
}

/// The median (the upper one of an even count) of the values `f` gives, over the rows that
/// have one.
fn median(rows: &[FitRow], f: impl Fn(&FitRecord) -> Option<f64>) -> Option<f64> {
    let mut v: Vec<f64> = rows.iter().filter_map(|r| f(&r.record)).collect();
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied()
}

/// The medians of the errors: tabulated, GGX (by least squares), GGX by slope moments,
/// Beckmann, and the coated tabulated models' (over the fits that kept a coat).
fn error_medians(rows: &[FitRow]) -> [Option<f64>; 5] {
    [
        median(rows, |r| r.tabulated.error),
        median(rows, |r| r.ggx.as_ref().map(|p| p.error)),
        median(rows, |r| r.ggx.as_ref().map(|p| p.moments.error)),
        median(rows, |r| r.beckmann.as_ref().map(|p| p.error)),
        median(rows, |r| r.coat.as_ref().map(|c| c.error)),
    ]
}

/// The medians line, with `seconds` as the time the sweep took.
pub fn print_medians(rows: &[FitRow], seconds: f64) {
    let [tab, ggx, ggx_m, beck, coat] =
        error_medians(rows).map(|m| m.map_or("-".into(), |m| format!("{m:.4}")));
    let coated = rows.iter().filter(|r| r.record.coat.is_some()).count();
    // The metric the fits minimised (their errors are in it), or "mixed".
    let metric = match rows.first().map(|r| r.record.metric) {
        Some(m) if rows.iter().all(|r| r.record.metric == m) => m.name(),
        _ => "mixed",
    };
    println!(
        "median error over {} fits ({metric} metric): tabulated {tab}, ggx {ggx} (moments {ggx_m}), beckmann {beck}; coat kept by {coated} (their coated error {coat}); {seconds:.2} s in all",
        rows.len()
    );
}

/// A CSV field: quoted (RFC 4180) when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// A number in full precision, or nothing.
fn csv_number(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

/// The text of `summary.csv` (the columns are in the module's documentation).
pub fn summary_csv(rows: &[FitRow]) -> String {
    let mut s = String::from(
        "material,json,iterations,tab_err,tab_rho_d_r,tab_rho_d_g,tab_rho_d_b,ggx_alpha_x,\
         ggx_alpha_y,ggx_err,ggx_moments_err,beckmann_alpha_x,beckmann_alpha_y,beckmann_err,\
         coat_alpha,coat_weight,coat_err,total_ms\n",
    );
    for FitRow { json, record: r } in rows {
        let rho = |c: usize| r.diffuse_lobe.then_some(r.tabulated.diffuse[c]);
        let param = |p: &Option<ParamRecord>| {
            let p = p.as_ref();
            [
                p.map(|p| p.alpha_x),
                p.map(|p| p.alpha_y),
                p.map(|p| p.error),
            ]
        };
        let [gx, gy, ge] = param(&r.ggx);
        let [bx, by, be] = param(&r.beckmann);
        let numbers = [
            r.tabulated.error,
            rho(0),
            rho(1),
            rho(2),
            gx,
            gy,
            ge,
            r.ggx.as_ref().map(|p| p.moments.error),
            bx,
            by,
            be,
            r.coat.as_ref().map(|c| c.coat.alpha),
            r.coat.as_ref().map(|c| c.coat.weight),
            r.coat.as_ref().map(|c| c.error),
            Some(r.timings_ms.total),
        ];
        let mut line = vec![
            csv_field(&r.name),
            csv_field(json),
            r.iterations.to_string(),
        ];
        line.extend(numbers.map(csv_number));
        s += &(line.join(",") + "\n");
    }
    if !rows.is_empty() {
        let [tab, ggx, ggx_m, beck, coat] = error_medians(rows).map(csv_number);
        let ms = csv_number(median(rows, |r| Some(r.timings_ms.total)));
        s += &format!("median,,,{tab},,,,,,{ggx},{ggx_m},,,{beck},,,{coat},{ms}\n");
    }
    s
}

/// Writes `summary.csv` into `dir` (through a temporary file renamed into place); the path.
pub fn write_summary_csv(dir: &Path, rows: &[FitRow]) -> Result<PathBuf> {
    let path = dir.join(SUMMARY_CSV);
    facet_fit::io::output::write_bytes_atomically(&path, summary_csv(rows))
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(path)
}

/// Refuses `output` when it is one of the files `read`.
pub fn refuse_over_input(output: &Path, read: &[PathBuf]) -> Result<()> {
    match read.iter().find(|i| same_file(i, output)) {
        Some(i) => bail!(
            "the output {} would replace the input {}; choose another --out",
            output.display(),
            i.display()
        ),
        None => Ok(()),
    }
}

/// The fits and manifests found in the folders of `--summary`.
#[derive(Default)]
struct Found {
    /// (folder index, file name, fit), by folder, then file name.
    fits: Vec<(usize, String, FitRecord)>,
    /// (folder index, path, manifest).
    manifests: Vec<(usize, PathBuf, Manifest)>,
    /// Every file read.
    read: Vec<PathBuf>,
}

/// Reads every `*.json` of `dir` (not hidden ones: a write in progress) into `found`: a shard
/// manifest (an object with `facet_shard`) or a fit; anything else is an error naming it.
fn read_folder(dir: &Path, at: usize, found: &mut Found) -> Result<()> {
    let problem = |e: std::io::Error| {
        anyhow!(
            "--summary {}: {}",
            dir.display(),
            facet_fit::io::input::io_problem(&e)
        )
    };
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(problem)? {
        let entry = entry.map_err(problem)?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let json = name.to_ascii_lowercase().ends_with(".json");
        if json && !name.starts_with('.') && entry.file_type().map_err(problem)?.is_file() {
            names.push(name);
        }
    }
    names.sort();
    for name in names {
        let path = dir.join(&name);
        let text = read_to_string(&path, Cap::FIT_JSON)?;
        found.read.push(path.clone());
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
            anyhow!(
                "{}: neither a fit nor a shard manifest: not JSON ({e})",
                path.display()
            )
        })?;
        if value.get("facet_shard").is_some() {
            let m = Manifest::parse(&value)
                .map_err(|e| anyhow!("{}: a broken shard manifest: {e}", path.display()))?;
            found.manifests.push((at, path, m));
        } else {
            let fit = FittedMaterial::parse(&path, &text).map_err(|e| {
                let problem = match e {
                    FitError::Material { problem, .. } => problem,
                    e => e.to_string(),
                };
                anyhow!(
                    "{}: neither a fit nor a shard manifest (as a fit: {problem})",
                    path.display()
                )
            })?;
            found.fits.push((at, name, fit.record));
        }
    }
    Ok(())
}

/// Every fit and manifest in `dirs`; a folder given twice is refused.
fn gather(dirs: &[PathBuf]) -> Result<Found> {
    let mut found = Found::default();
    for (at, dir) in dirs.iter().enumerate() {
        if let Some(before) = dirs[..at].iter().find(|d| same_file(d, dir)) {
            bail!(
                "--summary names the folder {} twice ({} and {})",
                dir.display(),
                before.display(),
                dir.display()
            );
        }
        read_folder(dir, at, &mut found)?;
    }
    Ok(found)
}

/// Checks that the manifests make one whole sweep: the same N, number of inputs, settings and
/// Facet version, and each shard once.
fn check_manifests(manifests: &[(usize, PathBuf, Manifest)]) -> Result<()> {
    let (_, first_path, first) = &manifests[0];
    for (_, path, m) in &manifests[1..] {
        let differ = |what: &str, a: &dyn std::fmt::Display, b: &dyn std::fmt::Display| {
            anyhow!(
                "the shard manifests disagree on {what}: {} has {a}, {} has {b}; they are not \
                 one sweep",
                first_path.display(),
                path.display()
            )
        };
        let (a, b) = (first, m);
        if a.shard.count != b.shard.count {
            return Err(differ("the shard count N", &a.shard.count, &b.shard.count));
        }
        if a.total_inputs != b.total_inputs {
            return Err(differ(
                "the number of inputs",
                &a.total_inputs,
                &b.total_inputs,
            ));
        }
        if a.settings != b.settings {
            let q = |s: &str| format!("`{s}`");
            return Err(differ("the fit settings", &q(&a.settings), &q(&b.settings)));
        }
        if a.facet_version != b.facet_version {
            return Err(differ(
                "the Facet version",
                &a.facet_version,
                &b.facet_version,
            ));
        }
    }
    let n = first.shard.count;
    let mut seen: Vec<Option<&Path>> = vec![None; n];
    for (_, path, m) in manifests {
        if let Some(before) = seen[m.shard.index].replace(path) {
            bail!(
                "{} appears twice: {} and {}",
                m.shard,
                before.display(),
                path.display()
            );
        }
    }
    let missing: Vec<usize> = (0..n).filter(|&i| seen[i].is_none()).collect();
    if !missing.is_empty() {
        let mut names: Vec<String> = missing
            .iter()
            .take(8)
            .map(|&i| Shard { index: i, count: n }.manifest_name())
            .collect();
        if missing.len() > names.len() {
            names.push("…".into());
        }
        bail!(
            "{} of {n} shard(s) missing: no {} in the folders; the sweep is not complete (a \
             shard writes its manifest when it finishes)",
            missing.len(),
            names.join(", "),
        );
    }
    Ok(())
}

/// The rows in the order one run over all the inputs gives them, and the errors of the inputs
/// that failed. With manifests: by the inputs' index, every fit in the folders listed by one;
/// without: by file name.
fn in_order(found: Found, dirs: &[PathBuf]) -> Result<(Vec<FitRow>, Vec<String>)> {
    let Found {
        mut fits,
        mut manifests,
        ..
    } = found;
    if manifests.is_empty() {
        fits.sort_by(|a, b| (&a.1, a.0).cmp(&(&b.1, b.0)));
        let rows = fits
            .into_iter()
            .map(|(_, json, record)| FitRow { json, record });
        return Ok((rows.collect(), Vec::new()));
    }
    check_manifests(&manifests)?;
    manifests.sort_by_key(|(_, _, m)| m.shard.index);
    let mut entries: Vec<_> = manifests
        .iter()
        .flat_map(|(at, path, m)| m.entries.iter().map(move |e| (*at, path, e)))
        .collect();
    entries.sort_by_key(|(_, _, e)| e.index);
    let mut fits: HashMap<(usize, String), FitRecord> = fits
        .into_iter()
        .map(|(at, name, r)| ((at, name), r))
        .collect();
    let (mut rows, mut errors) = (Vec::new(), Vec::new());
    for (at, path, e) in entries {
        let json = match &e.outcome {
            Ok(json) => json.clone(),
            Err(error) => {
                errors.push(error.clone());
                continue;
            }
        };
        let Some(record) = fits.remove(&(at, json.clone())) else {
            bail!(
                "{} is missing: {} lists it as the fit of input {} ({})",
                dirs[at].join(json).display(),
                path.display(),
                e.index,
                e.input
            );
        };
        rows.push(FitRow { json, record });
    }
    if let Some((at, name)) = fits.into_keys().min() {
        bail!(
            "{} is a fit that no shard manifest lists (from another run?); move it out of the \
             folder",
            dirs[at].join(name).display()
        );
    }
    Ok((rows, errors))
}

/// `facet fit --summary DIR…`: the table, medians and `summary.csv` of the fits in `dirs`, as
/// one run over all their inputs gives them; the medians line's time is the sum of the fits'.
/// Nothing is written when the folders do not hold one whole sweep.
pub fn run(dirs: &[PathBuf], out: &Path) -> Result<ExitCode> {
    let found = gather(dirs)?;
    let read = found.read.clone();
    let shards = found.manifests.len();
    if found.fits.is_empty() && found.manifests.is_empty() {
        bail!("--summary: no fit JSON or shard manifest in the folder(s) given");
    }
    let (rows, errors) = in_order(found, dirs)?;
    refuse_over_input(&out.join(SUMMARY_CSV), &read)?;
    crate::output::folder(out, "--out")?;
    for e in &errors {
        eprintln!("error: {e}");
    }
    print_summary(&rows);
    if rows.len() > 1 {
        let ms: f64 = rows.iter().map(|r| r.record.timings_ms.total).sum();
        print_medians(&rows, ms / 1e3);
    }
    let csv = write_summary_csv(out, &rows)?;
    let from = if shards > 0 {
        format!("{shards} shard(s)")
    } else {
        format!("{} folder(s)", dirs.len())
    };
    println!(
        "summarised {} fit(s) from {from}; wrote {}",
        rows.len(),
        csv.display()
    );
    Ok(if errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}
