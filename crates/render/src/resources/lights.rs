//! The lights next-event estimation picks from — punctual lights, emissive triangles, the
//! environment — each with an estimate of its power; one is chosen with probability ∝ power
//! (the CDF goes into the tables).

use super::tables::Tables;
use crate::gpu_types::{GpuLight, GpuMaterial, LightKind, NONE};
use crate::scene::{Light, Scene};
use glam::Vec3;
use std::f32::consts::PI;

/// Luminance of linear Rec. 709 RGB.
pub fn lum(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Lights with their power estimates, and the light index of every emissive triangle.
#[derive(Default)]
pub struct LightSet {
    pub lights: Vec<GpuLight>,
    pub power: Vec<f32>,
    /// Per triangle, its light index or NONE; a single NONE when no triangle emits.
    pub triangle_light: Vec<u32>,
}

impl LightSet {
    /// The scene's punctual lights (with positive power) and emissive triangles; `radius`
    /// bounds the scene (a directional light's power is its flux through that disc).
    pub fn new(scene: &Scene, materials: &[GpuMaterial], radius: f32) -> Self {
        let mut set = LightSet::default();
        for l in &scene.lights {
            let (g, p) = match *l {
                Light::Point {
                    position,
                    intensity,
                } => (
                    GpuLight {
                        kind: LightKind::Point as u32,
                        position: position.extend(1.0).to_array(),
                        intensity: intensity.extend(0.0).to_array(),
                        ..Default::default()
                    },
                    4.0 * PI * lum(intensity),
                ),
                Light::Spot {
                    position,
                    direction,
                    intensity,
                    inner_cone,
                    outer_cone,
                } => (
                    GpuLight {
                        kind: LightKind::Spot as u32,
                        cos_inner: inner_cone.cos(),
                        cos_outer: outer_cone.cos(),
                        position: position.extend(1.0).to_array(),
                        direction: direction.extend(0.0).to_array(),
                        intensity: intensity.extend(0.0).to_array(),
                        ..Default::default()
                    },
                    2.0 * PI * (1.0 - outer_cone.cos()) * lum(intensity),
                ),
                Light::Directional {
                    direction,
                    irradiance,
                } => (
                    GpuLight {
                        kind: LightKind::Directional as u32,
                        direction: direction.extend(0.0).to_array(),
                        intensity: irradiance.extend(0.0).to_array(),
                        ..Default::default()
                    },
                    PI * radius * radius * lum(irradiance),
                ),
            };
            set.push(g, p);
        }
        for (ti, tri) in scene.indices.iter().enumerate() {
            let m = &materials[scene.triangle_material[ti] as usize];
            let le = Vec3::from_slice(&m.emissive[..3]);
            if lum(le) <= 0.0 {
                continue;
            }
            let [a, b, c] = tri.map(|i| scene.positions[i as usize]);
            let area = 0.5 * (b - a).cross(c - a).length();
            if set.triangle_light.is_empty() {
                set.triangle_light = vec![NONE; scene.indices.len()];
            }
            set.triangle_light[ti] = set.lights.len() as u32;
            let light = GpuLight {
                kind: LightKind::Triangle as u32,
                prim: ti as u32,
                ..Default::default()
            };
            // Flux of a Lambertian emitter: π A Le.
            set.lights.push(light);
            set.power.push(PI * area * lum(le));
        }
        if set.triangle_light.is_empty() {
            set.triangle_light.push(NONE);
        }
        set
    }

    /// Adds a light if its power is positive.
    pub fn push(&mut self, light: GpuLight, power: f32) {
        if power > 0.0 {
            self.lights.push(light);
            self.power.push(power);
        }
    }

    pub fn emissive_triangles(&self) -> usize {
        self.lights
            .iter()
            .filter(|l| l.kind == LightKind::Triangle as u32)
            .count()
    }

    /// Writes the selection CDF (n + 1 entries, 0 … 1) into `tables`; returns its offset.
    pub fn place_cdf(&self, tables: &mut Tables) -> u32 {
        let total: f32 = self.power.iter().sum();
        let mut acc = 0.0;
        let mut cdf = vec![0.0f32];
        for p in &self.power {
            acc += p / total;
            cdf.push(acc);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        tables.push("the scene's lights", cdf)
    }
}
