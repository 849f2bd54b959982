//! Round trips through RGL `.bsdf` over the MERL proxies, side by side in one run:
//! MERL table → `.bsdf` → reader (both sample spaces of `sampling_ndfs` scored, the better
//! kept, as `write_rgl` does), and fit (tabulated model, its own NDF as the sample space) →
//! `.bsdf` → reader, each scored in Facet's metric against what was written; with the times
//! (write: the sample spaces' NDFs, the tables and the scoring).
//!
//! `cargo run --release -p facet-fit --example rgl_roundtrip [-- NAME_FILTER [THETA_I SAMPLE VNDF]]`

use facet_fit::export::rgl::{BsdfResolution, rgl_tensor, sampling_ndfs};
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, error_metric};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::numerics::stats::quantile;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::sources::rgl::RglBsdf;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let filter = args.get(1).cloned().unwrap_or_default();
    let mut res = BsdfResolution::standard();
    if args.len() >= 5 {
        res.theta_i = args[2].parse().unwrap();
        res.sample = args[3].parse().unwrap();
        res.vndf = args[4].parse().unwrap();
    }
    let lib = NbrdfLibrary::embedded();
    let names: Vec<String> = lib
        .names()
        .filter(|n| n.contains(&filter))
        .map(str::to_owned)
        .collect();
    println!("resolution {res:?}");
    println!(
        "material | MERL→bsdf error | fit→bsdf error | fit error | write ms | read ms | MiB | per sample space"
    );
    let (mut merl_err, mut fit_err, mut write_ms, mut read_ms) = (vec![], vec![], vec![], vec![]);
    for name in &names {
        let net = lib.get(name).unwrap();
        let merl = MerlBrdf::from_table(name, MerlTable::sample(&net)).unwrap();
        let merl_set = GridSamples::new(&merl);
        let t = Instant::now();
        // Both sample spaces, scored; the better kept, as `write_rgl` does.
        let mut e_merl = f64::INFINITY;
        let mut size = 0.0;
        let mut labels = String::new();
        for (label, ndf) in sampling_ndfs(&merl).unwrap() {
            let (tensor, _) = rgl_tensor(&merl, &ndf, res, name).unwrap();
            let bytes = tensor.to_bytes();
            size = bytes.len() as f64 / (1 << 20) as f64;
            let t = Instant::now();
            let back = RglBsdf::parse(name, bytes).unwrap();
            read_ms.push(t.elapsed().as_secs_f64() * 1e3);
            let e = error_metric(&back, &merl_set);
            labels += &format!(" {label}: {e:.5}");
            e_merl = e_merl.min(e);
        }
        write_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let fit = fit_material(&merl, name, &FitConfig::isotropic()).unwrap();
        let model = &fit.tabulated;
        let model_set = GridSamples::new(model);
        let (tensor, _) = rgl_tensor(model, &model.ndf, res, name).unwrap();
        let back = RglBsdf::parse(name, tensor.to_bytes()).unwrap();
        let e_fit = error_metric(&back, &model_set);
        println!(
            "{name:28} {e_merl:.5} {e_fit:.5} {:.5} {:.0} {:.1} {size:.2} |{labels}",
            fit.record.tabulated.error.unwrap(),
            write_ms.last().unwrap(),
            read_ms.last().unwrap()
        );
        merl_err.push(e_merl);
        fit_err.push(e_fit);
    }
    println!(
        "median / p90 / max: MERL→bsdf {:.5} / {:.5} / {:.5}; fit→bsdf {:.5} / {:.5} / {:.5}",
        quantile(&merl_err, 0.5),
        quantile(&merl_err, 0.9),
        quantile(&merl_err, 1.0),
        quantile(&fit_err, 0.5),
        quantile(&fit_err, 0.9),
        quantile(&fit_err, 1.0)
    );
    println!(
        "median write (NDF + tables) {:.0} ms, read {:.1} ms",
        quantile(&write_ms, 0.5),
        quantile(&read_ms, 0.5)
    );
}
