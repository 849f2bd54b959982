//! `facet bench`'s measured-material section: the gold scene's sphere as a MERL-100 proxy's
//! tabulated fit, as the proxy's own MERL-grid table (sampled by that fit), and as the RGL
//! `.bsdf` Facet writes of the proxy (sampled by its own warps), at equal spp: the time a
//! sample and the variance against the fit's, the image means, and the memory of each table on
//! the GPU.

use crate::error::{BenchError, Result};
use crate::measure::gold_row;
use facet_fit::export::rgl::{BsdfResolution, rgl_tensor};
use facet_fit::model::material::ModelChoice;
use facet_fit::sources::rgl::RglBsdf;
use facet_fit::sources::{InputSpec, nbrdf::NbrdfLibrary};
use facet_fit::{FitConfig, fit_material};
use facet_render::materials::measured_block;
use facet_render::scene::{FacetMaterial, Material, MeasuredMaterial, Measurement};
use serde_json::{Value, json};
use std::sync::Arc;

/// The proxy the section renders.
const PROXY: &str = "gold-metallic-paint";

/// The three materials of [`PROXY`]: its tabulated fit, its table, its `.bsdf`.
fn materials() -> Result<[(&'static str, Material); 3]> {
    let src = NbrdfLibrary::embedded().get(PROXY)?;
    let source = format!("nbrdf:{PROXY}");
    let fit = Arc::new(fit_material(&src, &source, &FitConfig::SINGLE_LAYER)?);
    let table = Measurement::of(&InputSpec::parse(&source), &src).map_err(BenchError::Other)?;
    let (tensor, _) = rgl_tensor(&src, &fit.tabulated.ndf, BsdfResolution::standard(), "")
        .map_err(|e| BenchError::Other(format!("{PROXY}.bsdf: {e}")))?;
    let bsdf = RglBsdf::parse(PROXY, tensor.to_bytes()).map_err(BenchError::Other)?;
    let measured = |data: Measurement| Material {
        name: PROXY.into(),
        measured: Some(MeasuredMaterial {
            source: source.clone(),
            path: None,
            data: Arc::new(data),
            fit: Some(fit.clone()),
            unfitted: None,
        }),
        ..Default::default()
    };
    let fitted = Material {
        name: PROXY.into(),
        facet: Some(FacetMaterial {
            source: source.clone().into(),
            fit: fit.clone(),
            model: ModelChoice::Tabulated,
            glint: None,
        }),
        ..Default::default()
    };
    Ok([
        ("tabulated fit", fitted),
        ("MERL table", measured(table)),
        ("RGL .bsdf", measured(Measurement::Rgl(Box::new(bsdf)))),
    ])
}

/// The section: each material on the gold scene's sphere at `side`² and `spp`.
pub fn measured(gpu: &facet_gpu::Gpu, side: u32, spp: u32) -> Result<Value> {
    println!(
        "\nmeasured materials ({PROXY}, gold scene, {side} × {side}, {spp} spp): time a sample and variance against the tabulated fit"
    );
    let mut rows = Vec::new();
    let mut base: Option<(f64, f64)> = None;
    for (label, material) in materials()? {
        let bytes = material
            .measured
            .as_ref()
            .map_or(0, |m| 4 * measured_block(&m.data).len());
        let (m, [t, v], mut row) = gold_row(gpu, material, side, spp, &mut base)?;
        println!(
            "  {label:<14} {:.0} ns a sample ({t:.2}×), variance {:.3e} ({v:.2}×), mean {:.4}, table {:.1} MiB",
            m.ns,
            m.var,
            m.mean,
            bytes as f64 / (1 << 20) as f64
        );
        row["material"] = json!(label);
        row["table_bytes"] = json!(bytes);
        rows.push(row);
    }
    Ok(json!({"proxy": PROXY, "side": side, "spp": spp, "rows": rows}))
}
