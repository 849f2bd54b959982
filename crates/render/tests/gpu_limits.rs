//! GPU resources sized by input, over the device's limits: an error naming the resource, the
//! limit and what set the size, never a wgpu validation panic. GPU tests (lavapipe in CI); the
//! device is requested with a 1 MiB storage binding limit so that small inputs exceed it.

use facet_gpu::{Gpu, GpuOptions};
use facet_render::camera::CameraFrame;
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
