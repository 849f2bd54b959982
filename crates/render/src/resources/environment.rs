//! The environment on the GPU: its kind and colour in the frame uniform, a map's texels and
//! sampling CDFs in the tables, and its entry among the lights.

use super::lights::{LightSet, Probe};
use crate::error::RenderError;
use crate::layout::gpu_types::{GpuLight, LightKind};
use crate::layout::limits::{DeviceLimits, Planned};
use crate::layout::tables::Tables;
use crate::layout::tags::EnvKind;
use crate::scene::environment::{luminance, uv_to_direction};
use crate::scene::{Environment, EnvironmentMap};
use glam::Vec2;
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

/// The map's irradiance ∫ L max(0, n·ω) dω averaged over the probes, on a grid of at most
/// 32 × 16 cells (each the mean of its texels, at its centre direction, with its solid angle).
fn map_irradiance(map: &EnvironmentMap, probes: &[Probe]) -> f32 {
    let (w, h) = (map.width as usize, map.height as usize);
    let (cw, ch) = (w.min(32), h.min(16));
    let mut cells = Vec::with_capacity(cw * ch);
    for cy in 0..ch {
        let (y0, y1) = (cy * h / ch, (cy + 1) * h / ch);
        let (t0, t1) = (PI * y0 as f32 / h as f32, PI * y1 as f32 / h as f32);
        for cx in 0..cw {
            let (x0, x1) = (cx * w / cw, (cx + 1) * w / cw);
            let mut l = 0.0;
            for y in y0..y1 {
                for x in x0..x1 {
                    l += luminance(map.texels[y * w + x]);
                }
            }
            l /= ((y1 - y0) * (x1 - x0)).max(1) as f32;
            let u = Vec2::new(
                0.5 * (x0 + x1) as f32 / w as f32,
                0.5 * (y0 + y1) as f32 / h as f32,
            );
            // dω of the cell: Δφ (cos θ0 − cos θ1).
            let omega = 2.0 * PI * (x1 - x0) as f32 / w as f32 * (t0.cos() - t1.cos());
            cells.push((uv_to_direction(u), l * omega));
        }
    }
    if probes.is_empty() {
        // No receivers to ask: the irradiance of an upward surface.
        return cells.iter().map(|(d, e)| d.y.max(0.0) * e).sum();
    }
    probes
        .iter()
        .map(|q| {
            cells
                .iter()
                .map(|(d, e)| q.n.dot(*d).max(0.0) * e)
                .sum::<f32>()
        })
        .sum::<f32>()
        / probes.len() as f32
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
            // Its light samples, uniform over the sphere, are never better than BSDF samples
            // (cosine or visible normals) at finding a uniform sky: it gets only the robust
            // selection's uniform share. (MIS compensation, Karlík et al. 2019: what light
            // sampling adds is the part of L above its mean, nothing for a constant.)
            lights.push(light, flux(luminance(*c)), 0.0);
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
            let mean = map.texels.iter().map(|t| luminance(*t)).sum::<f32>()
                / map.texels.len().max(1) as f32;
            let contribution = map_irradiance(map, &lights.probes);
            lights.push(light, flux(mean), contribution);
        }
        None => {}
    }
    Ok(rec)
}
