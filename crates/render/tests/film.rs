//! The written images read back: the EXR holds the rendered pixels bit for bit, the PNG holds
//! them through the tone map of `facet_render::output::film` (v = 1 − exp(−2^exposure · L), sRGB, 8 bits).

use facet_gpu::gpu_for_tests;
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Camera, Environment, Material, Scene};
use facet_render::{
    Image, ImageConfig, Integrator, RenderConfig, ResourceConfig, SampleConfig, SceneResources,
};
use glam::{Vec3, Vec4};
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The tone map written out independently: sRGB of 1 − exp(−2^e L), rounded to 8 bits.
fn tone_map(l: f32, exposure: f64) -> f64 {
    let v = 1.0 - (-(exposure.exp2()) * (l.max(0.0) as f64)).exp();
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    s * 255.0
}

fn read_exr(path: &std::path::Path) -> (usize, usize, Vec<[f32; 3]>) {
    use exr::prelude::*;
    let img = read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
        |(w, px), pos, (r, g, b, _a): (f32, f32, f32, f32)| px[pos.y() * *w + pos.x()] = [r, g, b],
    )
    .unwrap();
    let size = img.layer_data.size;
    (
        size.width(),
        size.height(),
        img.layer_data.channel_data.pixels.1,
    )
}

/// Checks a PNG against an image in memory: every byte within half a step of the tone map
/// (f32 in the writer against f64 here), and returns the mean byte.
fn check_png(path: &std::path::Path, image: &Image, exposure: f64) -> f64 {
    let png = image::open(path).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (image.width, image.height));
    let mut sum = 0.0;
    for (i, p) in png.pixels().enumerate() {
        for c in 0..3 {
            let want = tone_map(image.pixels[i][c], exposure);
            let got = p.0[c] as f64;
            assert!(
                (got - want).abs() <= 0.5 + 1e-3,
                "{}: pixel {i} channel {c}: {got} for {want:.3} (L = {})",
                path.display(),
                image.pixels[i][c]
            );
            sum += got;
        }
    }
    sum / (3 * png.pixels().len()) as f64
}

/// A rendered image (with values far above 1, so the tone map's shoulder is exercised) written
/// as EXR and PNG at two exposures and read back.
#[test]
fn written_exr_and_png_are_the_image_in_memory() {
    let Some(gpu) = gpu_for_tests("written_exr_and_png_are_the_image_in_memory") else {
        return;
    };
    let mut scene = Scene {
        materials: vec![Material {
            base_color: Vec4::new(0.9, 0.5, 0.2, 1.0),
            ..Default::default()
        }],
        camera: Camera {
            position: Vec3::new(0.0, 0.0, 3.0),
            forward: Vec3::NEG_Z,
            up: Vec3::Y,
            yfov: 0.6,
        },
        ..Default::default()
    };
    scene.add_uv_sphere(Vec3::ZERO, 1.0, 64, 32, 0);
    let env = Environment::Constant(Vec3::new(4.0, 1.0, 0.05));
    let res = SceneResources::new(&gpu, &scene, Some(&env), ResourceConfig::standard()).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    let config = RenderConfig {
        image: ImageConfig {
            width: 40,
            height: 24,
            ..ImageConfig::preview()
        },
        sampling: SampleConfig {
            spp: 2,
            ..SampleConfig::preview()
        },
    };
    let (image, _) = integrator
        .render(&gpu, &res, &camera, &config, &mut |_| {})
        .unwrap();
    let dir = scratch("film_readback");
    image.write_exr(&dir.join("a.exr")).unwrap();
    let (w, h, px) = read_exr(&dir.join("a.exr"));
    assert_eq!((w as u32, h as u32), (image.width, image.height));
    assert_eq!(px, image.pixels, "the EXR is not the rendered image");
    let mut means = Vec::new();
    for exposure in [0.0, -2.0, 1.5] {
        let path = dir.join(format!("a{exposure}.png"));
        image.write_png(&path, exposure as f32).unwrap();
        means.push(check_png(&path, &image, exposure));
    }
    println!("mean PNG byte at exposure 0, −2, 1.5: {means:.1?}");
    assert!(means[1] < means[0] && means[0] < means[2], "{means:?}");
}
