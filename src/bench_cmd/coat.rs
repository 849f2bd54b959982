//! `facet bench`'s coat section: the gold scene's sphere as a GGX gold fit with and without a
//! clear coat (η 1.5, α 0.05, weight 1, attached as the fit attaches one), smooth and as
//! glints, at equal spp: the time a sample and the variance, each against the uncoated smooth
//! fit's.

use super::gold_row;
use anyhow::Result;
use facet_fit::model::coat::Coat;
use facet_fit::model::material::{CoatRecord, FittedMaterial, ModelChoice};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::{FitConfig, fit_material};
use facet_render::scene::{FacetMaterial, GlintParams, Material};
use serde_json::{Value, json};
use std::sync::Arc;

/// The base material, an analytic spec fitted as a measurement would be.
const SPEC: &str = "ggx?alpha=0.3&conductor=gold&kd=0.05";

/// The coat attached.
const COAT: Coat = Coat::new(1.5, 0.05, 1.0);

/// The fit of [`SPEC`] without and with [`COAT`].
fn fits() -> Result<[Arc<FittedMaterial>; 2]> {
    let model = facet_fit::model::analytic::parse_analytic(SPEC)?;
    let src =
        MerlBrdf::from_table("gold", MerlTable::sample(&model)).map_err(anyhow::Error::msg)?;
    let bare = fit_material(&src, SPEC, &FitConfig::SINGLE_LAYER)?;
    let mut record = bare.record.clone();
    record.coat = Some(CoatRecord {
        coat: COAT,
        error: 0.0,
        ggx_error: None,
        beckmann_error: None,
        base: Box::new(bare.record.clone()),
    });
    let coated = FittedMaterial::from_record(record).map_err(anyhow::Error::msg)?;
    Ok([Arc::new(bare), Arc::new(coated)])
}

/// The section at `side`² and `spp`.
pub fn coat(gpu: &facet_gpu::Gpu, side: u32, spp: u32) -> Result<Value> {
    println!(
        "\ncoat ({SPEC} under η {} α {} w {}, gold scene, {side} × {side}, {spp} spp): time a sample and variance against the uncoated smooth fit",
        COAT.eta, COAT.alpha, COAT.weight
    );
    let glints = GlintParams {
        density: 2e6,
        gamma_deg: 2.0,
        threshold: 50.0,
    };
    let [bare, coated] = fits()?;
    let mut rows = Vec::new();
    let mut base: Option<(f64, f64)> = None;
    for (label, fit, glint) in [
        ("smooth", &bare, None),
        ("smooth, coated", &coated, None),
        ("glints", &bare, Some(glints)),
        ("glints, coated", &coated, Some(glints)),
    ] {
        let material = Material {
            name: label.into(),
            facet: Some(FacetMaterial {
                source: SPEC.into(),
                fit: fit.clone(),
                model: ModelChoice::Ggx,
                glint,
            }),
            ..Default::default()
        };
        let (m, [t, v], mut row) = gold_row(gpu, material, side, spp, &mut base)?;
        println!(
            "  {label:<15} {:.0} ns a sample ({t:.2}×), variance {:.3e} ({v:.2}×), mean {:.4}",
            m.ns, m.var, m.mean
        );
        row["material"] = json!(label);
        rows.push(row);
    }
    Ok(
        json!({"spec": SPEC, "coat": {"eta": COAT.eta, "alpha": COAT.alpha, "weight": COAT.weight}, "side": side, "spp": spp, "rows": rows}),
    )
}
