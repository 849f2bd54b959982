//! `facet bench`'s coat section: the gold scene's sphere as a GGX gold fit with and without a
//! clear coat (η 1.5, α 0.05, weight 1, attached as the fit attaches one), smooth and as
//! glints, and a diffuse plastic with and without it (where most of the base's light leaves
//! the coat near its critical angle), at equal spp: the time a sample and the variance, each
//! against the same base's uncoated smooth fit.

use crate::error::{BenchError, Result};
use crate::measure::gold_row;
use crate::scenes::analytic_table;
use facet_fit::model::coat::Coat;
use facet_fit::model::material::{CoatRecord, FittedMaterial, ModelChoice};
use facet_fit::{FitConfig, fit_material};
use facet_render::scene::{FacetMaterial, GlintParams, Material};
use serde_json::{Value, json};
use std::sync::Arc;

/// The base material, an analytic spec fitted as a measurement would be.
const SPEC: &str = "ggx?alpha=0.3&conductor=gold&kd=0.05";

/// The second base: mostly diffuse.
const PLASTIC: &str = "ggx?alpha=0.3&f0=0.04&kd=0.5,0.3,0.1";

/// The coat attached.
const COAT: Coat = Coat::new(1.5, 0.05, 1.0);

/// The fit of `spec` without and with [`COAT`].
fn fits(spec: &str) -> Result<[Arc<FittedMaterial>; 2]> {
    let src = analytic_table(spec)?;
    let bare = fit_material(&src, spec, &FitConfig::SINGLE_LAYER)?;
    let mut record = bare.record.clone();
    record.coat = Some(CoatRecord {
        coat: COAT,
        error: 0.0,
        ggx_error: None,
        beckmann_error: None,
        base: Box::new(bare.record.clone()),
    });
    let coated = FittedMaterial::from_record(record).map_err(BenchError::Other)?;
    Ok([Arc::new(bare), Arc::new(coated)])
}

/// The section at `side`² and `spp`.
pub fn coat(gpu: &facet_gpu::Gpu, side: u32, spp: u32) -> Result<Value> {
    println!(
        "\ncoat ({SPEC}, then {PLASTIC}, under η {} α {} w {}, gold scene, {side} × {side}, {spp} spp): time a sample and variance against the same base's uncoated smooth fit",
        COAT.eta, COAT.alpha, COAT.weight
    );
    let glints = GlintParams {
        density: 2e6,
        gamma_deg: 2.0,
        threshold: 50.0,
    };
    let [bare, coated] = fits(SPEC)?;
    let [plastic, coated_plastic] = fits(PLASTIC)?;
    let mut rows = Vec::new();
    // Each base's rows against its own uncoated smooth row.
    let mut bases: [Option<(f64, f64)>; 2] = [None, None];
    for (label, fit, glint, base) in [
        ("smooth", &bare, None, 0),
        ("smooth, coated", &coated, None, 0),
        ("glints", &bare, Some(glints), 0),
        ("glints, coated", &coated, Some(glints), 0),
        ("plastic", &plastic, None, 1),
        ("plastic, coated", &coated_plastic, None, 1),
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
        let (m, [t, v], mut row) = gold_row(gpu, material, side, spp, &mut bases[base])?;
        println!(
            "  {label:<15} {:.0} ns a sample ({t:.2}×), variance {:.3e} ({v:.2}×), mean {:.4}",
            m.ns, m.var, m.mean
        );
        row["material"] = json!(label);
        rows.push(row);
    }
    Ok(
        json!({"spec": SPEC, "plastic": PLASTIC, "coat": {"eta": COAT.eta, "alpha": COAT.alpha, "weight": COAT.weight}, "side": side, "spp": spp, "rows": rows}),
    )
}
