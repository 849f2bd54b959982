//! The scenes the benchmarks measure on, shared by `facet bench`'s sections and the criterion
//! benches: the demo, the gold sphere ([`SphereScene::GOLD`]), materials fitted to analytic
//! gold, the lit procedural scenes and their ray sets.

use crate::Assets;
use crate::error::{BenchError, Result};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::material::ModelChoice;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::{FitConfig, fit_material};
use facet_render::ImageConfig;
use facet_render::bvh::procedural::{self, Rng};
use facet_render::bvh::query::GpuRay;
use facet_render::scene::sphere::SphereScene;
use facet_render::scene::{
    Camera, Environment, EnvironmentMap, FacetMaterial, LoadOptions, Material, Scene, load_gltf,
};
use glam::{Vec3, Vec4};
use std::sync::Arc;

/// Where the procedural scenes' camera stands.
const PROCEDURAL_EYE: Vec3 = Vec3::new(-8.0, 6.0, 9.0);
/// Where it looks.
const PROCEDURAL_TARGET: Vec3 = Vec3::new(2.0, 2.0, -3.0);
/// Its vertical field of view, degrees.
const PROCEDURAL_YFOV_DEG: f32 = 60.0;

/// A `side` × `side` image with a path in flight per pixel.
pub fn square(side: u32) -> ImageConfig {
    ImageConfig {
        width: side,
        height: side,
        wavefront: side * side,
    }
}

/// The demo scene and sky; with `glints` false the glint sphere renders its smooth GGX model.
pub fn demo_scene(assets: &Assets, glints: bool) -> Result<(Scene, Environment)> {
    let mut scene = load_gltf(&assets.demo_gltf(), &LoadOptions::default())?;
    if !glints {
        for m in &mut scene.materials {
            if let Some(f) = &mut m.facet {
                f.glint = None;
            }
        }
    }
    let (map, _) = EnvironmentMap::load(&assets.sky())?;
    Ok((scene, Environment::Map(Arc::new(map))))
}

/// The analytic BRDF `spec` (`ggx?alpha=0.3&conductor=gold`) sampled into an in-memory MERL
/// table, as a measurement.
pub fn analytic_table(spec: &str) -> Result<MerlBrdf> {
    let model = parse_analytic(spec)?;
    MerlBrdf::from_table(spec, MerlTable::sample(&model))
        .map_err(|e| BenchError::Other(format!("{spec}: {e}")))
}

/// A fit of an analytic GGX gold conductor, as a Facet material rendering its GGX model.
pub fn gold_ggx(alpha: f64) -> Result<Material> {
    gold_fit(alpha, ModelChoice::Ggx)
}

/// A fit of gold GGX(α) written as a MERL table, rendered by `model` of the fit.
pub fn gold_fit(alpha: f64, model: ModelChoice) -> Result<Material> {
    let spec = format!("ggx?alpha={alpha}&conductor=gold");
    let fit = fit_material(&analytic_table(&spec)?, &spec, &FitConfig::isotropic())?;
    Ok(Material {
        name: spec.clone(),
        facet: Some(FacetMaterial {
            source: spec.into(),
            fit: Arc::new(fit),
            model,
            glint: None,
        }),
        ..Default::default()
    })
}

/// Issue 12's gold scene ([`SphereScene::GOLD`]: `sphere` on a 20 × 20 grey Lambertian floor,
/// a 40 W/sr point light) under a constant sky of 0.5.
pub fn gold_scene(sphere: Material) -> (Scene, Environment) {
    (
        SphereScene::GOLD.build(sphere),
        Environment::Constant(Vec3::splat(0.5)),
    )
}

/// The procedural scene of `triangles` triangles (seed 1) in a grey Lambertian material under a
/// directional light, seen by the trace rays' camera: the integrator's scaling benchmark.
pub fn lit_procedural_scene(triangles: usize) -> Scene {
    let mesh = procedural::test_scene(triangles, 1);
    let mut s = Scene {
        materials: vec![Material {
            base_color: Vec4::new(0.7, 0.7, 0.7, 1.0),
            ..Default::default()
        }],
        lights: vec![facet_render::scene::Light::Directional {
            direction: Vec3::new(0.3, -1.0, -0.4).normalize(),
            irradiance: Vec3::splat(3.0),
        }],
        camera: Camera {
            position: PROCEDURAL_EYE,
            forward: (PROCEDURAL_TARGET - PROCEDURAL_EYE).normalize(),
            up: Vec3::Y,
            yfov: PROCEDURAL_YFOV_DEG.to_radians(),
        },
        ..Default::default()
    };
    s.add_triangles(&mesh.positions, &mesh.indices, 0);
    s
}

/// At least `count` rays over the procedural scenes (seed 1) of two kinds: pinhole camera rays
/// of an image `width` wide, and random rays inside the scene's box (seed 5).
pub fn trace_rays(count: usize, width: u32) -> [(&'static str, Vec<GpuRay>); 2] {
    let camera = procedural::camera_rays(
        PROCEDURAL_EYE,
        PROCEDURAL_TARGET,
        PROCEDURAL_YFOV_DEG.to_radians(),
        width,
        count.div_ceil(width as usize) as u32,
    );
    let random = procedural::random_rays(
        count,
        Vec3::new(-9.9, 0.1, -9.9),
        Vec3::new(9.9, 9.9, 9.9),
        &mut Rng::new(5),
    );
    [("camera", camera), ("random", random)]
}
