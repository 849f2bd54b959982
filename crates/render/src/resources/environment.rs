//! The environment on the GPU: its kind and colour in the frame uniform, a map's texels and
//! sampling CDFs in the tables, and its entry among the lights.

use super::lights::{LightSet, lum};
use super::tables::Tables;
use crate::error::RenderError;
use crate::gpu_types::{GpuLight, LightKind};
use crate::limits::{DeviceLimits, Planned};
use crate::scene::Environment;
use crate::tags::EnvKind;
use std::f32::consts::PI;

/// The frame uniform's environment fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvRecord {
    pub kind: EnvKind,
    /// Map size (1 × 1 without a map).
    pub size: (u32, u32),
    /// Word offsets of the map's texels, marginal and conditional CDFs in the tables.
    pub offsets: (u32, u32, u32),
    /// A constant environment's radiance.
    pub color: [f32; 4],
}

/// Places `environment` in the tables and among the lights; `radius` bounds the scene (the
/// environment's power is its flux through the bounding sphere, 4π · π r² · mean L).
pub fn place(
    environment: Option<&Environment>,
    tables: &mut Tables,
    lights: &mut LightSet,
    limits: &DeviceLimits,
    radius: f32,
) -> Result<EnvRecord, RenderError> {
    let mut rec = EnvRecord {
        kind: EnvKind::None,
        size: (1, 1),
        offsets: (0, 0, 0),
        color: [0.0; 4],
    };
    let light = GpuLight {
        kind: LightKind::Environment as u32,
        ..Default::default()
    };
    let flux = |mean: f32| 4.0 * PI * PI * radius * radius * mean;
    match environment {
        Some(Environment::Constant(c)) => {
            rec.kind = EnvKind::Constant;
            rec.color = c.extend(0.0).to_array();
            // What it delivers to an unoccluded surface: π L.
            lights.push(light, flux(lum(*c)), PI * lum(*c));
        }
        Some(Environment::Map(map)) => {
            rec.kind = EnvKind::Map;
            rec.size = (map.width, map.height);
            let source = format!("the environment map {}", map.path.display());
            // Checked before the copy into the tables: the map is the largest input.
            let words = 3 * map.texels.len() + map.marginal_cdf.len() + map.conditional_cdf.len();
            limits.check(&[Planned::storage(
                "the scene tables",
                4 * (tables.words.len() + words) as u64,
                format!("{source} ({}×{})", map.width, map.height),
            )])?;
            let texels = tables.push(&source, map.texels.iter().flat_map(|t| t.to_array()));
            let marginal = tables.push(&source, map.marginal_cdf.iter().copied());
            let conditional = tables.push(&source, map.conditional_cdf.iter().copied());
            rec.offsets = (texels, marginal, conditional);
            let mean =
                map.texels.iter().map(|t| lum(*t)).sum::<f32>() / map.texels.len().max(1) as f32;
            // The solid-angle mean: rows weighted by sin θ at their centres.
            let (w, h) = (map.width as usize, map.height as usize);
            let (mut sum, mut weight) = (0.0f64, 0.0f64);
            for (y, row) in map.texels.chunks(w.max(1)).enumerate().take(h) {
                let s = (PI as f64 * (y as f64 + 0.5) / h as f64).sin();
                sum += s * row.iter().map(|t| lum(*t) as f64).sum::<f64>();
                weight += s * w as f64;
            }
            let solid_mean = (sum / weight.max(1e-30)) as f32;
            lights.push(light, flux(mean), PI * solid_mean);
        }
        None => {}
    }
    Ok(rec)
}
