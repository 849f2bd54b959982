//! The lights next-event estimation picks from — punctual lights, emissive triangles, the
//! environment — and the probability of picking each (the CDF goes into the tables).
//!
//! [`LightSelection::Robust`] (the default) estimates what each light delivers to what the
//! camera sees — the irradiance at the first hits of 256 camera rays (probes, each with its
//! shading normal n; the scene's vertices when the camera sees nothing), averaged, occlusion
//! ignored: I·falloff·max(0, n·l) / d² for punctual lights,
//! E max(0, n·l) for a directional light, Le A max(0, nl·(−l)) max(0, n·l) / d² for an
//! emissive triangle, ∫ L max(0, n·ω) dω for an environment map (nothing for a constant one,
//! which BSDF samples find as well as light samples do) — and picks with half that, half
//! uniformly, so that no light is starved by a bad estimate. [`LightSelection::Power`] is the older choice by
//! emitted flux, the environment's through the scene's bounding sphere (kept to measure
//! against).

use super::light_bvh::{LightBounds, LightBvh};
use crate::bvh::Bvh;
use crate::layout::gpu_types::{GpuLight, LightKind, NONE};
use crate::layout::tables::Tables;
use crate::materials::GpuMaterial;
use crate::scene::camera_frame::CameraFrame;
use crate::scene::{Light, Scene};
use glam::Vec3;
use std::f32::consts::PI;

use crate::scene::environment::luminance;

/// How next-event estimation picks a light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSelection {
    /// ½ uniform + ½ ∝ the irradiance each light delivers to what the camera sees.
    Robust,
    /// ∝ emitted flux (the environment's through the bounding sphere).
    Power,
    /// Per shading point, by the light BVH ([`super::light_bvh`]) over the punctual lights and
    /// emissive triangles; the environment and directional lights outside it. The tree as a
    /// whole and each light outside it keep their `Robust` probabilities, so a scene without
    /// local lights samples as `Robust` does.
    #[default]
    Bvh,
}

/// How the lights are picked, as uploaded: the CDF's pmf, the share of the tree, the tree.
pub struct Selection {
    /// The probability of each light by the CDF: every light (`Robust`, `Power`), or in
    /// `Bvh` the lights outside the tree, given the tree is not asked (0 for those in it).
    pub cdf_pmf: Vec<f32>,
    /// The probability of asking the tree (0 without one).
    pub tree_share: f32,
    /// The tree (empty unless `Bvh` and a light has bounds).
    pub tree: LightBvh,
}

/// Up to this many points stand for the receivers in the contribution estimates.
const PROBES: usize = 256;
/// Camera rays per side of the probe grid (PROBES of them).
const PROBE_GRID: usize = 16;
/// The aspect ratio assumed for the probe grid (the image's is not known yet).
const PROBE_ASPECT: f32 = 1.5;

/// What the camera sees: the first hits of a 16 × 16 grid of rays through pixel centres of a
/// 3:2 image with the camera's vertical field of view, with their shading normals turned to
/// the camera. Empty when the camera is degenerate or sees nothing.
fn camera_probes(scene: &Scene, bvh: &Bvh) -> Vec<Probe> {
    let Ok(cam) = CameraFrame::new(&scene.camera) else {
        return Vec::new();
    };
    let ty = (0.5 * cam.yfov).tan();
    let mut probes = Vec::with_capacity(PROBES);
    for j in 0..PROBE_GRID {
        for i in 0..PROBE_GRID {
            let sx = ((i as f32 + 0.5) / PROBE_GRID as f32 * 2.0 - 1.0) * ty * PROBE_ASPECT;
            let sy = (1.0 - (j as f32 + 0.5) / PROBE_GRID as f32 * 2.0) * ty;
            let dir = (cam.forward + sx * cam.right + sy * cam.up).normalize();
            let Some(hit) = bvh.closest_hit(cam.position, dir, f32::INFINITY) else {
                continue;
            };
            let [a, b, c] = scene.indices[hit.prim as usize].map(|k| k as usize);
            let w = 1.0 - hit.u - hit.v;
            let n = (w * scene.normals[a] + hit.u * scene.normals[b] + hit.v * scene.normals[c])
                .normalize_or_zero();
            let n = if n.dot(dir) > 0.0 { -n } else { n };
            probes.push(Probe {
                p: cam.position + hit.t * dir,
                n,
            });
        }
    }
    probes
}

/// A scene vertex standing for the receivers: its position and shading normal.
#[derive(Clone, Copy, Debug)]
pub struct Probe {
    pub p: Vec3,
    pub n: Vec3,
}

/// Lights with their flux and contribution estimates, and the light index of every emissive
/// triangle.
#[derive(Default)]
pub struct LightSet {
    pub lights: Vec<GpuLight>,
    /// Emitted flux (the Power selection).
    pub power: Vec<f32>,
    /// Mean irradiance delivered to the probe vertices (the Robust selection).
    pub contribution: Vec<f32>,
    /// Per triangle, its light index or NONE; a single NONE when no triangle emits.
    pub triangle_light: Vec<u32>,
    /// The receivers the contributions are averaged over.
    pub probes: Vec<Probe>,
    /// Per light, its bounds for the light BVH (None: the environment, a directional light).
    pub bounds: Vec<Option<LightBounds>>,
}

impl LightSet {
    /// The scene's punctual lights (with positive power) and emissive triangles; `radius`
    /// bounds the scene (a directional light's power is its flux through that disc).
    pub fn new(scene: &Scene, bvh: &Bvh, materials: &[GpuMaterial], radius: f32) -> Self {
        let mut set = LightSet {
            probes: camera_probes(scene, bvh),
            ..LightSet::default()
        };
        if set.probes.is_empty() {
            let stride = scene.positions.len().div_ceil(PROBES).max(1);
            set.probes = scene
                .positions
                .iter()
                .zip(&scene.normals)
                .step_by(stride)
                .map(|(p, n)| Probe { p: *p, n: *n })
                .collect();
        }
        let probes = ProbeMean {
            probes: set.probes.clone(),
            near: (1e-3 * radius).powi(2),
        };
        for l in &scene.lights {
            let (g, p, bounds) = punctual_record(l, radius);
            set.push_bounded(g, p, probes.punctual_contribution(l), bounds);
        }
        set.add_emissive_triangles(scene, materials, &probes);
        if set.triangle_light.is_empty() {
            set.triangle_light.push(NONE);
        }
        set
    }

    /// Adds every triangle whose material emits, with its contribution to `probes`.
    fn add_emissive_triangles(
        &mut self,
        scene: &Scene,
        materials: &[GpuMaterial],
        probes: &ProbeMean,
    ) {
        for (ti, tri) in scene.indices.iter().enumerate() {
            let m = &materials[scene.triangle_material[ti] as usize];
            let le = Vec3::from_slice(&m.emissive[..3]);
            if luminance(le) <= 0.0 {
                continue;
            }
            let [a, b, c] = tri.map(|i| scene.positions[i as usize]);
            let cross = (b - a).cross(c - a);
            let area = 0.5 * cross.length();
            let normal = cross.normalize_or_zero();
            let centre = (a + b + c) / 3.0;
            // One-sided: Le A cos θl cos θ / d² toward the probes in front.
            let contribution = luminance(le)
                * area
                * probes.mean(centre, &|l, d2, n| {
                    normal.dot(-l).max(0.0) * n.dot(l).max(0.0) / d2
                });
            if self.triangle_light.is_empty() {
                self.triangle_light = vec![NONE; scene.indices.len()];
            }
            self.triangle_light[ti] = self.lights.len() as u32;
            let light = GpuLight {
                kind: LightKind::Triangle as u32,
                prim: ti as u32,
                ..Default::default()
            };
            // Flux of a Lambertian emitter: π A Le.
            self.lights.push(light);
            self.power.push(PI * area * luminance(le));
            self.contribution.push(contribution);
            self.bounds
                .push(Some(LightBounds::triangle(a, b, c, luminance(le))));
        }
    }

    /// Adds a light outside the light BVH (the environment) if its power is positive.
    pub fn push(&mut self, light: GpuLight, power: f32, contribution: f32) {
        self.push_bounded(light, power, contribution, None);
    }

    /// Adds a light with its bounds for the light BVH (None: outside it) if its power is
    /// positive.
    fn push_bounded(
        &mut self,
        light: GpuLight,
        power: f32,
        contribution: f32,
        bounds: Option<LightBounds>,
    ) {
        if power > 0.0 {
            self.lights.push(light);
            self.power.push(power);
            self.contribution.push(contribution.max(0.0));
            self.bounds.push(bounds);
        }
    }

    /// How `selection` picks the lights: the CDF, and for `Bvh` the tree over the lights with
    /// bounds and its share (their `Robust` probabilities summed).
    pub fn selection(&self, selection: LightSelection) -> Selection {
        let n = self.lights.len();
        if selection != LightSelection::Bvh || self.bounds.iter().all(Option::is_none) {
            let cdf_pmf = self.pmf(match selection {
                LightSelection::Bvh => LightSelection::Robust,
                s => s,
            });
            return Selection {
                cdf_pmf,
                tree_share: 0.0,
                tree: LightBvh::build(&[], n),
            };
        }
        let robust = self.pmf(LightSelection::Robust);
        let in_tree: Vec<(u32, LightBounds)> = (0..n)
            .filter_map(|i| self.bounds[i].map(|b| (i as u32, b)))
            .collect();
        let tree = LightBvh::build(&in_tree, n);
        let outside: Vec<f32> = (0..n)
            .map(|i| {
                if self.bounds[i].is_some() {
                    0.0
                } else {
                    robust[i]
                }
            })
            .collect();
        let rest: f32 = outside.iter().sum();
        let tree_share = if rest > 0.0 { 1.0 - rest } else { 1.0 };
        Selection {
            cdf_pmf: outside
                .iter()
                .map(|p| if rest > 0.0 { p / rest } else { 0.0 })
                .collect(),
            tree_share: if tree.is_empty() { 0.0 } else { tree_share },
            tree,
        }
    }

    /// The probability of picking each light by the CDF (`Bvh`: as `Robust`).
    pub fn pmf(&self, selection: LightSelection) -> Vec<f32> {
        let n = self.lights.len();
        let normalised = |w: &[f32]| {
            let total: f32 = w.iter().sum();
            if total > 0.0 && total.is_finite() {
                w.iter().map(|x| x / total).collect()
            } else {
                vec![1.0 / n as f32; n]
            }
        };
        match selection {
            LightSelection::Power => normalised(&self.power),
            // The tree's lights share as Robust picks them (`selection`).
            LightSelection::Robust | LightSelection::Bvh => normalised(&self.contribution)
                .into_iter()
                .map(|p: f32| 0.5 * p + 0.5 / n as f32)
                .collect(),
        }
    }

    pub fn emissive_triangles(&self) -> usize {
        self.lights
            .iter()
            .filter(|l| l.kind == LightKind::Triangle as u32)
            .count()
    }

    /// Writes the selection CDF (n + 1 entries, 0 … 1) of `pmf` into `tables`; returns its
    /// offset.
    pub fn place_cdf(pmf: &[f32], tables: &mut Tables) -> u32 {
        let mut acc = 0.0;
        let mut cdf = vec![0.0f32];
        for p in pmf {
            acc += p;
            cdf.push(acc);
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        tables.push("the scene's lights", cdf)
    }
}

/// Means over the probes, for the lights' contributions.
struct ProbeMean {
    probes: Vec<Probe>,
    /// The least squared distance counted, (r / 1000)².
    near: f32,
}

impl ProbeMean {
    /// Mean over the probes of g(l, d², n): l the unit vector from the probe to x, d² its
    /// squared distance (kept above `near`), n the probe's normal.
    fn mean(&self, x: Vec3, g: &dyn Fn(Vec3, f32, Vec3) -> f32) -> f32 {
        self.probes
            .iter()
            .map(|q| {
                let v = x - q.p;
                g(
                    v.normalize_or_zero(),
                    v.length_squared().max(self.near),
                    q.n,
                )
            })
            .sum::<f32>()
            / self.probes.len().max(1) as f32
    }

    /// The mean irradiance punctual light `l` delivers to the probes.
    fn punctual_contribution(&self, l: &Light) -> f32 {
        match *l {
            Light::Point {
                position,
                intensity,
            } => luminance(intensity) * self.mean(position, &|l, d2, n| n.dot(l).max(0.0) / d2),
            Light::Spot {
                position,
                direction,
                intensity,
                inner_cone,
                outer_cone,
            } => {
                let (ci, co) = (inner_cone.cos(), outer_cone.cos());
                // glTF's smooth falloff t², t = (cos α − cos outer) / (cos inner − cos outer).
                // l points from the probe to the light: the light sees the probe along −l.
                let falloff = |l: Vec3| {
                    let t = ((-l).dot(direction) - co) / (ci - co).max(1e-4);
                    t.clamp(0.0, 1.0).powi(2)
                };
                luminance(intensity)
                    * self.mean(position, &|l, d2, n| falloff(l) * n.dot(l).max(0.0) / d2)
            }
            Light::Directional {
                direction,
                irradiance,
            } => {
                let l = -direction.normalize_or_zero();
                luminance(irradiance) * self.probes.iter().map(|q| q.n.dot(l).max(0.0)).sum::<f32>()
                    / self.probes.len().max(1) as f32
            }
        }
    }
}

/// Punctual light `l`'s record, power and bounds for the light BVH (None for a directional
/// light, which stays outside the tree); `radius` bounds the scene (a directional light's power
/// is its flux through that disc).
fn punctual_record(l: &Light, radius: f32) -> (GpuLight, f32, Option<LightBounds>) {
    match *l {
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
            4.0 * PI * luminance(intensity),
            Some(LightBounds::point(position, luminance(intensity))),
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
            2.0 * PI * (1.0 - outer_cone.cos()) * luminance(intensity),
            Some(LightBounds::spot(
                position,
                direction,
                luminance(intensity),
                inner_cone,
                outer_cone,
            )),
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
            PI * radius * radius * luminance(irradiance),
            None,
        ),
    }
}
