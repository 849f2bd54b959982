//! In-process timing of the isotropic fit, phase by phase, with the fitted α and errors.
//!
//! `cargo run --release -p facet-fit --example fit_timing -- DIR [REPEATS] [NAME...]`
//! writes `DIR/<name>.binary` MERL files (a gold GGX of α = 0.2 and the named MERL neural
//! proxies; once, reused afterwards), then fits each `REPEATS` times (default 15) with all models
//! and with the tabulated model only, and prints the median times (ms) and the results.
//! `SINGLE_LOBE=1` times the paper's pipeline (`FitConfig::single_lobe`) instead of the default.

use facet_fit::Brdf;
use facet_fit::fitting::{FitConfig, Models, fit_material};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use std::path::{Path, PathBuf};
use std::time::Instant;

const DEFAULT_PROXIES: [&str; 4] = [
    "gold-metallic-paint",
    "yellow-matte-plastic",
    "delrin",
    "chrome",
];

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn files(dir: &Path, names: &[String]) -> Vec<PathBuf> {
    std::fs::create_dir_all(dir).expect("creating the output folder");
    let mut out = Vec::new();
    let gt = dir.join("bench-ggx-0.2.binary");
    if !gt.exists() {
        MerlTable::sample(&parse_analytic("ggx?alpha=0.2&conductor=gold").unwrap())
            .write(&gt)
            .unwrap();
    }
    out.push(gt);
    let lib = NbrdfLibrary::embedded();
    for name in names {
        let path = dir.join(format!("{name}.binary"));
        if !path.exists() {
            MerlTable::sample(&lib.get(name).unwrap())
                .write(&path)
                .unwrap();
        }
        out.push(path);
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = PathBuf::from(args.first().map_or("target/fit-timing", String::as_str));
    let repeats: usize = args.get(1).map_or(15, |r| r.parse().expect("REPEATS"));
    let names: Vec<String> = if args.len() > 2 {
        args[2..].to_vec()
    } else {
        DEFAULT_PROXIES.iter().map(|s| s.to_string()).collect()
    };
    println!(
        "{:<24} {:>6} {:>7} {:>7} {:>7} {:>7} {:>7}  {:>7} {:>8} {:>8} {:>8} {:>8}",
        "material",
        "load",
        "extract",
        "fresnel",
        "fit",
        "total",
        "tab",
        "tab err",
        "ggx α",
        "ggx err",
        "beck α",
        "beck err"
    );
    for path in files(&dir, &names) {
        let t = Instant::now();
        let src = MerlBrdf::map(&path).unwrap();
        let load = t.elapsed().as_secs_f64() * 1e3;
        if std::env::var_os("PROBE").is_some() {
            probe(&src);
        }
        if std::env::var_os("SWEEP").is_some() {
            sweep(&src);
            continue;
        }
        // SINGLE_LOBE=1: the paper's pipeline (`--no-diffuse`) instead of the default fit.
        let all = if std::env::var_os("SINGLE_LOBE").is_some() {
            FitConfig::single_lobe()
        } else {
            FitConfig::isotropic()
        };
        let tab_only = FitConfig {
            models: Models {
                tabulated: true,
                ggx: false,
                beckmann: false,
            },
            ..all
        };
        let first = fit_material(&src, "timing", &all).unwrap();
        let mut phases = [vec![], vec![], vec![], vec![]];
        let mut tab = vec![];
        for _ in 0..repeats {
            let f = fit_material(&src, "timing", &all).unwrap();
            let t = f.record.timings_ms;
            for (v, x) in phases
                .iter_mut()
                .zip([t.extract, t.fresnel, t.fit, t.total])
            {
                v.push(x);
            }
            let t = Instant::now();
            fit_material(&src, "timing", &tab_only).unwrap();
            tab.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let [e, f, p, total] = phases.map(median);
        let r = &first.record;
        let (g, b) = (r.ggx.as_ref().unwrap(), r.beckmann.as_ref().unwrap());
        println!(
            "{:<24} {load:>6.1} {e:>7.2} {f:>7.2} {p:>7.2} {total:>7.2} {:>7.2}  {:>7.5} {:>8.5} {:>8.5} {:>8.5} {:>8.5}",
            r.name,
            median(tab),
            r.tabulated.error.unwrap(),
            g.alpha_x,
            g.error,
            b.alpha_x,
            b.error
        );
    }
}

/// Time of the two passes and the sample set (temporary probe).
#[allow(dead_code)]
pub fn probe(src: &MerlBrdf) {
    use facet_fit::metric::grid::{GridSamples, fresnel_average, microfacet_error};
    let t = Instant::now();
    let set = GridSamples::new(src);
    let t_first = t.elapsed().as_secs_f64() * 1e3;
    drop(set);
    let t = Instant::now();
    let set = GridSamples::new(src);
    let t_set = t.elapsed().as_secs_f64() * 1e3;
    let model = parse_analytic("ggx?alpha=0.2&f0=0.5").unwrap();
    // Medians of 31 runs each: single runs on a shared machine scatter by ±30 %.
    let time = |f: &dyn Fn()| {
        median(
            (0..31)
                .map(|_| {
                    let t = Instant::now();
                    f();
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        )
    };
    let t_f = time(&|| {
        std::hint::black_box(fresnel_average(&model, &set));
    });
    let t_e = time(&|| {
        std::hint::black_box(microfacet_error(&model, &set));
    });
    for irls in [0, 1, 2] {
        let t = time(&|| {
            std::hint::black_box(facet_fit::metric::grid::fresnel_diffuse_and_error(
                &model, &set, irls,
            ));
        });
        println!("probe: solve irls {irls}: {t:.2} ms");
    }
    println!(
        "probe: first set (with the grid geometry) {t_first:.2} ms, set {t_set:.2} ms, fresnel pass {t_f:.2} ms, error pass {t_e:.2} ms"
    );
}

/// α and full-grid error of the least-squares fits against the search's subsampling stride.
#[allow(dead_code)]
pub fn sweep(src: &MerlBrdf) {
    use facet_fit::extract::extract_isotropic;
    use facet_fit::fitting::params::{fit_least_squares, fit_moments, model_with_fresnel};
    use facet_fit::metric::grid::{GridSamples, microfacet_error};
    use facet_fit::model::microfacet::NdfKind;
    let set = GridSamples::new(src);
    let ex = extract_isotropic(src, &Default::default()).unwrap();
    for kind in NdfKind::ALL {
        let start = fit_moments(kind, &ex.ndf);
        let reference = fit_least_squares(start, false, false, &set).alpha_x;
        for stride in [1, 4, 12, 48, 192] {
            let search = set.subsample(stride);
            let t = Instant::now();
            let a = fit_least_squares(start, false, false, &search);
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let e = microfacet_error(&model_with_fresnel("m", a, &set), &set);
            println!(
                "sweep {} {:?} stride {stride:>3}: {:>6} samples, α {:.5} ({:+.4} % of the full-grid α {reference:.5}), full-grid error {e:.6}, search {ms:.1} ms",
                src.name(),
                kind,
                search.len(),
                a.alpha_x,
                (a.alpha_x / reference - 1.0) * 100.0
            );
        }
    }
}
