//! The report's two sphere scenes and their renders: a unit sphere seen from +z under (a) one
//! point light with no environment, depth 1 — every pixel is then f(ωi, ωo) cos θi I / r²,
//! with only the pixel positions random, so two materials differ by their BRDFs alone — and
//! (b) an environment map, paths of up to [`ENV_DEPTH`] bounces. Both take Owen-scrambled Sobol
//! points ([`Sequence::Sobol`]): at the same cost, about 0.55 of the independent numbers' noise
//! floor under the environment and a fifth of it under the point light.
//!
//! Pipelines cost about half a second each on lavapipe: one [`Integrator`] is built per set of
//! shading classes a scene needs and reused for every scene with the same set (an integrator's
//! pipelines depend only on those classes; each render gets its own wavefront bound to its own
//! scene's resources).

use crate::error::{ReportError, Result};
use crate::sky::Sky;
use facet_fit::metric::look::SphereScene as LookScene;
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_gpu::Gpu;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::sphere::{SphereScene, View};
use facet_render::scene::{
    Environment, FacetMaterial, Material, MeasuredMaterial, Measurement, Scene,
};
use facet_render::{
    Image, ImageConfig, Integrator, RenderConfig, RenderError, ResourceConfig, SampleConfig,
    SceneResources, Sequence, Strategy,
};
use glam::Vec3;
use std::collections::HashMap;
use std::sync::Arc;

/// The scene every sphere is rendered in ([`SphereScene::REPORT`]), the one the fit judges its
/// look in ([`LookScene::REPORT`]; checked equal below): the camera on +z at 3 with a 45°
/// vertical field of view, the point light upper left in front at distance ≈ 3.9, of intensity
/// 40 (a white Lambertian facing it gives L = I/(π r²) ≈ 1.5, shown as 1 − e^−1.5 = 0.78 —
/// most MERL materials are darker).
const SCENE: SphereScene = SphereScene::REPORT;
const LOOK: LookScene = LookScene::REPORT;
const CAMERA_Z: f32 = LOOK.camera_z as f32;
const YFOV_DEG: f32 = SCENE.yfov_deg;
// The rendered spheres and the fit's look are one scene.
const _: () = {
    let View::Look { position, .. } = SCENE.view else {
        panic!("the report's camera is on +z")
    };
    let Some(light) = SCENE.light else {
        panic!("the report's scene has a point light")
    };
    assert!(position.x == 0.0 && position.y == 0.0 && position.z == CAMERA_Z);
    assert!(YFOV_DEG == LOOK.yfov_deg as f32);
    assert!(light.position.x == LOOK.light.x as f32);
    assert!(light.position.y == LOOK.light.y as f32);
    assert!(light.position.z == LOOK.light.z as f32);
    assert!(light.intensity == LOOK.intensity as f32);
};
/// Bounces of the environment renders (the sphere sees only the sky: 3 is plenty).
pub const ENV_DEPTH: u32 = 3;
/// Samples per pixel of the point-light renders: only the pixel positions vary (anti-aliasing).
pub const POINT_SPP: u32 = 4;
/// The seed of every sphere's render: the measurement and the models take the same sample
/// sequence.
pub const SEED: u32 = 0;
/// The seed of the reference's second render, whose ΔE against the first is the noise floor.
pub const FLOOR_SEED: u32 = 1;

/// The two lightings of every material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lighting {
    /// One point light, no environment, depth 1.
    Point,
    /// The environment map, depth [`ENV_DEPTH`].
    Environment,
}

impl Lighting {
    pub const ALL: [Lighting; 2] = [Lighting::Point, Lighting::Environment];

    /// A short name for file names and the page.
    pub fn key(self) -> &'static str {
        match self {
            Lighting::Point => "point",
            Lighting::Environment => "env",
        }
    }
}

/// What one sphere is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The measurement itself (a MERL-grid table sampled by the fit's tabulated NDF, or an RGL
    /// file by its own warps).
    Measured,
    /// One of the fit's single-layer models, each with its diffuse lobe.
    Model(ModelChoice),
    /// The fit's coated tabulated model: the coat over the base's tabulated model (only for a
    /// fit that kept a coat).
    Coated,
}

/// How many models the page can show ([`Variant::MODELS`]).
pub const N_MODELS: usize = Variant::MODELS.len();

impl Variant {
    /// The models, in the order of the page's columns.
    pub const MODELS: [Variant; 4] = [
        Variant::Model(ModelChoice::Tabulated),
        Variant::Model(ModelChoice::Ggx),
        Variant::Model(ModelChoice::Beckmann),
        Variant::Coated,
    ];

    /// A short name for file names and the page.
    pub fn key(self) -> &'static str {
        match self {
            Variant::Measured => "measured",
            Variant::Model(m) => model_key(m),
            Variant::Coated => "coated",
        }
    }
}

/// `tabulated`, `ggx` or `beckmann`.
pub fn model_key(m: ModelChoice) -> &'static str {
    match m {
        ModelChoice::Tabulated => "tabulated",
        ModelChoice::Ggx => "ggx",
        ModelChoice::Beckmann => "beckmann",
    }
}

/// The scene material of `variant`: the `measurement` of `source` (sampled by `fit`), a
/// single-layer model of `fit` (its coat, if it kept one, left off) or its coated model.
pub fn material(
    variant: Variant,
    source: &str,
    fit: &Arc<FittedMaterial>,
    measurement: Option<&Arc<Measurement>>,
) -> Result<Material> {
    Ok(match (variant, measurement) {
        (Variant::Measured, Some(data)) => Material {
            name: "measured".into(),
            measured: Some(MeasuredMaterial {
                source: source.into(),
                path: None,
                data: data.clone(),
                fit: Some(fit.clone()),
                unfitted: None,
            }),
            ..Default::default()
        },
        (Variant::Measured, None) => {
            return Err(ReportError::Other(format!(
                "{source}: no measurement to render"
            )));
        }
        (Variant::Model(model), _) => facet_material(source, single_layer(fit), model),
        (Variant::Coated, _) if fit.coated.is_some() => {
            facet_material(source, fit.clone(), ModelChoice::Tabulated)
        }
        (Variant::Coated, _) => {
            return Err(ReportError::Other(format!(
                "{source}: the fit kept no coat"
            )));
        }
    })
}

/// `model` of `fit` as the scene's material (a fit that kept a coat renders coated).
fn facet_material(source: &str, fit: Arc<FittedMaterial>, model: ModelChoice) -> Material {
    Material {
        name: model_key(model).into(),
        facet: Some(FacetMaterial {
            source: source.into(),
            fit,
            model,
            glint: None,
        }),
        ..Default::default()
    }
}

/// `fit` without its coat: its single layer's models.
fn single_layer(fit: &Arc<FittedMaterial>) -> Arc<FittedMaterial> {
    if fit.coated.is_none() {
        return fit.clone();
    }
    let mut single = FittedMaterial::clone(fit);
    single.coated = None;
    single.record.coat = None;
    Arc::new(single)
}

/// The unit sphere at the origin made of `material`, the camera on +z, the point light for
/// [`Lighting::Point`].
fn sphere_scene(material: Material, lighting: Lighting) -> Scene {
    match lighting {
        Lighting::Point => SCENE.build(material),
        Lighting::Environment => SCENE.without_light().build(material),
    }
}

/// Whether the centre of pixel (x, y) of a `side`² image sees the sphere, away from its
/// silhouette (within radius 0.98, where the tessellation and anti-aliasing decide coverage).
pub fn on_sphere(side: u32, x: u32, y: u32) -> bool {
    let tan_half = (0.5 * YFOV_DEG.to_radians()).tan();
    let ndc = |p: u32| 2.0 * (p as f32 + 0.5) / side as f32 - 1.0;
    // The ray o + t d from o = (0, 0, z) meets |p| = r where b² > c, b = o·d, c = |o|² − r².
    let d = Vec3::new(ndc(x) * tan_half, -ndc(y) * tan_half, -1.0).normalize();
    let o = Vec3::new(0.0, 0.0, CAMERA_Z);
    let b = o.dot(d);
    b * b > o.length_squared() - 0.98f32.powi(2)
}

/// Renders the sphere scenes on one adapter, its integrators shared between scenes.
pub struct SphereRenderer<'g> {
    gpu: &'g Gpu,
    environment: Environment,
    /// The image side, pixels.
    side: u32,
    /// Samples per pixel of the environment renders.
    env_spp: u32,
    integrators: HashMap<Vec<&'static str>, Integrator>,
}

impl<'g> SphereRenderer<'g> {
    /// A renderer of `side`² images with `env_spp` samples in the environment `sky`.
    pub fn new(gpu: &'g Gpu, side: u32, env_spp: u32, sky: &Sky) -> Self {
        SphereRenderer {
            gpu,
            environment: Environment::Map(sky.map.clone()),
            side,
            env_spp,
            integrators: HashMap::new(),
        }
    }

    /// The image side, pixels.
    pub fn side(&self) -> u32 {
        self.side
    }

    /// `material` on the sphere under `lighting`, its samples drawn from `seed`'s sequence.
    pub fn render(
        &mut self,
        material: Material,
        lighting: Lighting,
        seed: u32,
    ) -> Result<Image, RenderError> {
        let scene = sphere_scene(material, lighting);
        let env = (lighting == Lighting::Environment).then_some(&self.environment);
        let res = SceneResources::new(self.gpu, &scene, env, ResourceConfig::standard())?;
        let key = res.built.classes.clone();
        let integrator = match self.integrators.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                e.insert(Integrator::new(&self.gpu.device, &res)?)
            }
        };
        let camera = CameraFrame::new(&scene.camera)?;
        let sampling = match lighting {
            // Next-event estimation only reaches a point light: with depth 1 and no
            // environment, each sample is exact for its pixel position.
            Lighting::Point => SampleConfig {
                spp: POINT_SPP,
                max_depth: 1,
                strategy: Strategy::Mis,
                ..SampleConfig::preview()
            },
            Lighting::Environment => SampleConfig {
                spp: self.env_spp,
                max_depth: ENV_DEPTH,
                ..SampleConfig::preview()
            },
        };
        let config = RenderConfig {
            image: ImageConfig {
                width: self.side,
                height: self.side,
                wavefront: 1 << 18,
            },
            sampling: SampleConfig {
                seed,
                sequence: Sequence::Sobol,
                ..sampling
            },
        };
        let (image, _) = integrator.render(self.gpu, &res, &camera, &config, &mut |_| {})?;
        Ok(image)
    }
}
