//! `facet bench`'s DPF section: the glint model's nine-level pyramid built on the GPU by the
//! direct and the fast cone rule, side by side, and the fast tables' error against the direct.

use crate::Sizes;
use crate::error::{BenchError, Result};
use crate::timing::{median, median_ms};
use facet_gpu::Gpu;
use serde_json::{Value, json};

/// The nine-level DPF pyramid on the GPU with the direct cone rule (the previous fixed one) and
/// the fast rule (sized to the lobe), median build times side by side, and the fast tables'
/// relative error against the direct ones per level: max and median over the cells above 1 % of
/// the level's peak where the direct rule is converged (cone above the horizon, θo + γ ≤ 85°,
/// θi ≤ 60°; `fast_cone_rule_matches_the_direct_integral` in crates/glint/tests/glint.rs says why), and the
/// max over all cells above 1 % of the peak.
pub fn dpf_pyramid(gpu: &Gpu, sizes: &Sizes) -> Result<Value> {
    use facet_fit::model::microfacet::{AnalyticNdf, Ndf, NdfKind};
    use facet_glint::cone_rule::ConeRule;
    use facet_glint::dpf::{DpfConfig, DpfTable, LEVELS_DEG};
    let cfg = if sizes.dpf_preview {
        DpfConfig::preview()
    } else {
        DpfConfig::standard()
    };
    let all: Vec<usize> = (0..LEVELS_DEG.len()).collect();
    let runs = sizes.runs.min(3);
    let mut rows = Vec::new();
    println!(
        "DPF pyramid, nine levels, {}×{}×{} cells, GPU:",
        cfg.n_theta, cfg.n_theta, cfg.n_dphi
    );
    for (name, kind, alpha) in [
        ("beckmann 0.1", NdfKind::Beckmann, 0.1),
        ("ggx 0.15", NdfKind::Ggx, 0.15),
        ("ggx 0.05", NdfKind::Ggx, 0.05),
    ] {
        let ndf = Ndf::Analytic(AnalyticNdf::isotropic(kind, alpha));
        let build = |rule: &ConeRule| {
            facet_glint::gpu::build_levels_with(gpu, &ndf, cfg, &all, rule)
                .map_err(BenchError::from)
        };
        let direct_ms = median_ms(runs, || build(&ConeRule::direct()).map(|_| ()))?;
        let fast_ms = median_ms(runs, || build(&ConeRule::fast()).map(|_| ()))?;
        let (direct, fast) = (build(&ConeRule::direct())?, build(&ConeRule::fast())?);
        let mut levels = Vec::new();
        let mut line = String::new();
        for (d, f) in direct
            .pyramid
            .levels
            .iter()
            .flatten()
            .zip(fast.pyramid.levels.iter().flatten())
        {
            let peak = d.values.iter().cloned().fold(0.0f32, f32::max) as f64;
            let (mut trusted, mut any) = (Vec::new(), 0.0f64);
            for (k, (a, b)) in f.values.iter().zip(&d.values).enumerate() {
                let (a, b) = (*a as f64, *b as f64);
                if b <= 1e-2 * peak {
                    continue;
                }
                let e = (a / b - 1.0).abs();
                any = any.max(e);
                let (o, i) = (k / (cfg.n_theta * cfg.n_dphi), k / cfg.n_dphi % cfg.n_theta);
                let (to, ti, _) = DpfTable::cell_centre(cfg, o, i, 0);
                if (to + d.gamma).to_degrees() <= 85.0 && ti.to_degrees() <= 60.0 {
                    trusted.push(e);
                }
            }
            let max = trusted.iter().cloned().fold(0.0, f64::max);
            let med = if trusted.is_empty() {
                0.0
            } else {
                median(&mut trusted)
            };
            let deg = d.gamma.to_degrees();
            line += &format!(" {deg:.0}°: {max:.1e}/{med:.0e}");
            levels.push(json!({"gamma_deg": deg, "max_rel": max, "median_rel": med, "cells": trusted.len(), "max_rel_all_cells": any}));
        }
        println!(
            "  {name}: direct rule {direct_ms:.0} ms, fast rule {fast_ms:.0} ms ({:.1}× faster)",
            direct_ms / fast_ms
        );
        println!("    fast vs direct, max/median relative error per level:{line}");
        rows.push(json!({"ndf": name, "n_theta": cfg.n_theta, "n_dphi": cfg.n_dphi, "direct_ms": direct_ms, "fast_ms": fast_ms, "speedup": direct_ms / fast_ms, "levels": levels}));
    }
    Ok(Value::Array(rows))
}
