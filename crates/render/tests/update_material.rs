//! `SceneResources::update_material`: an edit written in place renders exactly as resources
//! built from scratch for the edited scene (same seed, same image).

use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::sphere::SphereScene;
use facet_render::scene::{Environment, FacetMaterial, Material, Scene};
use facet_render::{
    ImageConfig, Integrator, RenderConfig, ResourceConfig, SampleConfig, SceneResources,
};
use glam::Vec3;
use std::path::Path;
use std::sync::Arc;

fn demo_fit() -> FittedMaterial {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/demo/default_fit.json");
    FittedMaterial::load(&p).unwrap()
}

fn sphere_scene(fit: FittedMaterial, model: ModelChoice) -> Scene {
    SphereScene::SMALL.build(Material {
        name: "sphere".into(),
        facet: Some(FacetMaterial {
            source: "demo".into(),
            fit: Arc::new(fit),
            model,
            glint: None,
        }),
        ..Material::default()
    })
}

fn render(gpu: &facet_gpu::Gpu, res: &SceneResources, scene: &Scene) -> facet_render::Image {
    let integrator = Integrator::new(&gpu.device, res).unwrap();
    let cfg = RenderConfig {
        image: ImageConfig {
            width: 48,
            height: 48,
            ..ImageConfig::preview()
        },
        sampling: SampleConfig {
            spp: 2,
            ..SampleConfig::preview()
        },
    };
    let cam = CameraFrame::new(&scene.camera).unwrap();
    integrator
        .render(gpu, res, &cam, &cfg, &mut |_| {})
        .unwrap()
        .0
}

#[test]
fn in_place_edit_renders_as_a_rebuild() {
    let Some(gpu) = facet_gpu::gpu_for_tests("in_place_edit_renders_as_a_rebuild") else {
        return;
    };
    let env = Environment::Constant(Vec3::splat(1.0));
    for model in [ModelChoice::Ggx, ModelChoice::Tabulated] {
        let base = demo_fit();
        let mut edited = base.record.clone();
        edited.tabulated.stretch.alpha_x *= 2.0;
        edited.tabulated.stretch.rotation = 0.3;
        if let Some(p) = edited.ggx.as_mut() {
            p.alpha_x *= 2.0;
            for v in &mut p.fresnel.rgb {
                v[2] *= 0.5;
            }
        }
        for v in &mut edited.fresnel.rgb {
            v[0] *= 0.5;
        }
        let edited = FittedMaterial::from_record(edited).unwrap();

        let scene0 = sphere_scene(base, model);
        let mut res =
            SceneResources::new(&gpu, &scene0, Some(&env), ResourceConfig::standard()).unwrap();
        let before = render(&gpu, &res, &scene0);
        let scene1 = sphere_scene(edited, model);
        res.update_material(&gpu.queue, &scene1, 0).unwrap();
        let updated = render(&gpu, &res, &scene1);
        let fresh =
            SceneResources::new(&gpu, &scene1, Some(&env), ResourceConfig::standard()).unwrap();
        let rebuilt = render(&gpu, &fresh, &scene1);
        assert!(
            before.rmse(&rebuilt) > 1e-4,
            "{model:?}: the edit changes the image"
        );
        assert_eq!(
            updated.pixels, rebuilt.pixels,
            "{model:?}: in place = rebuilt"
        );
    }
}

#[test]
fn class_changes_ask_for_a_rebuild() {
    let Some(gpu) = facet_gpu::gpu_for_tests("class_changes_ask_for_a_rebuild") else {
        return;
    };
    let scene0 = sphere_scene(demo_fit(), ModelChoice::Ggx);
    let mut res = SceneResources::new(&gpu, &scene0, None, ResourceConfig::standard()).unwrap();
    let scene1 = sphere_scene(demo_fit(), ModelChoice::Tabulated);
    assert!(res.update_material(&gpu.queue, &scene1, 0).is_err());
    let scene2 = sphere_scene(demo_fit(), ModelChoice::Beckmann);
    assert!(res.update_material(&gpu.queue, &scene2, 0).is_err());
    assert!(res.update_material(&gpu.queue, &scene0, 5).is_err());
}
