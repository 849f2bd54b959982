//! `facet-downstream OUT_DIR`: what a program that uses Facet as a library does.
//!
//! Fits the embedded neural proxy of MERL's `gold-metallic-paint` with facet-fit, saves the
//! fit as JSON and loads it back, evaluates the glint model's DPF of the fitted NDF with
//! facet-glint, and renders the loaded fit on a sphere with facet-render on the default wgpu
//! adapter (`FACET_BACKEND` and `FACET_ADAPTER` choose another), writing `OUT_DIR/fit.json` and
//! `OUT_DIR/sphere.png`.

use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_glint::dpf::{dpf, query_directions};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::sphere::SphereScene;
use facet_render::scene::{Environment, FacetMaterial, Material};
use facet_render::{
    Gpu, ImageConfig, Integrator, RenderConfig, ResourceConfig, SampleConfig, SceneResources,
};
use std::path::PathBuf;
use std::sync::Arc;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = PathBuf::from(
        std::env::args()
            .nth(1)
            .ok_or("usage: facet-downstream OUT_DIR")?,
    );
    std::fs::create_dir_all(&out)?;

    // Fit: a neural proxy of a MERL measurement is a BRDF source like a MERL file.
    let proxy = NbrdfLibrary::embedded().get("gold-metallic-paint")?;
    let fit = fit_material(&proxy, "nbrdf:gold-metallic-paint", &FitConfig::isotropic())?;
    let ggx = fit.record.ggx.as_ref().ok_or("no GGX fit")?;
    println!("fit: GGX alpha {:.4}, error {:.5}", ggx.alpha_x, ggx.error);

    // Save the fit and load it back: the JSON is what `facet render` and the viewer read.
    let json = out.join("fit.json");
    fit.save(&json)?;
    let loaded = FittedMaterial::load(&json)?;

    // Glints: the DPF of the loaded GGX lobe, the probability that a flake reflects ωo into the
    // 1° cone around ωi (here both at 20° from the normal, in the plane of incidence).
    let model = loaded
        .model(ModelChoice::Ggx)
        .ok_or("the loaded fit has no GGX model")?;
    let (wi, wo) = query_directions(20f64.to_radians(), 20f64.to_radians(), 0.0);
    let p = dpf(&model.ndf, wi, wo, 1f64.to_radians());
    println!("glint DPF at 20°/20°, γ = 1°: {p:.3e}");

    // Render the loaded fit, its tabulated NDF, on a sphere under a white sky.
    let sphere = Material {
        name: "gold-metallic-paint".into(),
        facet: Some(FacetMaterial {
            source: json.clone(),
            fit: Arc::new(loaded),
            model: ModelChoice::Tabulated,
            glint: None,
        }),
        ..Material::default()
    };
    let scene = SphereScene::PREVIEW.build(sphere);
    let sky = Environment::Constant(facet_render::glam::Vec3::splat(1.0));
    let gpu = Gpu::new()?;
    println!("adapter: {}", gpu.describe());
    let resources = SceneResources::new(&gpu, &scene, Some(&sky), ResourceConfig::standard())?;
    let integrator = Integrator::new(&gpu.device, &resources)?;
    let camera = CameraFrame::new(&scene.camera)?;
    let config = RenderConfig {
        image: ImageConfig {
            width: 64,
            height: 64,
            wavefront: 64 * 64,
        },
        sampling: SampleConfig {
            spp: 4,
            ..SampleConfig::preview()
        },
    };
    let (image, stats) = integrator.render(&gpu, &resources, &camera, &config, &mut |_| {})?;
    image.write_png(&out.join("sphere.png"), 0.0)?;
    println!(
        "rendered {}×{} at {} spp in {:.0} ms: {}",
        image.width,
        image.height,
        stats.spp,
        stats.ms,
        out.join("sphere.png").display()
    );
    Ok(())
}
