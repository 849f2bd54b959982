//! The wavefront integrator against theory: white furnaces, the glints' smooth limit and their
//! filtered switch, only-what-is-needed resources, determinism. GPU tests (lavapipe in CI).

mod common;

use common::renders::{SIZE, YFOV_DEG, config, lambert, sphere_scene};
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::MicrofacetBrdf;
use facet_fit::sources::merl::MerlBrdf;
use facet_gpu::{Gpu, gpu_for_tests};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Environment, FacetMaterial, GlintParams, Material, Scene};
use facet_render::{
    Image, ImageConfig, Integrator, RenderConfig, ResourceConfig, SampleConfig, SceneResources,
};
use glam::{DVec3, Vec3};
use std::sync::{Arc, OnceLock};

/// A fit of an analytic GGX α = 0.3 with every Fresnel table set to 1: a perfect conductor.
fn conductor_fit() -> Arc<FittedMaterial> {
    static FIT: OnceLock<Arc<FittedMaterial>> = OnceLock::new();
    FIT.get_or_init(|| {
        let model = facet_fit::model::analytic::parse_analytic("ggx?alpha=0.3&f0=1").unwrap();
        let src = MerlBrdf::from_table("ggx-0.3", MerlTable::sample(&model)).unwrap();
        let fit =
            facet_fit::fit_material(&src, "test", &facet_fit::FitConfig::isotropic()).unwrap();
        let mut r = fit.record.clone();
        let one = |t: &mut facet_fit::model::fresnel::FresnelTable| {
            t.rgb.iter_mut().for_each(|c| *c = [1.0; 3])
        };
        one(&mut r.fresnel);
        for p in [r.ggx.as_mut(), r.beckmann.as_mut()].into_iter().flatten() {
            one(&mut p.fresnel);
        }
        Arc::new(FittedMaterial::from_record(r).unwrap())
    })
    .clone()
}

fn facet_material(model: ModelChoice, glint: Option<GlintParams>) -> Material {
    Material {
        name: format!("{model:?}"),
        facet: Some(FacetMaterial {
            source: "test-fit.json".into(),
            fit: conductor_fit(),
            model,
            glint,
        }),
        ..Default::default()
    }
}

fn render(
    gpu: &Gpu,
    scene: &Scene,
    env: &Environment,
    res_config: ResourceConfig,
    config: RenderConfig,
) -> (Image, facet_render::Built, Vec<&'static str>) {
    let res = SceneResources::new(gpu, scene, Some(env), res_config).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    let (image, _) = integrator
        .render(gpu, &res, &camera, &config, &mut |_| {})
        .unwrap();
    assert!(
        image.pixels.iter().flatten().all(|v| v.is_finite()),
        "non-finite pixel"
    );
    (image, res.built.clone(), integrator.stage_names())
}

/// The view direction's angle to the sphere's normal at pixel (x, y)'s centre, or None when the
/// pixel is not well inside the silhouette (θo below `max_deg`).
fn theta_o(x: u32, y: u32, max_deg: f64) -> Option<f64> {
    let t = (YFOV_DEG as f64).to_radians() * 0.5;
    let ndc = (
        2.0 * (x as f64 + 0.5) / SIZE as f64 - 1.0,
        1.0 - 2.0 * (y as f64 + 0.5) / SIZE as f64,
    );
    let o = DVec3::new(0.0, 0.0, 3.0);
    let d = DVec3::new(ndc.0 * t.tan(), ndc.1 * t.tan(), -1.0).normalize();
    // |o + s d| = 1
    let b = o.dot(d);
    let disc = b * b - (o.length_squared() - 1.0);
    if disc <= 0.0 {
        return None;
    }
    let n = (o + (-b - disc.sqrt()) * d).normalize();
    let theta = n.dot(-d).clamp(-1.0, 1.0).acos();
    (theta.to_degrees() < max_deg).then_some(theta)
}

#[test]
fn white_furnace_lambert_sphere_is_one() {
    let Some(gpu) = gpu_for_tests("white_furnace_lambert_sphere_is_one") else {
        return;
    };
    let scene = sphere_scene(lambert([1.0; 3]));
    let env = Environment::Constant(Vec3::ONE);
    let (img, built, _) = render(&gpu, &scene, &env, ResourceConfig::standard(), config(32));
    let on = img.mean_where(|x, y| theta_o(x, y, 80.0).is_some());
    let all = img.mean();
    println!("furnace lambert: sphere {on:.4?}, image {all:.4?}");
    for c in 0..3 {
        assert!((on[c] - 1.0).abs() < 0.01, "sphere mean {on:?}");
        assert!((all[c] - 1.0).abs() < 0.01, "image mean {all:?}");
    }
    assert_eq!(built.classes, vec!["diffuse"]);
}

/// A conductor with F = 1 under a uniform environment of radiance 1 renders its directional
/// albedo E(θo), computed on the CPU by facet_fit::model::albedo for the same fitted model.
#[test]
fn white_furnace_conductor_matches_cpu_albedo() {
    let Some(gpu) = gpu_for_tests("white_furnace_conductor_matches_cpu_albedo") else {
        return;
    };
    let env = Environment::Constant(Vec3::ONE);
    for model in [
        ModelChoice::Ggx,
        ModelChoice::Beckmann,
        ModelChoice::Tabulated,
    ] {
        let scene = sphere_scene(facet_material(model, None));
        let (img, built, _) = render(&gpu, &scene, &env, ResourceConfig::standard(), config(32));
        let fit = conductor_fit();
        let brdf: &MicrofacetBrdf = fit.model(model).unwrap();
        // E(θo) tabulated every degree, interpolated per pixel.
        let table: Vec<f64> = (0..=90)
            .map(|deg| {
                let t = (deg as f64).to_radians();
                facet_fit::model::albedo::directional_albedo(
                    brdf,
                    DVec3::new(t.sin(), 0.0, t.cos()),
                    128,
                )[0]
            })
            .collect();
        let expect = |theta: f64| {
            let x = theta.to_degrees();
            let i = (x as usize).min(89);
            table[i] + (x - i as f64) * (table[i + 1] - table[i])
        };
        let (mut sum_img, mut sum_cpu, mut n) = (0.0, 0.0, 0);
        for y in 0..SIZE {
            for x in 0..SIZE {
                if let Some(t) = theta_o(x, y, 70.0) {
                    sum_img += img.pixels[(y * SIZE + x) as usize][0] as f64;
                    sum_cpu += expect(t);
                    n += 1;
                }
            }
        }
        let (gpu_mean, cpu_mean) = (sum_img / n as f64, sum_cpu / n as f64);
        println!(
            "furnace {model:?}: image {gpu_mean:.4}, CPU albedo {cpu_mean:.4} over {n} pixels ({:+.2} %), classes {:?}",
            100.0 * (gpu_mean / cpu_mean - 1.0),
            built.classes
        );
        assert!(
            (gpu_mean / cpu_mean - 1.0).abs() < 0.01,
            "{model:?}: {gpu_mean} vs {cpu_mean}"
        );
    }
}

#[test]
fn scene_without_glints_builds_no_glint_resources() {
    let Some(gpu) = gpu_for_tests("scene_without_glints_builds_no_glint_resources") else {
        return;
    };
    let mut scene = sphere_scene(facet_material(ModelChoice::Ggx, None));
    // A glint material that no triangle uses costs nothing either.
    scene.materials.push(facet_material(
        ModelChoice::Ggx,
        Some(GlintParams {
            density: 1e6,
            gamma_deg: 2.0,
            threshold: 50.0,
        }),
    ));
    let res = SceneResources::new(&gpu, &scene, None, ResourceConfig::standard()).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    println!(
        "built: {:?}, stages {:?}",
        res.built,
        integrator.stage_names()
    );
    assert!(res.built.glint_pyramids.is_empty());
    assert!(res.glints.is_empty());
    assert_eq!(res.built.classes, vec!["analytic"]);
    assert!(!res.built.environment_map);
    assert_eq!(res.built.tabulated_tables, 0);
    assert_eq!(
        integrator.stage_names(),
        vec!["logic", "generate", "extend", "shade_microfacet", "connect"]
    );
}

fn glint(density: f32, threshold: f32) -> Material {
    facet_material(
        ModelChoice::Ggx,
        Some(GlintParams {
            density,
            gamma_deg: 5.0,
            threshold,
        }),
    )
}

/// With a huge flake density the glint material is its smooth model: the image means agree,
/// for the fit's GGX model and for its tabulated NDF (DPF tables built from the table; D, Λ and
/// the visible-normal sampling from the fit's tables in the glint stage).
#[test]
fn glints_with_huge_density_render_the_smooth_model() {
    let Some(gpu) = gpu_for_tests("glints_with_huge_density_render_the_smooth_model") else {
        return;
    };
    let env = Environment::Constant(Vec3::ONE);
    for model in [ModelChoice::Ggx, ModelChoice::Tabulated] {
        let (smooth, _, _) = render(
            &gpu,
            &sphere_scene(facet_material(model, None)),
            &env,
            ResourceConfig::standard(),
            config(16),
        );
        let spec = GlintParams {
            density: 1e12,
            gamma_deg: 5.0,
            threshold: 50.0,
        };
        let (glinty, built, stages) = render(
            &gpu,
            &sphere_scene(facet_material(model, Some(spec))),
            &env,
            ResourceConfig::standard(),
            config(16),
        );
        let on = |x, y| theta_o(x, y, 70.0).is_some();
        let (a, b) = (smooth.mean_where(on)[0], glinty.mean_where(on)[0]);
        println!(
            "{model:?} glint smooth limit: smooth {a:.4}, glints (N = 1e12) {b:.4} ({:+.2} %); pyramid {:?}; stages {stages:?}",
            100.0 * (b / a - 1.0),
            built.glint_pyramids
        );
        assert!((b / a - 1.0).abs() < 0.02, "{model:?}: {b} vs {a}");
        assert_eq!(built.glint_pyramids, vec![vec![5.0]]);
    }
}

/// Glints under a coat: with a huge flake density the glint material is its smooth coated
/// model (the image means agree within 2 %), and the coat is seen (the uncoated glints' mean is
/// more than 5 % away).
#[test]
fn coated_glints_with_huge_density_render_the_smooth_coated_model() {
    use facet_fit::model::coat::Coat;
    use facet_fit::model::material::CoatRecord;
    let Some(gpu) = gpu_for_tests("coated_glints_with_huge_density_render_the_smooth_coated_model")
    else {
        return;
    };
    let env = Environment::Constant(Vec3::ONE);
    let mut record = conductor_fit().record.clone();
    record.coat = Some(CoatRecord {
        coat: Coat::new(1.5, 0.05, 1.0),
        error: 0.0,
        ggx_error: None,
        beckmann_error: None,
        base: Box::new(conductor_fit().record.clone()),
    });
    let coated = Arc::new(FittedMaterial::from_record(record).unwrap());
    let spec = GlintParams {
        density: 1e12,
        gamma_deg: 5.0,
        threshold: 50.0,
    };
    let on = |x, y| theta_o(x, y, 70.0).is_some();
    let mean = |fit: &Arc<FittedMaterial>, glint: Option<GlintParams>| {
        let mut m = facet_material(ModelChoice::Ggx, glint);
        m.facet.as_mut().unwrap().fit = fit.clone();
        let scene = sphere_scene(m);
        let (img, _, _) = render(&gpu, &scene, &env, ResourceConfig::standard(), config(16));
        img.mean_where(on)[0]
    };
    let smooth = mean(&coated, None);
    let glinty = mean(&coated, Some(spec));
    let bare = mean(&conductor_fit(), Some(spec));
    println!(
        "coated: smooth {smooth:.4}, glints (N = 1e12) {glinty:.4}; uncoated glints {bare:.4}"
    );
    assert!((glinty / smooth - 1.0).abs() < 0.02, "{glinty} vs {smooth}");
    assert!((bare / smooth - 1.0).abs() > 0.05, "{bare} vs {smooth}");
}

/// The filtered switch leaves no seam: counting everywhere, the mean everywhere and a threshold
/// in the middle of the footprints' expected counts give the same image mean.
#[test]
fn glint_filter_switch_leaves_no_seam() {
    let Some(gpu) = gpu_for_tests("glint_filter_switch_leaves_no_seam") else {
        return;
    };
    let env = Environment::Constant(Vec3::ONE);
    // Density and threshold put the switch inside the range of the footprints' expected counts
    // N·a·P (≈ 0.01 … 2 here).
    let density = 2e6;
    let mut means = Vec::new();
    for (label, threshold, filter) in [
        ("counted", 0.0, false),
        ("switch at 0.5", 0.5, true),
        ("mean", 0.0, true),
    ] {
        let rc = ResourceConfig {
            glint_filter: filter,
            ..ResourceConfig::standard()
        };
        let (img, _, _) = render(
            &gpu,
            &sphere_scene(glint(density, threshold)),
            &env,
            rc,
            config(16),
        );
        let m = img.mean_where(|x, y| theta_o(x, y, 70.0).is_some())[0];
        println!("glint {label}: mean {m:.4}");
        means.push(m);
    }
    for m in &means[..2] {
        assert!((m / means[2] - 1.0).abs() < 0.03, "{means:?}");
    }
}

/// The threshold decides, footprint by footprint, whether flakes are counted or replaced by
/// their mean N·a·P. One sample per pixel of a sphere under a directional light, direct light
/// only: each pixel is one evaluation of the glint BRDF, so with the same seed a pixel under
/// threshold T is bit for bit either the counted render's or the all-mean render's. Raising T
/// can only move footprints from the mean to the count; T = 0 is the mean everywhere, T = ∞ and
/// the filter switched off are the count everywhere.
#[test]
fn glint_threshold_decides_which_footprints_are_counted() {
    let Some(gpu) = gpu_for_tests("glint_threshold_decides_which_footprints_are_counted") else {
        return;
    };
    let render_with = |threshold: f32, filter: bool| {
        let mut scene = sphere_scene(glint(2e6, threshold));
        scene.lights.push(facet_render::scene::Light::Directional {
            direction: Vec3::new(0.3, -0.4, -1.0).normalize(),
            irradiance: Vec3::splat(2.0),
        });
        let rc = ResourceConfig {
            glint_filter: filter,
            ..ResourceConfig::standard()
        };
        let res = SceneResources::new(&gpu, &scene, None, rc).unwrap();
        let integrator = Integrator::new(&gpu.device, &res).unwrap();
        let camera = CameraFrame::new(&scene.camera).unwrap();
        let mut c = config(1);
        c.sampling.max_depth = 1;
        integrator
            .render(&gpu, &res, &camera, &c, &mut |_| {})
            .unwrap()
            .0
            .pixels
    };
    let counted = render_with(0.0, false);
    let mean = render_with(0.0, true);
    assert_eq!(
        render_with(1e30, true),
        counted,
        "T = ∞ must count every footprint"
    );
    // Pixels where counting and the mean differ say which one a render took.
    let telling: Vec<usize> = (0..counted.len())
        .filter(|&i| counted[i] != mean[i])
        .collect();
    println!(
        "{} of {} pixels tell the count from the mean",
        telling.len(),
        counted.len()
    );
    assert!(telling.len() > 500, "{}", telling.len());
    let mut previous: Option<Vec<bool>> = None;
    for threshold in [0.0, 0.02, 0.05, 0.2] {
        let img = render_with(threshold, true);
        let mut took_mean = Vec::new();
        for &i in &telling {
            let m = img[i] == mean[i];
            assert!(
                m || img[i] == counted[i],
                "T = {threshold}: pixel {i} is neither: {:?} counted {:?} mean {:?}",
                img[i],
                counted[i],
                mean[i]
            );
            took_mean.push(m);
        }
        let n = took_mean.iter().filter(|&&m| m).count();
        println!(
            "T = {threshold}: {n} of {} footprints replaced by the mean",
            telling.len()
        );
        if threshold == 0.0 {
            assert_eq!(n, telling.len(), "T = 0 must replace every footprint");
        } else {
            assert!(n > 0 && n < telling.len(), "T = {threshold}: {n}");
        }
        if let Some(p) = &previous {
            for (k, (&now, &before)) in took_mean.iter().zip(p).enumerate() {
                assert!(
                    !now || before,
                    "pixel {} went back to the mean as T grew",
                    telling[k]
                );
            }
            assert!(
                n < p.iter().filter(|&&m| m).count(),
                "T = {threshold} changed nothing"
            );
        }
        previous = Some(took_mean);
    }
}

#[test]
fn same_seed_same_image() {
    let Some(gpu) = gpu_for_tests("same_seed_same_image") else {
        return;
    };
    let env = Environment::Constant(Vec3::new(1.0, 0.8, 0.6));
    let scene = sphere_scene(facet_material(ModelChoice::Tabulated, None));
    let mut c = config(4);
    c.image.wavefront = 1000; // several tiles
    let (a, _, _) = render(&gpu, &scene, &env, ResourceConfig::standard(), c);
    let (b, _, _) = render(&gpu, &scene, &env, ResourceConfig::standard(), c);
    let mut seven = c;
    seven.sampling.seed = 7;
    let (other, _, _) = render(&gpu, &scene, &env, ResourceConfig::standard(), seven);
    assert_eq!(a.pixels, b.pixels);
    assert_ne!(a.pixels, other.pixels);
    assert!(a.samples.iter().all(|&s| s == 4));
}

/// A scene built in code with a NaN vertex or an index out of range is refused with a message,
/// before anything reaches the GPU.
#[test]
fn broken_scenes_are_refused() {
    let mut scene = sphere_scene(lambert([0.5; 3]));
    scene.positions[10].x = f32::NAN;
    let err = facet_render::resources::validate(&scene)
        .unwrap_err()
        .to_string();
    assert!(err.contains("vertex 10"), "{err}");
    let mut scene = sphere_scene(lambert([0.5; 3]));
    scene.indices[3][1] = 1 << 30;
    let err = facet_render::resources::validate(&scene)
        .unwrap_err()
        .to_string();
    assert!(err.contains("triangle 3"), "{err}");
    assert!(facet_render::resources::validate(&sphere_scene(lambert([0.5; 3]))).is_ok());
}

/// Large footprints count on the GPU as on the CPU. Before lit counts per node this hit a known
/// limit of lavapipe (llvmpipe caps the loop iterations of a shader invocation at 65 535, and
/// the walk visited every flake: 5537 of 6288 found at density 5e7, footprints of 3·10⁵ flakes
/// hopeless). Now a node inside the ellipse adds its lit count and a node with none lit is not
/// entered: with P = 1 (every flake lit, the worst case: every boundary leaf is entered)
/// ellipses of ~1500 and ~3100 flakes count exactly; with the P that renders count at (~30 lit
/// expected, the filter's range) footprints of 3·10³, 3·10⁴ and 3·10⁵ flakes do. Stated budget:
/// 2 flakes (f32 positions on the ellipse's edge).
#[test]
fn gpu_count_matches_cpu_on_large_footprints() {
    use facet_glint::flakes::{FlakeField, Footprint};
    use facet_glint::glint_brdf::glint_count_at;
    use facet_glint::gpu::{GlintCounter, GlintQuery};
    let Some(gpu) = gpu_for_tests("gpu_count_matches_cpu_on_large_footprints") else {
        return;
    };
    let field = FlakeField {
        density: 5e7,
        seed: 0,
    };
    let cfg = facet_glint::glint_brdf::GlintConfig {
        gamma: 0.05,
        threshold: 1e30,
        filtered: false,
        blend: false,
    };
    let coords = glam::DVec2::new(0.5, 7.5);
    let counter = GlintCounter::new(&gpu.device).unwrap();
    let mut bad = Vec::new();
    // (semi-axes, P): every flake lit; ~30 lit in round footprints of 3·10³ … 3·10⁵ flakes.
    for ((ax, by), all_lit) in [
        ((0.01, 1e-3), true),
        ((0.02, 1e-3), true),
        ((0.0044, 0.0044), false),
        ((0.014, 0.014), false),
        ((0.044, 0.044), false),
    ] {
        let fps: Vec<Footprint> = (0..4)
            .map(|i| Footprint {
                center: glam::DVec2::new(0.37 + 0.01 * i as f64, 0.61),
                a: glam::DVec2::new(ax, 0.0),
                b: glam::DVec2::new(0.0, by),
            })
            .collect();
        let p_of = |fp: &Footprint| {
            let p = if all_lit {
                1.0
            } else {
                30.0 / (field.density * fp.area())
            };
            p as f32 as f64
        };
        let qs: Vec<GlintQuery> = fps
            .iter()
            .map(|fp| GlintQuery::new(fp, p_of(fp), coords))
            .collect();
        let gpu_counts = counter.count(&gpu, &field, &cfg, &qs).unwrap();
        for (fp, [g, _]) in fps.iter().zip(gpu_counts) {
            let cpu = glint_count_at(&field, fp, coords, p_of(fp), &cfg);
            let flakes = field.density * fp.area();
            println!(
                "axes ({ax}, {by}), ~{flakes:.0} flakes, P {:.2e}: CPU {cpu}, GPU {g}",
                p_of(fp)
            );
            if all_lit {
                assert_eq!(
                    cpu,
                    field.flakes_in(fp).len() as f64,
                    "P = 1 lights every flake"
                );
            }
            if (g - cpu).abs() > 2.0 {
                bad.push((cpu, g));
            }
        }
    }
    assert!(bad.is_empty(), "(CPU, GPU): {bad:?}");
}

/// A wavefront reused across renders: two renders with seeds a, b after a clear give exactly
/// the pixels of fresh renders; 4 × 2 spp accumulated are one 8 spp render (same sample
/// indices, same summation order); its GPU tone map is the CPU's to the byte.
#[test]
fn a_reused_wavefront_renders_what_fresh_ones_do() {
    let Some(gpu) = gpu_for_tests("a_reused_wavefront_renders_what_fresh_ones_do") else {
        return;
    };
    let env = Environment::Constant(Vec3::new(1.0, 0.8, 0.6));
    let scene = sphere_scene(facet_material(ModelChoice::Tabulated, None));
    let res = SceneResources::new(&gpu, &scene, Some(&env), ResourceConfig::standard()).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    let mut c = config(2);
    c.image.wavefront = 1000; // several tiles
    let fresh = |seed: u32, spp: u32| {
        let mut c = c;
        (c.sampling.seed, c.sampling.spp) = (seed, spp);
        integrator
            .render(&gpu, &res, &camera, &c, &mut |_| {})
            .unwrap()
            .0
    };
    let mut wf = integrator.wavefront(&gpu, &res, c.image).unwrap();
    for seed in [3, 9] {
        wf.clear(&gpu);
        let s = SampleConfig { seed, ..c.sampling };
        integrator
            .render_more(&gpu, &mut wf, &camera, &s, &mut |_| {})
            .unwrap();
        assert_eq!(
            wf.image(&gpu).unwrap().pixels,
            fresh(seed, 2).pixels,
            "seed {seed}"
        );
    }
    wf.clear(&gpu);
    for _ in 0..4 {
        let stats = integrator
            .render_more(&gpu, &mut wf, &camera, &c.sampling, &mut |_| {})
            .unwrap();
        assert_eq!(stats.spp, 2);
    }
    assert_eq!(wf.spp(), 8);
    let accumulated = wf.image(&gpu).unwrap();
    let once = fresh(0, 8);
    assert!(accumulated.samples.iter().all(|&s| s == 8));
    let worst = accumulated
        .pixels
        .iter()
        .flatten()
        .zip(once.pixels.iter().flatten())
        .map(|(a, b)| (a - b).abs() / b.abs().max(1e-3))
        .fold(0f32, f32::max);
    println!("4 × 2 spp against 8 spp: worst relative difference {worst:e}");
    assert!(worst <= 4.0 * f32::EPSILON, "{worst}");
    for exposure in [0.0, 1.5, -3.0] {
        let gpu_bytes = wf.tone_mapped(&gpu, exposure).unwrap();
        let cpu_bytes = accumulated.tone_mapped(exposure);
        let off = gpu_bytes
            .iter()
            .zip(&cpu_bytes)
            .flat_map(|(g, c)| (0..3).map(move |k| (g[k] as i32 - c[k] as i32).abs()))
            .max()
            .unwrap();
        println!("tone map at {exposure} stops: GPU and CPU bytes differ by at most {off}");
        // f32 exp and pow on two devices: a value on a rounding edge may land one step apart.
        assert!(off <= 1, "exposure {exposure}: {off}");
        assert!(gpu_bytes.iter().all(|p| p[3] == 255));
    }
}

/// The variance output predicts the noise: the mean per-pixel variance of the mean reported at
/// 16 spp is a quarter of that at 4 spp (σ²/n), and it matches the spread between two renders
/// with different seeds, E[(a − b)²] / 2, to 15 % (the estimate of either over 4096 pixels).
#[test]
fn reported_variance_matches_the_seed_to_seed_spread() {
    let Some(gpu) = gpu_for_tests("reported_variance_matches_the_seed_to_seed_spread") else {
        return;
    };
    let mut scene = sphere_scene(facet_material(ModelChoice::Ggx, None));
    scene.lights.push(facet_render::scene::Light::Directional {
        direction: Vec3::new(0.3, -0.4, -1.0).normalize(),
        irradiance: Vec3::splat(2.0),
    });
    let env = Environment::Constant(Vec3::new(0.5, 0.4, 0.3));
    let res = SceneResources::new(&gpu, &scene, Some(&env), ResourceConfig::standard()).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    let image = ImageConfig {
        width: SIZE,
        height: SIZE,
        wavefront: 1 << 16,
    };
    let mut wf = integrator
        .wavefront_with_variance(&gpu, &res, image)
        .unwrap();
    let mut at = |spp: u32, seed: u32| {
        wf.clear(&gpu);
        let c = SampleConfig {
            seed,
            ..config(spp).sampling
        };
        integrator
            .render_more(&gpu, &mut wf, &camera, &c, &mut |_| {})
            .unwrap();
        (wf.image(&gpu).unwrap(), wf.variance(&gpu).unwrap().unwrap())
    };
    let mean_var = |v: &Image| {
        v.pixels.iter().flatten().map(|&x| x as f64).sum::<f64>() / (3 * v.pixels.len()) as f64
    };
    let (a4, v4) = at(4, 0);
    let (a16, v16) = at(16, 0);
    let (b16, _) = at(16, 1);
    let spread = a16
        .pixels
        .iter()
        .flatten()
        .zip(b16.pixels.iter().flatten())
        .map(|(a, b)| 0.5 * (*a as f64 - *b as f64).powi(2))
        .sum::<f64>()
        / (3 * a16.pixels.len()) as f64;
    let (m4, m16) = (mean_var(&v4), mean_var(&v16));
    println!(
        "mean variance of a pixel: 4 spp {m4:.4e}, 16 spp {m16:.4e} (ratio {:.3}); seed-to-seed spread at 16 spp {spread:.4e}",
        m4 / m16
    );
    assert!(
        v16.pixels
            .iter()
            .flatten()
            .all(|v| v.is_finite() && *v >= 0.0)
    );
    assert!((m4 / m16 / 4.0 - 1.0).abs() < 0.15, "{m4} / {m16}");
    assert!((m16 / spread - 1.0).abs() < 0.15, "{m16} vs {spread}");
    assert!(a4.samples.iter().all(|&s| s == 4) && v16.samples.iter().all(|&s| s == 16));
    // Without the moments there is no variance.
    let plain = integrator.wavefront(&gpu, &res, image).unwrap();
    assert!(plain.variance(&gpu).unwrap().is_none());
}

/// Radiance a scene can hold in f32 does not overflow the film: a Lambertian sphere under a
/// constant sky of 0.8 · s, at 16 spp, s = 1e25 and 1e37, gives the image and variance of the
/// same scene at s = 1 scaled back: the mean times s within 1e-5 (each sample scaled by s rounds once, the running
/// means round alike), the variance times s² within 1e-4 plus 1e-6 of the squared mean (r² − m²
/// of f32 r and m cancels to about 2⁻²³ m²), or `f32::MAX` where that is past what an image
/// holds (saturated, never infinite). At s = 1e38 every pixel is finite, and every pixel that
/// sees only the sky is 0.8e38 (a sum of its 16 samples overflowed f32 before, as did their
/// squares at 1e25); the sphere's pixels there lose samples whose path overflowed inside the
/// integrator (the sky's radiance over a direction's density, past 3.4e38), which it drops.
#[test]
fn bright_skies_scale_the_image_without_overflow() {
    let Some(gpu) = gpu_for_tests("bright_skies_scale_the_image_without_overflow") else {
        return;
    };
    let scene = sphere_scene(lambert([0.5, 0.4, 0.3]));
    let camera = CameraFrame::new(&scene.camera).unwrap();
    let render = |s: f32| {
        let env = Environment::Constant(Vec3::splat(0.8 * s));
        let res =
            SceneResources::new(&gpu, &scene, Some(&env), ResourceConfig::standard()).unwrap();
        let integrator = Integrator::new(&gpu.device, &res).unwrap();
        let mut wf = integrator
            .wavefront_with_variance(&gpu, &res, config(16).image)
            .unwrap();
        integrator
            .render_more(&gpu, &mut wf, &camera, &config(16).sampling, &mut |_| {})
            .unwrap();
        (wf.image(&gpu).unwrap(), wf.variance(&gpu).unwrap().unwrap())
    };
    let (image, variance) = render(1.0);
    assert!(variance.pixels.iter().flatten().any(|&v| v > 0.0));
    let (sky, _) = render(1e38);
    for (got, want) in sky.pixels.iter().zip(&image.pixels) {
        assert!(got.iter().all(|v| v.is_finite()), "{got:?}");
        if *want == [0.8; 3] {
            assert!(
                got.iter().all(|&v| (v as f64 / 0.8e38 - 1.0).abs() < 1e-6),
                "{got:?}"
            );
        }
    }
    assert!(
        image.pixels.contains(&[0.8; 3]),
        "no pixel sees the sky alone"
    );
    for s in [1e25f32, 1e37] {
        let (bright, bright_var) = render(s);
        let s = s as f64;
        let close = |got: f32, want: f64, tol: f64| {
            (got as f64 - want).abs() <= tol * want.abs() + f64::from(f32::MIN_POSITIVE)
        };
        for (k, (got, want)) in bright.pixels.iter().zip(&image.pixels).enumerate() {
            for c in 0..3 {
                assert!(
                    got[c].is_finite() && close(got[c], s * want[c] as f64, 1e-5),
                    "s = {s:e}, pixel {k}: {} against {}",
                    got[c],
                    s * want[c] as f64
                );
            }
        }
        let mut saturated = 0;
        let pixels = bright_var.pixels.iter().zip(&variance.pixels);
        for ((got, want), m) in pixels.zip(&bright.pixels) {
            for c in 0..3 {
                let want = s * s * want[c] as f64;
                if want > f32::MAX as f64 {
                    assert_eq!(got[c], f32::MAX);
                    saturated += 1;
                } else {
                    let slack = 1e-4 * want + 1e-6 * (m[c] as f64).powi(2);
                    assert!(
                        (got[c] as f64 - want).abs() <= slack,
                        "{} against {want}",
                        got[c]
                    );
                }
            }
        }
        println!("s = {s:e}: {saturated} variances past f32::MAX, saturated");
    }
}
