//! The scenes and settings of the GPU render tests (`analytic_scenes`, `integrator`): a
//! Lambertian material, a unit sphere filling most of a square frame, render configurations.

use facet_render::scene::sphere::SphereScene;
use facet_render::scene::{Material, Scene};
use facet_render::{ImageConfig, RenderConfig, SampleConfig, Strategy};
use glam::Vec4;

/// The width and height of the test renders.
pub const SIZE: u32 = 64;
/// The vertical field of view of [`sphere_scene`]'s camera.
pub const YFOV_DEG: f32 = SphereScene::TEST.yfov_deg;

/// A unit sphere at the origin seen from +z at distance 3, filling most of the frame
/// ([`SphereScene::TEST`]).
pub fn sphere_scene(material: Material) -> Scene {
    SphereScene::TEST.build(material)
}

/// A Lambertian material of this albedo (glTF: dielectric, roughness 1, no specular).
pub fn lambert(albedo: [f32; 3]) -> Material {
    Material {
        name: "lambert".into(),
        base_color: Vec4::new(albedo[0], albedo[1], albedo[2], 1.0),
        metallic: 0.0,
        roughness: 1.0,
        specular: 0.0,
        ..Default::default()
    }
}

/// [`SIZE`]² at `spp`, paths of up to 8 segments, the rest of [`SampleConfig::preview`].
pub fn config(spp: u32) -> RenderConfig {
    RenderConfig {
        image: image(),
        sampling: SampleConfig {
            spp,
            max_depth: 8,
            ..SampleConfig::preview()
        },
    }
}

/// [`SIZE`]², the rest of [`ImageConfig::preview`].
fn image() -> ImageConfig {
    ImageConfig {
        width: SIZE,
        height: SIZE,
        ..ImageConfig::preview()
    }
}

/// [`SIZE`]² at `spp`, direct light only, sampled by `strategy`.
pub fn direct_config(spp: u32, strategy: Strategy) -> RenderConfig {
    RenderConfig {
        image: image(),
        sampling: SampleConfig {
            spp,
            // Direct light only: every reference of `analytic_scenes` is a single-bounce
            // integral.
            max_depth: 1,
            strategy,
            ..SampleConfig::preview()
        },
    }
}
