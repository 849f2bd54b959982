//! GPU resources sized by input, over the device's limits: an error naming the resource, the
//! limit and what set the size, never a wgpu validation panic. GPU tests (lavapipe in CI); the
//! device is requested with a 1 MiB storage binding limit so that small inputs exceed it.

use facet_gpu::{Gpu, GpuOptions};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Camera, Environment, EnvironmentMap, Material, Scene};
use facet_render::{
    ImageConfig, Integrator, RenderConfig, RenderError, ResourceConfig, SampleConfig,
    SceneResources,
};
use glam::Vec3;
use std::sync::Arc;

const CAP: u64 = 1 << 20;

/// A device whose storage bindings are capped at 1 MiB, or `None` (a reported skip) without a
/// GPU; panics under `FACET_REQUIRE_GPU=1`.
fn small_gpu(test: &str) -> Option<Gpu> {
    facet_gpu::gpu_for_tests_with(test, |options| GpuOptions {
        max_storage_binding: Some(CAP),
        ..options
    })
}

fn sphere(segments: u32, rings: u32) -> Scene {
    let mut s = Scene {
        materials: vec![Material::default()],
        camera: Camera {
            position: Vec3::new(0.0, 0.0, 3.0),
            ..Default::default()
        },
        ..Default::default()
    };
    s.add_uv_sphere(Vec3::ZERO, 1.0, segments, rings, 0);
    s
}

fn too_large(e: RenderError) -> String {
    assert!(matches!(e, RenderError::TooLarge { .. }), "{e:?}");
    println!("{e}");
    e.to_string()
}

#[test]
fn over_the_device_limits_is_an_error_naming_the_input() {
    let Some(gpu) = small_gpu("over_the_device_limits_is_an_error_naming_the_input") else {
        return;
    };
    assert_eq!(gpu.device.limits().max_storage_buffer_binding_size, CAP);

    // An environment map of 512 × 256: 1.5 MiB of texels in the scene tables.
    let (w, h) = (512u32, 256u32);
    let map = EnvironmentMap::from_texels(
        "big-sky.exr".into(),
        w,
        h,
        vec![Vec3::splat(0.5); (w * h) as usize],
    )
    .unwrap();
    let env = Environment::Map(Arc::new(map));
    let scene = sphere(16, 8);
    let e = too_large(
        SceneResources::new(&gpu, &scene, Some(&env), ResourceConfig::standard())
            .err()
            .expect("a 1.5 MiB table in a 1 MiB binding"),
    );
    for word in [
        "scene tables",
        "big-sky.exr",
        "512×256",
        "max_storage_buffer_binding_size (1048576)",
    ] {
        assert!(e.contains(word), "`{word}` missing: {e}");
    }

    // A scene of 66 049 vertices: 4 MiB of vertex data.
    let big = sphere(256, 256);
    let e = too_large(
        SceneResources::new(&gpu, &big, None, ResourceConfig::standard())
            .err()
            .expect("4 MiB of vertices in a 1 MiB binding"),
    );
    assert!(
        e.contains("the scene (") && e.contains("max_storage_buffer_binding_size"),
        "{e}"
    );

    // The film of a 512 × 512 render: 4 MiB; and a render size whose film overflows u64 bytes.
    let res = SceneResources::new(&gpu, &scene, None, ResourceConfig::standard()).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    for (width, height) in [(512, 512), (u32::MAX, u32::MAX)] {
        let config = RenderConfig {
            image: ImageConfig {
                width,
                height,
                wavefront: 1024,
            },
            sampling: SampleConfig {
                spp: 1,
                ..SampleConfig::preview()
            },
        };
        let e = too_large(
            integrator
                .render(&gpu, &res, &camera, &config, &mut |_| {})
                .expect_err("a film over the binding limit"),
        );
        let size = format!("--width × --height = {width} × {height}");
        assert!(e.contains("the film") && e.contains(&size), "{e}");
    }
    // The path state of a large wavefront.
    let config = RenderConfig {
        image: ImageConfig {
            width: 128,
            height: 128,
            wavefront: 16384,
        },
        sampling: SampleConfig {
            spp: 1,
            ..SampleConfig::preview()
        },
    };
    let e = too_large(
        integrator
            .render(&gpu, &res, &camera, &config, &mut |_| {})
            .expect_err("8 × 16384 × 16 bytes of path state"),
    );
    assert!(
        e.contains("the path state") && e.contains("--wavefront"),
        "{e}"
    );
    // Within the limits, the same device renders.
    let config = RenderConfig {
        image: ImageConfig {
            width: 32,
            height: 32,
            wavefront: 1024,
        },
        sampling: SampleConfig {
            spp: 1,
            ..SampleConfig::preview()
        },
    };
    let (image, _) = integrator
        .render(&gpu, &res, &camera, &config, &mut |_| {})
        .unwrap();
    assert_eq!((image.width, image.height), (32, 32));
}

/// A light BVH over this device's storage binding limit (10 000 point lights: 1.28 MB of nodes
/// against the 1 MiB cap, their 800 kB of light records within it) is not an error: the lights
/// are picked by the robust selection, `built` says why, and the scene renders.
#[test]
fn a_light_bvh_over_the_limit_falls_back_to_the_robust_selection() {
    let Some(gpu) = small_gpu("a_light_bvh_over_the_limit_falls_back_to_the_robust_selection")
    else {
        return;
    };
    let mut scene = sphere(16, 8);
    scene.lights = (0..10_000)
        .map(|k| facet_render::scene::Light::Point {
            position: Vec3::new(
                (k % 100) as f32 * 0.05 - 2.5,
                2.0,
                (k / 100) as f32 * 0.05 - 2.5,
            ),
            intensity: Vec3::splat(0.01),
        })
        .collect();
    let res = SceneResources::new(&gpu, &scene, None, ResourceConfig::standard()).unwrap();
    let why = res
        .built
        .light_tree_fallback
        .clone()
        .expect("the tree is over the cap");
    println!("{why}");
    assert!(
        why.contains("the light BVH") && why.contains("robust"),
        "{why}"
    );
    assert_eq!(res.built.light_tree_nodes, 0);
    assert_eq!(res.built.light_pmf.len(), 10_000);
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    let config = RenderConfig {
        image: ImageConfig {
            width: 16,
            height: 16,
            wavefront: 256,
        },
        sampling: SampleConfig {
            spp: 1,
            ..SampleConfig::preview()
        },
    };
    let (image, _) = integrator
        .render(&gpu, &res, &camera, &config, &mut |_| {})
        .unwrap();
    assert!(image.mean()[0] > 0.0, "the lamps light the sphere");
}
