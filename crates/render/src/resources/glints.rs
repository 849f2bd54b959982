//! Glint materials on the GPU: per material, the two DPF pyramid levels bracketing its γ
//! (3D textures) built from its NDF (analytic or the fit's table), its flake field and
//! evaluation parameters (bind group 2 of its stage).

use super::{GlintResources, ResourceConfig};
use crate::error::RenderError;
use crate::layout::limits::{DeviceLimits, Planned, product};
use crate::scene::GlintParams;
use facet_brdf::model::microfacet::Ndf;
use facet_glint::dpf::{DpfPyramid, LEVELS_DEG};
use facet_glint::flakes::FlakeField;
use facet_glint::glint_brdf::GlintConfig;
use facet_glint::gpu::GlintField;
use facet_gpu::{Gpu, buffer};

/// The resources of glint material `material` (its index, also its flake seed), and the
/// pyramid levels built, in degrees.
pub fn build(
    gpu: &Gpu,
    limits: &DeviceLimits,
    config: &ResourceConfig,
    material: u32,
    ndf: Ndf,
    spec: GlintParams,
) -> Result<(GlintResources, Vec<f64>), RenderError> {
    let cfg = GlintConfig {
        gamma: (spec.gamma_deg as f64).to_radians(),
        threshold: spec.threshold as f64,
        filtered: config.glint_filter,
        blend: true,
    };
    let ([k0, k1], w) = DpfPyramid::levels_for(cfg.gamma);
    let which: Vec<usize> = if w > 0.0 { vec![k0, k1] } else { vec![k0] };
    let (nt, np) = (config.dpf.n_theta as u64, config.dpf.n_dphi as u64);
    let set_by = format!("the DPF resolution (ResourceConfig::dpf: n_theta {nt}, n_dphi {np})");
    let side = |x: u64| u32::try_from(x).unwrap_or(u32::MAX);
    limits.check(&[
        Planned::texture_3d(
            "a DPF level texture",
            [side(np), side(nt), side(nt)],
            &set_by,
        ),
        Planned::storage("a DPF level buffer", product(&[nt, nt, np, 4]), &set_by),
    ])?;
    let dpf = facet_glint::gpu::build_levels(gpu, &ndf, config.dpf, &which)?;
    let (params, t0, t1) = facet_glint::gpu::eval_params(&cfg, &ndf, &dpf)?;
    let field = FlakeField {
        density: spec.density as f64,
        seed: material,
    };
    let table = field.split_table();
    let d = &gpu.device;
    let res = GlintResources {
        material,
        field: buffer::uniform(d, "glint field", &GlintField::new(&field, &cfg, &table)),
        split_table: buffer::storage(d, "glint split table", &table.counts),
        params: buffer::uniform(d, "glint params", &params),
        level0: t0.create_view(&Default::default()),
        level1: t1.create_view(&Default::default()),
        dpf,
    };
    Ok((res, which.iter().map(|&k| LEVELS_DEG[k]).collect()))
}
