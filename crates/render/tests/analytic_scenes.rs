//! The GPU renderer against closed forms and independent CPU estimates: punctual, spot,
//! directional and area lights on a Lambertian plane, a shadow, an environment map through each
//! sampling strategy, a texture, the glTF metallic-roughness BRDF and a rotated anisotropic GGX.
//!
//! Every comparison is by region (blocks of pixels, or bands of θo on a sphere). Each scene is
//! rendered twice with different seeds; a region's estimate is the mean of both and its standard
//! error comes from the spread of their per-pixel difference, so the tolerance follows the sample
//! count: |GPU − reference| ≤ Z · se + BIAS · reference (+ a tiny absolute floor), with Z = 5
//! (a pass-by-chance miss about once in 10^6 regions) and BIAS = 1 % for what the references
//! leave out: f32 against f64, the tessellated sphere against the exact one, the sub-pixel grid
//! against the GPU's random pixel positions.

mod common;

use common::renders::{SIZE, direct_config, lambert, sphere_scene};
use facet_fit::Brdf;
use facet_fit::export::rgl::{BsdfResolution, rgl_tensor};
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::model::microfacet::MicrofacetBrdf;
use facet_fit::model::microfacet::{AnalyticNdf, NdfKind, correlation, g2};
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::rgl::RglBsdf;
use facet_gpu::{Gpu, gpu_for_tests};
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{
    Camera, Environment, EnvironmentMap, FacetMaterial, Light, Material, MeasuredMaterial,
    Measurement, Scene, Texture,
};
use facet_render::{
    Image, Integrator, NdfSampling, RenderConfig, ResourceConfig, SampleConfig, SceneResources,
    Sequence, Strategy,
};
use glam::{DVec2, DVec3, Vec3, Vec4};
use std::f64::consts::PI;
use std::sync::Arc;

const Z: f64 = 5.0;
const BIAS: f64 = 0.01;
/// Sub-pixel grid of the CPU references (n × n points per pixel).
const SUB: u32 = 4;

// ---- scenes and renders ---------------------------------------------------------------------

const FLOOR_ALBEDO: [f32; 3] = [0.5, 0.6, 0.7];

/// The plane y = 0, |x|, |z| ≤ 3, facing +Y, Lambertian, seen from straight above at `height`.
fn floor_scene(height: f32, yfov_deg: f32) -> Scene {
    let mut s = Scene {
        materials: vec![lambert(FLOOR_ALBEDO)],
        camera: Camera {
            position: Vec3::new(0.0, height, 0.0),
            forward: Vec3::NEG_Y,
            up: Vec3::NEG_Z,
            yfov: yfov_deg.to_radians(),
        },
        ..Default::default()
    };
    s.add_quad(
        Vec3::new(-3.0, 0.0, 3.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -6.0),
        1.0,
        0,
    );
    s
}

/// The scene rendered with seeds 0 and 1.
fn render_twice(
    gpu: &Gpu,
    scene: &Scene,
    env: Option<&Environment>,
    config: RenderConfig,
) -> [Image; 2] {
    let res = SceneResources::new(gpu, scene, env, ResourceConfig::standard()).unwrap();
    let integrator = Integrator::new(&gpu.device, &res).unwrap();
    let camera = CameraFrame::new(&scene.camera).unwrap();
    [0, 1].map(|seed| {
        let (image, _) = integrator
            .render(
                gpu,
                &res,
                &camera,
                &RenderConfig {
                    sampling: SampleConfig {
                        seed,
                        ..config.sampling
                    },
                    ..config
                },
                &mut |_| {},
            )
            .unwrap();
        assert!(image.pixels.iter().flatten().all(|v| v.is_finite()));
        image
    })
}

// ---- the CPU side -----------------------------------------------------------------------------

/// The camera ray through image position (fx, fy) (pixels, row 0 at the top), as the generate
/// stage makes it.
fn camera_ray(scene: &Scene, fx: f64, fy: f64) -> (DVec3, DVec3) {
    let c = CameraFrame::new(&scene.camera).unwrap();
    let tan_half = (0.5 * c.yfov as f64).tan();
    let ndc = DVec2::new(2.0 * fx / SIZE as f64 - 1.0, 1.0 - 2.0 * fy / SIZE as f64);
    let d = c.forward.as_dvec3()
        + ndc.x * tan_half * c.right.as_dvec3()
        + ndc.y * tan_half * c.up.as_dvec3();
    (c.position.as_dvec3(), d.normalize())
}

/// Per pixel, the mean of `radiance(origin, direction)` over a SUB × SUB grid in the pixel, or
/// None where any grid point has none (pixels the comparison leaves out).
fn reference(
    scene: &Scene,
    radiance: impl Fn(DVec3, DVec3) -> Option<DVec3>,
) -> Vec<Option<DVec3>> {
    let mut out = Vec::with_capacity((SIZE * SIZE) as usize);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let mut sum = Some(DVec3::ZERO);
            for j in 0..SUB {
                for i in 0..SUB {
                    let fx = x as f64 + (i as f64 + 0.5) / SUB as f64;
                    let fy = y as f64 + (j as f64 + 0.5) / SUB as f64;
                    let (o, d) = camera_ray(scene, fx, fy);
                    sum = sum.zip(radiance(o, d)).map(|(s, l)| s + l);
                }
            }
            out.push(sum.map(|s| s / (SUB * SUB) as f64));
        }
    }
    out
}

/// Where a ray meets the plane y = h, if ahead of it within |x|, |z| ≤ half-extents.
fn hit_plane_y(o: DVec3, d: DVec3, h: f64, x: (f64, f64), z: (f64, f64)) -> Option<(f64, DVec3)> {
    let t = (h - o.y) / d.y;
    let p = o + t * d;
    (t > 0.0 && (x.0..=x.1).contains(&p.x) && (z.0..=z.1).contains(&p.z)).then_some((t, p))
}

/// Where a ray from `o` meets the unit sphere at the origin: the point (= normal), or None
/// unless the view angle there is below `max_deg` (the silhouette, where the tessellation and
/// the exact sphere differ most, is left out).
fn hit_unit_sphere(o: DVec3, d: DVec3, max_deg: f64) -> Option<DVec3> {
    let b = o.dot(d);
    let disc = b * b - (o.length_squared() - 1.0);
    if disc <= 0.0 {
        return None;
    }
    let n = (o + (-b - disc.sqrt()) * d).normalize();
    (n.dot(-d) > max_deg.to_radians().cos()).then_some(n)
}

/// The sphere's shading frame at normal n, as `add_uv_sphere` lays it out: n = (sin θ cos φ,
/// cos θ, sin θ sin φ), tangent ∂/∂φ = (−sin φ, 0, cos φ), bitangent n × t.
fn sphere_frame(n: DVec3) -> (DVec3, DVec3, DVec3) {
    let phi = n.z.atan2(n.x);
    let t = DVec3::new(-phi.sin(), 0.0, phi.cos());
    (t, n.cross(t), n)
}

fn local(frame: (DVec3, DVec3, DVec3), w: DVec3) -> DVec3 {
    DVec3::new(w.dot(frame.0), w.dot(frame.1), w.dot(frame.2))
}

fn dv(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

// ---- the comparison ---------------------------------------------------------------------------

/// Pools pixels into regions (`region(x, y)`: None leaves a pixel out) and checks every region
/// with at least `min_pixels` against the reference. Returns the worst |error| / allowance.
fn check(
    label: &str,
    images: &[Image; 2],
    reference: &[Option<DVec3>],
    region: impl Fn(u32, u32) -> Option<usize>,
    min_pixels: usize,
) -> Result<f64, String> {
    #[derive(Clone, Default)]
    struct Acc {
        n: usize,
        gpu: DVec3,
        cpu: DVec3,
        diff2: DVec3,
    }
    let mut acc: Vec<Acc> = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            let (Some(r), Some(k)) = (reference[i], region(x, y)) else {
                continue;
            };
            if acc.len() <= k {
                acc.resize(k + 1, Acc::default());
            }
            let (a, b) = (dv(images[0].pixels[i]), dv(images[1].pixels[i]));
            let e = &mut acc[k];
            e.n += 1;
            e.gpu += 0.5 * (a + b);
            e.cpu += r;
            e.diff2 += (a - b) * (a - b);
        }
    }
    let mut worst = 0.0f64;
    let mut problems = Vec::new();
    let mut checked = 0;
    for (k, e) in acc.iter().enumerate().filter(|(_, e)| e.n >= min_pixels) {
        checked += 1;
        let n = e.n as f64;
        let (gpu, cpu) = (e.gpu / n, e.cpu / n);
        // Var(mean of (a+b)/2 over n pixels) = Var(a − b) / (4 n), Var(a − b) pooled.
        let v = e.diff2 / n / (4.0 * n);
        let se = DVec3::new(v.x.sqrt(), v.y.sqrt(), v.z.sqrt());
        for c in 0..3 {
            let allowed = Z * se[c] + BIAS * cpu[c].abs() + 1e-5;
            let ratio = (gpu[c] - cpu[c]).abs() / allowed;
            worst = worst.max(ratio);
            if ratio > 1.0 {
                problems.push(format!(
                    "region {k} channel {c}: GPU {:.5} vs CPU {:.5} (se {:.5}, {} pixels)",
                    gpu[c], cpu[c], se[c], e.n
                ));
            }
        }
    }
    println!("{label}: {checked} regions, worst |error| / allowance {worst:.3}");
    assert!(checked > 0, "{label}: no region to check");
    if problems.is_empty() {
        Ok(worst)
    } else {
        Err(format!("{label}:\n{}", problems.join("\n")))
    }
}

/// 8 × 8-pixel blocks.
fn blocks(x: u32, y: u32) -> Option<usize> {
    Some(((y / 8) * (SIZE / 8) + x / 8) as usize)
}

/// Asserts that the check passes, and that it fails for a reference of a broken renderer:
/// the test has the power to see the error it guards against.
fn check_with_power(
    label: &str,
    images: &[Image; 2],
    good: &[Option<DVec3>],
    broken: &[Option<DVec3>],
    region: impl Fn(u32, u32) -> Option<usize> + Copy,
    min_pixels: usize,
) {
    if let Err(e) = check(label, images, good, region, min_pixels) {
        panic!("{e}");
    }
    assert!(
        check(
            &format!("{label} (broken reference)"),
            images,
            broken,
            region,
            min_pixels
        )
        .is_err(),
        "{label}: the check cannot tell the broken reference from the image"
    );
}

// ---- punctual lights --------------------------------------------------------------------------

const LIGHT_POS: DVec3 = DVec3::new(0.3, 1.0, -0.2);
const INTENSITY: DVec3 = DVec3::new(10.0, 5.0, 2.0);

/// A Lambertian plane under a point light: L = ρ/π · I cos θ / r².
#[test]
fn point_light_on_a_plane_falls_off_as_cos_over_r2() {
    let Some(gpu) = gpu_for_tests("point_light_on_a_plane_falls_off_as_cos_over_r2") else {
        return;
    };
    let mut scene = floor_scene(2.5, 60.0);
    scene.lights.push(Light::Point {
        position: LIGHT_POS.as_vec3(),
        intensity: INTENSITY.as_vec3(),
    });
    let images = render_twice(&gpu, &scene, None, direct_config(16, Strategy::Mis));
    let rho = dv(FLOOR_ALBEDO) / PI;
    let expect = |power: i32| {
        reference(&scene, |o, d| {
            let (_, p) = hit_plane_y(o, d, 0.0, (-3.0, 3.0), (-3.0, 3.0))?;
            let v = LIGHT_POS - p;
            let r = v.length();
            Some(rho * INTENSITY * (v.y / r) / r.powi(power))
        })
    };
    check_with_power("point light", &images, &expect(2), &expect(1), blocks, 32);
}

/// A spot light pointing down: glTF's falloff t², t = (cos α − cos outer) / (cos inner − cos
/// outer) clamped to [0, 1], times I cos θ / r².
#[test]
fn spot_light_on_a_plane_has_the_gltf_falloff() {
    let Some(gpu) = gpu_for_tests("spot_light_on_a_plane_has_the_gltf_falloff") else {
        return;
    };
    let (inner, outer) = (15f64.to_radians(), 30f64.to_radians());
    let pos = DVec3::new(0.1, 1.2, 0.0);
    let axis = DVec3::new(0.2, -1.0, 0.1).normalize();
    let mut scene = floor_scene(2.0, 60.0);
    scene.lights.push(Light::Spot {
        position: pos.as_vec3(),
        direction: axis.as_vec3(),
        intensity: INTENSITY.as_vec3(),
        inner_cone: inner as f32,
        outer_cone: outer as f32,
    });
    let images = render_twice(&gpu, &scene, None, direct_config(16, Strategy::Mis));
    let rho = dv(FLOOR_ALBEDO) / PI;
    let expect = |falloff: &dyn Fn(f64) -> f64| {
        reference(&scene, |o, d| {
            let (_, p) = hit_plane_y(o, d, 0.0, (-3.0, 3.0), (-3.0, 3.0))?;
            let v = pos - p;
            let r = v.length();
            let cos_axis = (-v / r).dot(axis);
            Some(rho * INTENSITY * falloff(cos_axis) * (v.y / r) / (r * r))
        })
    };
    let gltf = |c: f64| {
        let t = ((c - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
        t * t
    };
    // Broken: a hard cone at the outer angle.
    let hard = |c: f64| if c >= outer.cos() { 1.0 } else { 0.0 };
    check_with_power(
        "spot light",
        &images,
        &expect(&gltf),
        &expect(&hard),
        blocks,
        32,
    );
    // The cone's edge is in the picture: some blocks are dark, some lit.
    let m = images[0].mean_where(|x, y| x < 8 && y < 8)[0];
    assert!(m < 1e-6, "a corner outside the cone is lit: {m}");
}

/// A directional light at 45° and a square occluder 0.5 above the plane: the shadow is the
/// occluder shifted by 0.5 along the light, black; everything lit has L = ρ/π · E cos 45°.
#[test]
fn directional_light_casts_the_occluders_shadow() {
    let Some(gpu) = gpu_for_tests("directional_light_casts_the_occluders_shadow") else {
        return;
    };
    let h = 0.5;
    let (ox, oz) = ((-0.6, -0.1), (-0.4, 0.4));
    let mut scene = floor_scene(3.0, 50.0);
    scene.add_quad(
        Vec3::new(ox.0 as f32, h as f32, oz.1 as f32),
        Vec3::new((ox.1 - ox.0) as f32, 0.0, 0.0),
        Vec3::new(0.0, 0.0, (oz.0 - oz.1) as f32),
        1.0,
        0,
    );
    let travel = DVec3::new(1.0, -1.0, 0.0).normalize();
    let irradiance = DVec3::new(3.0, 2.0, 1.0);
    scene.lights.push(Light::Directional {
        direction: travel.as_vec3(),
        irradiance: irradiance.as_vec3(),
    });
    let images = render_twice(&gpu, &scene, None, direct_config(16, Strategy::Mis));
    let lit = dv(FLOOR_ALBEDO) / PI * irradiance * (-travel).y;
    let shade = |with_shadows: bool| {
        move |o: DVec3, d: DVec3| {
            if hit_plane_y(o, d, h, ox, oz).is_some() {
                return Some(lit);
            }
            let (_, p) = hit_plane_y(o, d, 0.0, (-3.0, 3.0), (-3.0, 3.0))?;
            let blocked = hit_plane_y(p, -travel, h, ox, oz).is_some();
            Some(if blocked && with_shadows {
                DVec3::ZERO
            } else {
                lit
            })
        }
    };
    let good = reference(&scene, shade(true));
    check_with_power(
        "directional light and shadow",
        &images,
        &good,
        &reference(&scene, shade(false)),
        blocks,
        32,
    );
    // Pixel by pixel, away from the shadow's edge (a pixel and its neighbours all in the umbra,
    // or all lit): the umbra is black, the rest is lit.
    let class = |x: i64, y: i64| {
        let r = good.get((y * SIZE as i64 + x) as usize)?.as_ref()?;
        (0..SIZE as i64).contains(&x).then_some(())?;
        Some(if r.x == 0.0 {
            0
        } else if (r.x - lit.x).abs() < 1e-12 {
            1
        } else {
            2
        })
    };
    let (mut dark, mut bright) = (0, 0);
    for y in 0..SIZE as i64 {
        for x in 0..SIZE as i64 {
            let c = class(x, y);
            let interior = (-1..=1).all(|j| (-1..=1).all(|i| class(x + i, y + j) == c));
            let g = images[0].pixels[(y * SIZE as i64 + x) as usize][0] as f64;
            match c {
                Some(0) if interior => {
                    assert!(g == 0.0, "pixel ({x}, {y}) in the umbra is {g}");
                    dark += 1;
                }
                Some(1) if interior => {
                    assert!(
                        (g / lit.x - 1.0).abs() < 1e-3,
                        "lit pixel ({x}, {y}) is {g}, not {}",
                        lit.x
                    );
                    bright += 1;
                }
                _ => {}
            }
        }
    }
    println!("umbra pixels {dark}, lit pixels {bright}");
    assert!(dark > 100 && bright > 1000, "{dark} {bright}");
}

// ---- an area light ------------------------------------------------------------------------------

/// Irradiance at p (normal n) from a uniformly emitting polygon of radiance 1: Lambert's
/// formula E = ½ |Σ Θᵢ n · (rᵢ × rᵢ₊₁) / |rᵢ × rᵢ₊₁||, rᵢ the unit vectors to the vertices and
/// Θᵢ the angle between consecutive ones (Lambert 1760; Arvo 1995, eq. 2).
fn polygon_irradiance(p: DVec3, n: DVec3, vertices: &[DVec3]) -> f64 {
    let r: Vec<DVec3> = vertices.iter().map(|v| (*v - p).normalize()).collect();
    let mut sum = 0.0;
    for i in 0..r.len() {
        let (a, b) = (r[i], r[(i + 1) % r.len()]);
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(a.cross(b).normalize());
    }
    0.5 * sum.abs()
}

/// An emissive rectangle 1 above the plane, facing it: L = ρ/π · Le · E(p), E the form-factor
/// integral in closed form.
#[test]
fn emissive_quad_lights_the_plane_by_its_form_factor() {
    let Some(gpu) = gpu_for_tests("emissive_quad_lights_the_plane_by_its_form_factor") else {
        return;
    };
    let le = DVec3::new(4.0, 3.0, 2.0);
    let (corner, eu, ev) = (
        DVec3::new(-0.3, 1.0, -0.2),
        DVec3::new(0.6, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.4),
    );
    // Looking down from below the light: the camera sees only the plane.
    let mut scene = floor_scene(0.9, 90.0);
    scene.materials.push(Material {
        name: "emitter".into(),
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        emissive: le.as_vec3(),
        specular: 0.0,
        ..Default::default()
    });
    scene.add_quad(corner.as_vec3(), eu.as_vec3(), ev.as_vec3(), 1.0, 1);
    let images = render_twice(&gpu, &scene, None, direct_config(64, Strategy::Mis));
    let quad = [corner, corner + eu, corner + eu + ev, corner + ev];
    let rho = dv(FLOOR_ALBEDO) / PI;
    let expect = |scale: f64| {
        reference(&scene, |o, d| {
            let (_, p) = hit_plane_y(o, d, 0.0, (-3.0, 3.0), (-3.0, 3.0))?;
            Some(rho * le * polygon_irradiance(p, DVec3::Y, &quad) * scale)
        })
    };
    // Broken: the light counted twice (MIS weights that do not sum to one).
    check_with_power(
        "emissive quad",
        &images,
        &expect(1.0),
        &expect(1.1),
        blocks,
        32,
    );
}

// ---- an environment map, each strategy ---------------------------------------------------------

const ENV_W: u32 = 32;
const ENV_H: u32 = 16;

/// A sky brighter upward, a warm blob and a blue cast, smooth enough for BSDF sampling alone.
fn sky_texels() -> Vec<Vec3> {
    let blob = DVec3::new(0.6, 0.5, 0.62).normalize();
    (0..ENV_W * ENV_H)
        .map(|i| {
            let (x, y) = (i % ENV_W, i / ENV_W);
            let d = facet_render::scene::environment::uv_to_direction(glam::Vec2::new(
                (x as f32 + 0.5) / ENV_W as f32,
                (y as f32 + 0.5) / ENV_H as f32,
            ))
            .as_dvec3();
            let sky = 0.3 + 1.2 * d.y.max(0.0);
            let sun = 6.0 * (-(1.0 - d.dot(blob)) / 0.08).exp();
            Vec3::new(
                (sky + sun) as f32,
                (sky + 0.7 * sun) as f32,
                (1.3 * sky + 0.3 * sun) as f32,
            )
        })
        .collect()
}

/// ∫ L(ω) max(0, n·ω) dω over the piecewise-constant map, by a 4 × 4 midpoint rule in (φ, cos θ)
/// inside every texel (the map is constant per texel; only the cosine varies).
fn env_irradiance(texels: &[Vec3], n: DVec3) -> DVec3 {
    const K: u32 = 4;
    let mut e = DVec3::ZERO;
    for y in 0..ENV_H {
        let (t0, t1) = (
            PI * y as f64 / ENV_H as f64,
            PI * (y + 1) as f64 / ENV_H as f64,
        );
        for x in 0..ENV_W {
            let l = texels[(y * ENV_W + x) as usize].as_dvec3();
            let mut w = 0.0;
            for j in 0..K {
                // Equal steps in cos θ are equal solid angles.
                let c = t0.cos() + (t1.cos() - t0.cos()) * (j as f64 + 0.5) / K as f64;
                let s = (1.0 - c * c).max(0.0).sqrt();
                for i in 0..K {
                    let phi = 2.0 * PI * (x as f64 + (i as f64 + 0.5) / K as f64) / ENV_W as f64;
                    let d = DVec3::new(s * phi.cos(), c, s * phi.sin());
                    w += n.dot(d).max(0.0);
                }
            }
            let d_omega = 2.0 * PI / ENV_W as f64 * (t0.cos() - t1.cos()) / (K * K) as f64;
            e += l * w * d_omega;
        }
    }
    e
}

/// A Lambertian sphere under a non-constant map: L(n) = ρ/π ∫ L_env max(0, n·ω) dω. MIS, light
/// sampling alone and BSDF sampling alone each converge to the CPU quadrature.
#[test]
fn environment_map_on_a_lambertian_sphere_each_strategy() {
    let Some(gpu) = gpu_for_tests("environment_map_on_a_lambertian_sphere_each_strategy") else {
        return;
    };
    let texels = sky_texels();
    let map = EnvironmentMap::from_texels("sky".into(), ENV_W, ENV_H, texels.clone()).unwrap();
    let env = Environment::Map(Arc::new(map));
    let albedo = [0.8, 0.7, 0.6];
    let scene = sphere_scene(lambert(albedo));
    let rho = dv(albedo) / PI;
    let good = reference(&scene, |o, d| {
        let n = hit_unit_sphere(o, d, 70.0)?;
        Some(rho * env_irradiance(&texels, n))
    });
    // Broken: the map's texels read upside down.
    let flipped: Vec<Vec3> = (0..ENV_W * ENV_H)
        .map(|i| texels[((ENV_H - 1 - i / ENV_W) * ENV_W + i % ENV_W) as usize])
        .collect();
    let broken = reference(&scene, |o, d| {
        let n = hit_unit_sphere(o, d, 70.0)?;
        Some(rho * env_irradiance(&flipped, n))
    });
    let mut noise = Vec::new();
    for strategy in [Strategy::Mis, Strategy::Light, Strategy::Bsdf] {
        let images = render_twice(&gpu, &scene, Some(&env), direct_config(32, strategy));
        check_with_power(
            &format!("environment map, {strategy:?}"),
            &images,
            &good,
            &broken,
            blocks,
            16,
        );
        noise.push(images[0].rmse(&images[1]));
    }
    println!("seed-to-seed RMS difference, MIS / light / BSDF: {noise:.4?}");
}

/// The same sphere and map with Owen-scrambled Sobol points (`Sequence::Sobol`): it converges to
/// the same CPU quadrature (the scrambling keeps every sample uniform, so the estimate is
/// unbiased), and at 32 spp its seed-to-seed RMS difference is below 0.7 of the independent
/// numbers' (a scrambled (0, m, 2)-net's variance is o(1/N) for a smooth integrand, MC's 1/N;
/// here the pairs are padded together, so only the parts of each pair stratify — measured
/// 0.33 on lavapipe).
#[test]
fn environment_map_on_a_lambertian_sphere_with_sobol_points() {
    let Some(gpu) = gpu_for_tests("environment_map_on_a_lambertian_sphere_with_sobol_points")
    else {
        return;
    };
    let texels = sky_texels();
    let map = EnvironmentMap::from_texels("sky".into(), ENV_W, ENV_H, texels.clone()).unwrap();
    let env = Environment::Map(Arc::new(map));
    let albedo = [0.8, 0.7, 0.6];
    let scene = sphere_scene(lambert(albedo));
    let rho = dv(albedo) / PI;
    let good = reference(&scene, |o, d| {
        let n = hit_unit_sphere(o, d, 70.0)?;
        Some(rho * env_irradiance(&texels, n))
    });
    // Broken: the albedo 5 % too bright.
    let broken = reference(&scene, |o, d| {
        let n = hit_unit_sphere(o, d, 70.0)?;
        Some(1.05 * rho * env_irradiance(&texels, n))
    });
    let config = |sequence| {
        let mut c = direct_config(32, Strategy::Mis);
        c.sampling.sequence = sequence;
        c
    };
    let sobol = render_twice(&gpu, &scene, Some(&env), config(Sequence::Sobol));
    check_with_power("environment map, Sobol", &sobol, &good, &broken, blocks, 16);
    let random = render_twice(&gpu, &scene, Some(&env), config(Sequence::Random));
    let (s, r) = (sobol[0].rmse(&sobol[1]), random[0].rmse(&random[1]));
    println!("seed-to-seed RMS difference at 32 spp: Sobol {s:.5}, random {r:.5}");
    assert!(s < 0.7 * r, "Sobol {s}, random {r}");
}

// ---- a texture ----------------------------------------------------------------------------------

/// sRGB-encoded byte → linear (IEC 61966-2-1).
fn srgb_to_linear(b: u8) -> f64 {
    let v = b as f64 / 255.0;
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// A plane with a 4 × 4 sRGB base-colour texture under a constant sky of radiance 1, BSDF
/// sampling alone: every sample is ρ(uv) exactly, so the pixels are the bilinearly filtered,
/// decoded texels.
#[test]
fn textured_plane_returns_its_texels() {
    let Some(gpu) = gpu_for_tests("textured_plane_returns_its_texels") else {
        return;
    };
    const T: u32 = 4;
    let texels: Vec<[u8; 4]> = (0..T * T)
        .map(|i| {
            let (x, y) = (i % T, i / T);
            [
                (40 + 60 * x) as u8,
                (230 - 50 * y) as u8,
                ((x * 7 + y * 13) % 5 * 50) as u8,
                255,
            ]
        })
        .collect();
    // The plane fills the frame exactly: UV (s, t) ∈ [0, 1]² over |x|, |z| ≤ 1, seen from 1
    // at 90°.
    let mut scene = Scene {
        materials: vec![Material {
            base_color_texture: Some(0),
            base_color: Vec4::ONE,
            ..lambert([1.0; 3])
        }],
        textures: vec![Texture {
            name: "checker".into(),
            width: T,
            height: T,
            texels: texels.clone(),
            srgb: true,
        }],
        camera: Camera {
            position: Vec3::new(0.0, 1.0, 0.0),
            forward: Vec3::NEG_Y,
            up: Vec3::NEG_Z,
            yfov: 90f32.to_radians(),
        },
        ..Default::default()
    };
    scene.add_quad(
        Vec3::new(-1.0, 0.0, 1.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -2.0),
        1.0,
        0,
    );
    let env = Environment::Constant(Vec3::ONE);
    let images = render_twice(&gpu, &scene, Some(&env), direct_config(8, Strategy::Bsdf));
    // Bilinear filtering with wrap-around, texel centres at (i + ½) / T.
    let texel = |x: i64, y: i64, srgb: bool| {
        let t = texels[(y.rem_euclid(T as i64) * T as i64 + x.rem_euclid(T as i64)) as usize];
        let c = |b: u8| {
            if srgb {
                srgb_to_linear(b)
            } else {
                b as f64 / 255.0
            }
        };
        DVec3::new(c(t[0]), c(t[1]), c(t[2]))
    };
    let sample = |uv: DVec2, srgb: bool| {
        let (x, y) = (uv.x * T as f64 - 0.5, uv.y * T as f64 - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = texel(x0, y0, srgb).lerp(texel(x0 + 1, y0, srgb), fx);
        let b = texel(x0, y0 + 1, srgb).lerp(texel(x0 + 1, y0 + 1, srgb), fx);
        a.lerp(b, fy)
    };
    let expect = |srgb: bool| {
        reference(&scene, |o, d| {
            let (_, p) = hit_plane_y(o, d, 0.0, (-1.0, 1.0), (-1.0, 1.0))?;
            // add_quad: corner (−1, 0, 1), s along +x, t along −z.
            Some(sample(
                DVec2::new((p.x + 1.0) / 2.0, (1.0 - p.z) / 2.0),
                srgb,
            ))
        })
    };
    // Broken: the sRGB texels used as linear values.
    check_with_power(
        "textured plane",
        &images,
        &expect(true),
        &expect(false),
        blocks,
        32,
    );
    // At a texel centre the texel itself comes back: the centres fall on pixel corners, and the
    // four pixels around one (± h = 1/16 texel) average to the texel up to the filter's kink
    // there, at most the mean |slope| on either side times h/2 along each axis.
    let h = T as f64 / SIZE as f64;
    for (tx, ty) in [(0u32, 0u32), (3, 0), (1, 2), (3, 3)] {
        // Image x runs along s (+x), image y against t (row 0 is z = −1, t = 1).
        let (cx, cy) = (
            (tx * 2 + 1) * SIZE / (2 * T),
            SIZE - (ty * 2 + 1) * SIZE / (2 * T),
        );
        let g = [(cx - 1, cy - 1), (cx, cy - 1), (cx - 1, cy), (cx, cy)]
            .iter()
            .map(|&(x, y)| dv(images[0].pixels[(y * SIZE + x) as usize]))
            .sum::<DVec3>()
            / 4.0;
        let (x, y) = (tx as i64, ty as i64);
        let want = texel(x, y, true);
        let slope = |a: DVec3, b: DVec3| 0.5 * ((a - want).abs() + (b - want).abs());
        let kink = (slope(texel(x - 1, y, true), texel(x + 1, y, true))
            + slope(texel(x, y - 1, true), texel(x, y + 1, true)))
            * (0.5 * h);
        println!("texel ({tx}, {ty}): GPU {g:.4?}, decoded {want:.4?}, kink bound {kink:.4?}");
        assert!(
            ((g - want).abs() - kink).max_element() < 0.002,
            "{g} vs {want} ± {kink}"
        );
    }
}

// ---- BRDFs on a sphere ------------------------------------------------------------------------

/// Directional albedo E(θo) = ∫ f(ωi, ωo) cos θi dωi of an isotropic BRDF in the local frame,
/// by the midpoint rule in (cos θi, φi) on a 384 × 384 grid, tabulated every 2° of θo.
fn albedo_table(f: impl Fn(DVec3, DVec3) -> DVec3 + Sync) -> Vec<DVec3> {
    const N: usize = 384;
    (0..=45)
        .map(|k| {
            let t = (2.0 * k as f64).to_radians();
            let wo = DVec3::new(t.sin(), 0.0, t.cos());
            let mut e = DVec3::ZERO;
            for i in 0..N {
                let c = (i as f64 + 0.5) / N as f64;
                let s = (1.0 - c * c).sqrt();
                for j in 0..N {
                    let phi = 2.0 * PI * (j as f64 + 0.5) / N as f64;
                    let wi = DVec3::new(s * phi.cos(), s * phi.sin(), c);
                    e += f(wi, wo) * c;
                }
            }
            e * (2.0 * PI / (N * N) as f64)
        })
        .collect()
}

fn interpolate(table: &[DVec3], theta: f64) -> DVec3 {
    let x = theta.to_degrees() / 2.0;
    let i = (x as usize).min(table.len() - 2);
    table[i].lerp(table[i + 1], x - i as f64)
}

/// θo bands of 5° on the sphere (the furnace depends on θo only).
fn theta_bands(scene: &Scene) -> impl Fn(u32, u32) -> Option<usize> + Copy + '_ {
    move |x, y| {
        let (o, d) = camera_ray(scene, x as f64 + 0.5, y as f64 + 0.5);
        let n = hit_unit_sphere(o, d, 70.0)?;
        Some((n.dot(-d).acos().to_degrees() / 5.0) as usize)
    }
}

/// glTF 2.0 metallic-roughness (Appendix B) with KHR_materials_specular's weight s, written
/// out from the specification: α = roughness², F(c) = F0 + (1 − F0)(1 − c)⁵ per lobe,
/// f = (1 − metallic)(1 − s F_d) ρ/π + [mix(s F_d, F_m, metallic)] D G2 / (4 cos θi cos θo)
/// with F_d the dielectric's (F0 = 0.04) and F_m the metal's (F0 = base colour), GGX D and the
/// correlated Smith G2 of design.md.
fn gltf_brdf(base: DVec3, metallic: f64, roughness: f64, s: f64, wi: DVec3, wo: DVec3) -> DVec3 {
    let ndf = AnalyticNdf::isotropic(NdfKind::Ggx, (roughness * roughness).max(1e-3));
    let h = (wi + wo).normalize();
    let c = wi.dot(h);
    let schlick = |f0: DVec3| f0 + (DVec3::ONE - f0) * (1.0 - c).powi(5);
    let fd = schlick(DVec3::splat(0.04)).x * s;
    let phi = {
        let (a, b) = (wi.truncate(), wo.truncate());
        if a.length() < 1e-9 || b.length() < 1e-9 {
            0.0
        } else {
            (a.dot(b) / (a.length() * b.length()))
                .clamp(-1.0, 1.0)
                .acos()
        }
    };
    let spec =
        ndf.d(h) * g2(ndf.lambda(wi), ndf.lambda(wo), correlation(phi)) / (4.0 * wi.z * wo.z);
    let f_spec = DVec3::splat(fd).lerp(schlick(base), metallic);
    (1.0 - metallic) * (1.0 - fd) * base / PI + f_spec * spec
}

/// A glTF metallic-roughness sphere in a white furnace renders its directional albedo, computed
/// on the CPU from the specification's formula: a metal, and a dielectric with its diffuse base.
#[test]
fn metallic_roughness_sphere_matches_the_cpu_albedo() {
    let Some(gpu) = gpu_for_tests("metallic_roughness_sphere_matches_the_cpu_albedo") else {
        return;
    };
    let env = Environment::Constant(Vec3::ONE);
    for (base, metallic, roughness) in [([0.9, 0.6, 0.3], 1.0, 0.5), ([0.2, 0.5, 0.8], 0.0, 0.6)] {
        let material = Material {
            name: "mr".into(),
            base_color: Vec4::new(base[0], base[1], base[2], 1.0),
            metallic,
            roughness,
            specular: 1.0,
            ..Default::default()
        };
        let scene = sphere_scene(material);
        let images = render_twice(&gpu, &scene, Some(&env), direct_config(32, Strategy::Mis));
        let b = dv(base);
        let (m, r) = (metallic as f64, roughness as f64);
        let table = albedo_table(|wi, wo| gltf_brdf(b, m, r, 1.0, wi, wo));
        // Broken: roughness used as α (no squaring).
        let wrong = albedo_table(|wi, wo| gltf_brdf(b, m, r.sqrt(), 1.0, wi, wo));
        let expect = |t: &[DVec3]| {
            reference(&scene, |o, d| {
                let n = hit_unit_sphere(o, d, 70.0)?;
                Some(interpolate(t, n.dot(-d).acos()))
            })
        };
        check_with_power(
            &format!("metallic-roughness base {base:?} metallic {metallic} roughness {roughness}"),
            &images,
            &expect(&table),
            &expect(&wrong),
            theta_bands(&scene),
            16,
        );
    }
}

/// A fit whose GGX is anisotropic and rotated (F = 1, no diffuse), on a sphere lit by a
/// directional light: each pixel is f(ωi, ωo) cos θi E from the CPU evaluator of the same model,
/// in the sphere's tangent frame.
#[test]
fn rotated_anisotropic_ggx_sphere_matches_the_cpu_evaluator() {
    let Some(gpu) = gpu_for_tests("rotated_anisotropic_ggx_sphere_matches_the_cpu_evaluator")
    else {
        return;
    };
    let model = facet_fit::model::analytic::parse_analytic("ggx?alpha=0.3&f0=1").unwrap();
    let src = MerlBrdf::from_table("ggx", MerlTable::sample(&model)).unwrap();
    let fit = facet_fit::fit_material(&src, "test", &facet_fit::FitConfig::isotropic()).unwrap();
    let with = |alpha_x: f64, alpha_y: f64, rotation: f64| {
        let mut r = fit.record.clone();
        let g = r.ggx.as_mut().unwrap();
        (g.alpha_x, g.alpha_y, g.rotation) = (alpha_x, alpha_y, rotation);
        g.fresnel.rgb.iter_mut().for_each(|c| *c = [1.0; 3]);
        Arc::new(FittedMaterial::from_record(r).unwrap())
    };
    let (ax, ay, rot) = (0.12, 0.4, 0.6);
    let fitted = with(ax, ay, rot);
    let mut scene = sphere_scene(Material {
        name: "aniso".into(),
        facet: Some(FacetMaterial {
            source: "aniso.json".into(),
            fit: fitted.clone(),
            model: ModelChoice::Ggx,
            glint: None,
        }),
        ..Default::default()
    });
    let to_light = DVec3::new(-0.4, 0.5, 1.0).normalize();
    let irradiance = 2.0;
    scene.lights.push(Light::Directional {
        direction: (-to_light).as_vec3(),
        irradiance: Vec3::splat(irradiance as f32),
    });
    let images = render_twice(&gpu, &scene, None, direct_config(32, Strategy::Mis));
    let expect = |fit: &FittedMaterial| {
        let brdf = fit.model(ModelChoice::Ggx).unwrap();
        reference(&scene, |o, d| {
            let n = hit_unit_sphere(o, d, 70.0)?;
            let frame = sphere_frame(n);
            let (wi, wo) = (local(frame, to_light), local(frame, -d));
            let f = brdf.eval(wi, wo).unwrap_or([0.0; 3]);
            Some(DVec3::from_array(f) * wi.z.max(0.0) * irradiance)
        })
    };
    // Broken: the rotation ignored.
    check_with_power(
        "rotated anisotropic GGX",
        &images,
        &expect(&fitted),
        &expect(&with(ax, ay, 0.0)),
        blocks,
        16,
    );
}

/// KHR_materials_clearcoat's layering over `base` (the extension's formula, written out): with
/// the coat's normal the shading normal, F_c = 0.04 + 0.96 (1 − ωo·h)⁵,
/// f = (1 − c F_c) f_base + c F_c D_c G2_c / (4 cos θi cos θo), D_c GGX of α = roughness².
fn clearcoat_brdf(c: f64, roughness: f64, base: DVec3, wi: DVec3, wo: DVec3) -> DVec3 {
    let lobe = gltf_brdf(DVec3::ONE, 1.0, roughness, 1.0, wi, wo);
    let f = 0.04 + 0.96 * (1.0 - wo.dot((wi + wo).normalize())).powi(5);
    // gltf_brdf of a white metal is F = 1 times D G2 / (4 cos θi cos θo): the bare lobe.
    (1.0 - c * f) * base + c * f * lobe
}

/// A glTF metallic-roughness sphere under KHR_materials_clearcoat (factor 0.8, roughness 0.2)
/// in a white furnace renders the extension's formula's albedo, by MIS and by BSDF sampling
/// alone. Broken: the coat's roughness used as α (no squaring).
#[test]
fn clearcoat_sphere_matches_the_cpu_albedo() {
    let Some(gpu) = gpu_for_tests("clearcoat_sphere_matches_the_cpu_albedo") else {
        return;
    };
    let env = Environment::Constant(Vec3::ONE);
    let (base, metallic, roughness) = ([0.2, 0.5, 0.8], 0.0, 0.6);
    let (c, cr) = (0.8, 0.2);
    let material = Material {
        name: "clearcoat".into(),
        base_color: Vec4::new(base[0], base[1], base[2], 1.0),
        metallic,
        roughness,
        clearcoat: Some(facet_render::scene::Clearcoat {
            factor: c as f32,
            texture: None,
            roughness: cr as f32,
            roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
        }),
        ..Default::default()
    };
    let scene = sphere_scene(material);
    let (b, m, r) = (dv(base), metallic as f64, roughness as f64);
    let table = |coat_roughness: f64| {
        albedo_table(|wi, wo| {
            let under = gltf_brdf(b, m, r, 1.0, wi, wo);
            clearcoat_brdf(c, coat_roughness, under, wi, wo)
        })
    };
    let (good, wrong) = (table(cr), table(cr.sqrt()));
    let expect = |t: &[DVec3]| {
        reference(&scene, |o, d| {
            let n = hit_unit_sphere(o, d, 70.0)?;
            Some(interpolate(t, n.dot(-d).acos()))
        })
    };
    for strategy in [Strategy::Mis, Strategy::Bsdf] {
        let images = render_twice(&gpu, &scene, Some(&env), direct_config(32, strategy));
        check_with_power(
            &format!("clearcoat over metallic-roughness, {strategy:?}"),
            &images,
            &expect(&good),
            &expect(&wrong),
            theta_bands(&scene),
            16,
        );
    }
}

// ---- coated fits ------------------------------------------------------------------------------

/// A fit of a GGX α 0.3 gold conductor with a ρd 0.2 diffuse lobe, under a clear coat (η 1.5,
/// α 0.1, weight 0.8) attached to its record as the fit would, as a material rendering its
/// `model`; and the fit itself (its single layer: the uncoated base).
fn coated_material(model: ModelChoice) -> (Material, Arc<FittedMaterial>) {
    use facet_fit::model::coat::Coat;
    use facet_fit::model::material::CoatRecord;
    let spec = "ggx?alpha=0.3&conductor=gold&kd=0.2";
    let base = facet_fit::model::analytic::parse_analytic(spec).unwrap();
    let src = MerlBrdf::from_table("gold", MerlTable::sample(&base)).unwrap();
    let fit = facet_fit::fit_material(&src, "test", &facet_fit::FitConfig::isotropic()).unwrap();
    let mut record = fit.record.clone();
    record.coat = Some(CoatRecord {
        coat: Coat::new(1.5, 0.1, 0.8),
        error: 0.0,
        ggx_error: None,
        beckmann_error: None,
        base: Box::new(fit.record.clone()),
    });
    let coated = Arc::new(FittedMaterial::from_record(record).unwrap());
    let material = Material {
        name: "coated".into(),
        facet: Some(FacetMaterial {
            source: "coated.json".into(),
            fit: coated,
            model,
            glint: None,
        }),
        ..Default::default()
    };
    (material, Arc::new(fit))
}

/// f of a coated material's model on the CPU (`facet_fit::model::coat::Coated`).
fn coated_eval(material: &Material, wi: DVec3, wo: DVec3) -> DVec3 {
    let f = material.facet.as_ref().unwrap();
    let coated = f.fit.coated.as_ref().unwrap().model(f.model).unwrap();
    DVec3::from_array(coated.eval(wi, wo).unwrap_or([0.0; 3]))
}

/// A coated fit's sphere under a point light, depth 1, with its GGX and its tabulated model:
/// every pixel is f cos θi I / r² of the CPU's coated model. Broken: the base without its coat.
#[test]
fn coated_sphere_under_a_point_light_is_f_cos_i_over_r2() {
    let Some(gpu) = gpu_for_tests("coated_sphere_under_a_point_light_is_f_cos_i_over_r2") else {
        return;
    };
    for model in [ModelChoice::Ggx, ModelChoice::Tabulated] {
        let (material, uncoated) = coated_material(model);
        let (scene, images) = point_lit_sphere(&gpu, material.clone());
        let bare = uncoated.model(model).unwrap();
        check_with_power(
            &format!("coated {model:?}, point light"),
            &images,
            &point_light_reference(&scene, &|wi, wo| coated_eval(&material, wi, wo)),
            &point_light_reference(&scene, &|wi, wo| {
                DVec3::from_array(bare.eval(wi, wo).unwrap_or([0.0; 3]))
            }),
            blocks,
            16,
        );
    }
}

/// A coated fit's sphere in a white furnace renders the CPU coated model's albedo, by MIS and
/// by BSDF sampling alone (whose estimate is f cos θi / pdf: it is right only if the pdf of the
/// two layers' sampling is the density it samples). Broken: the albedo 5 % low.
#[test]
fn coated_sphere_in_a_white_furnace_renders_its_albedo() {
    let Some(gpu) = gpu_for_tests("coated_sphere_in_a_white_furnace_renders_its_albedo") else {
        return;
    };
    let (material, _) = coated_material(ModelChoice::Tabulated);
    let albedo = albedo_table(|wi, wo| coated_eval(&material, wi, wo));
    let scene = sphere_scene(material);
    let env = Environment::Constant(Vec3::ONE);
    let expect = |scale: f64| {
        reference(&scene, |o, d| {
            let n = hit_unit_sphere(o, d, 70.0)?;
            Some(interpolate(&albedo, n.dot(-d).acos()) * scale)
        })
    };
    for strategy in [Strategy::Mis, Strategy::Bsdf] {
        let images = render_twice(&gpu, &scene, Some(&env), direct_config(32, strategy));
        check_with_power(
            &format!("coated tabulated, white furnace, {strategy:?}"),
            &images,
            &expect(1.0),
            &expect(0.95),
            theta_bands(&scene),
            16,
        );
    }
}

// ---- measured materials ----------------------------------------------------------------------

/// The embedded MERL-100 proxy `name` as a measured material (its sampling fit made after
/// loading, as `facet render` makes it), and the CPU lookup of its filled table with the
/// channels as stored and reversed (a broken renderer that reads the interleaved table
/// backwards).
fn measured_proxy(name: &str) -> (Material, MerlTable) {
    let mut m = MeasuredMaterial::open(
        &format!("nbrdf:{name}"),
        std::path::Path::new(""),
        None,
        None,
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let src = m
        .unfitted
        .take()
        .expect("loading leaves the fit to the caller");
    let fit = facet_fit::fit_material(&*src, &m.source, &facet_fit::FitConfig::SINGLE_LAYER);
    m.fit = Some(std::sync::Arc::new(fit.unwrap_or_else(|e| panic!("{e}"))));
    let Measurement::Merl(table) = &*m.data else {
        panic!("a proxy is a MERL-grid table");
    };
    let table = table.clone();
    let material = Material {
        name: name.into(),
        measured: Some(m),
        ..Default::default()
    };
    (material, table)
}

/// 200 materials naming one measurement hold its table and its sampling fit's tabulated NDF
/// once: the scene's tables grow by each material's own Fresnel table (3 × FRESNEL_NODES f32)
/// and nothing else, where each used to add the NDF's block again (about 1 MB: 110 of them
/// passed the 128 MiB binding).
#[test]
fn materials_sharing_a_measurement_upload_it_once() {
    let Some(gpu) = gpu_for_tests("materials_sharing_a_measurement_upload_it_once") else {
        return;
    };
    let (material, _) = measured_proxy("gold-metallic-paint");
    let upload = |n: usize| {
        let mut scene = sphere_scene(material.clone());
        scene.materials = vec![material.clone(); n];
        let res = SceneResources::new(&gpu, &scene, None, ResourceConfig::standard()).unwrap();
        let b = &res.built;
        (res.tables.size(), b.measured_tables, b.tabulated_tables)
    };
    let (one, many) = (upload(1), upload(200));
    assert_eq!((one.1, one.2, many.1, many.2), (1, 1, 1, 1));
    let fresnel = 4 * 3 * facet_render::materials::FRESNEL_NODES as u64;
    println!(
        "tables: {} bytes for 1 material, {} for 200 ({} a material more)",
        one.0,
        many.0,
        (many.0 - one.0) / 199
    );
    assert_eq!(many.0 - one.0, 199 * fresnel);
}

/// f of the table at (wi, wo), channels reversed when `broken`.
fn lookup(table: &MerlTable, wi: DVec3, wo: DVec3, broken: bool) -> DVec3 {
    let v = table.lookup_interpolated(wi, wo).unwrap_or([0.0; 3]);
    match broken {
        false => DVec3::from_array(v),
        true => DVec3::new(v[2], v[1], v[0]),
    }
}

/// The point light of the measured-material tests.
const MEASURED_LIGHT: (DVec3, DVec3) = (DVec3::new(-1.2, 1.5, 2.5), DVec3::new(6.0, 5.0, 4.0));

/// The unit sphere of `material` under [`MEASURED_LIGHT`], no environment, rendered at depth 1
/// with seeds 0 and 1.
fn point_lit_sphere(gpu: &Gpu, material: Material) -> (Scene, [Image; 2]) {
    let mut scene = sphere_scene(material);
    let (position, intensity) = MEASURED_LIGHT;
    scene.lights.push(Light::Point {
        position: position.as_vec3(),
        intensity: intensity.as_vec3(),
    });
    let images = render_twice(gpu, &scene, None, direct_config(16, Strategy::Mis));
    (scene, images)
}

/// Per pixel of [`point_lit_sphere`]'s scene, f(ωi, ωo) cos θi I / r² in the sphere's frame.
fn point_light_reference(scene: &Scene, f: &dyn Fn(DVec3, DVec3) -> DVec3) -> Vec<Option<DVec3>> {
    let (position, intensity) = MEASURED_LIGHT;
    reference(scene, |o, d| {
        let n = hit_unit_sphere(o, d, 70.0)?;
        let frame = sphere_frame(n);
        let to_light = position - n;
        let r2 = to_light.length_squared();
        let (wi, wo) = (local(frame, to_light.normalize()), local(frame, -d));
        if wi.z <= 0.0 {
            return Some(DVec3::ZERO);
        }
        Some(f(wi, wo) * wi.z * intensity / r2)
    })
}

/// A measured sphere under one point light, no environment, depth 1: every pixel is
/// f(ωi, ωo) cos θi I / r², f the CPU's interpolated lookup of the same filled table.
#[test]
fn measured_sphere_under_a_point_light_is_f_cos_i_over_r2() {
    let Some(gpu) = gpu_for_tests("measured_sphere_under_a_point_light_is_f_cos_i_over_r2") else {
        return;
    };
    let (material, table) = measured_proxy("gold-metallic-paint");
    let (scene, images) = point_lit_sphere(&gpu, material);
    let expect =
        |broken: bool| point_light_reference(&scene, &|wi, wo| lookup(&table, wi, wo, broken));
    check_with_power(
        "measured gold-metallic-paint, point light",
        &images,
        &expect(false),
        &expect(true),
        blocks,
        16,
    );
}

/// A measured sphere in a white furnace renders its directional albedo ∫ f cos θi dωi, from
/// the CPU's lookup of the same table (within 1 % and the noise).
#[test]
fn measured_sphere_in_a_white_furnace_renders_its_albedo() {
    let Some(gpu) = gpu_for_tests("measured_sphere_in_a_white_furnace_renders_its_albedo") else {
        return;
    };
    let (material, table) = measured_proxy("blue-metallic-paint");
    let scene = sphere_scene(material);
    let env = Environment::Constant(Vec3::ONE);
    let images = render_twice(&gpu, &scene, Some(&env), direct_config(32, Strategy::Mis));
    let expect = |broken: bool| {
        let albedo = albedo_table(|wi, wo| lookup(&table, wi, wo, broken));
        reference(&scene, |o, d| {
            let n = hit_unit_sphere(o, d, 70.0)?;
            Some(interpolate(&albedo, n.dot(-d).acos()))
        })
    };
    check_with_power(
        "measured blue-metallic-paint, white furnace",
        &images,
        &expect(false),
        &expect(true),
        theta_bands(&scene),
        16,
    );
}

/// The same measured material sampled by its fit's visible normals and by the cosine lobe
/// alone (BSDF sampling only, a white furnace): the same image, block by block within the
/// noise, and the visible normals with less than a quarter of the variance (14× less when
/// written).
#[test]
fn measured_sampling_by_the_fit_is_unbiased_and_lowers_the_variance() {
    let Some(gpu) =
        gpu_for_tests("measured_sampling_by_the_fit_is_unbiased_and_lowers_the_variance")
    else {
        return;
    };
    let (material, _) = measured_proxy("gold-metallic-paint");
    let scene = sphere_scene(material);
    let env = Environment::Constant(Vec3::ONE);
    let with = |ndf_sampling: NdfSampling| {
        let mut c = direct_config(32, Strategy::Bsdf);
        c.sampling.ndf_sampling = ndf_sampling;
        render_twice(&gpu, &scene, Some(&env), c)
    };
    let (visible, cosine) = (with(NdfSampling::Visible), with(NdfSampling::Cosine));
    assert_sum_of_parts(
        "visible normals against cosine",
        &visible,
        std::slice::from_ref(&cosine),
    );
    let variance =
        |imgs: &[Image; 2]| -> f64 { block_stats(imgs).iter().map(|(_, v)| v.element_sum()).sum() };
    let (v_visible, v_cosine) = (variance(&visible), variance(&cosine));
    println!("variance of the mean: visible normals {v_visible:.3e}, cosine {v_cosine:.3e}");
    assert!(
        v_visible < 0.25 * v_cosine,
        "visible normals {v_visible:.3e} against cosine {v_cosine:.3e}"
    );
}

/// An RGL file that Facet writes from the analytic `spec` (its own NDF as the sample space, the
/// standard resolution) as a measured material, with the file as the CPU reads it and the
/// analytic model.
fn rgl_material(spec: &str) -> (Material, Arc<RglBsdf>, MicrofacetBrdf) {
    let src = facet_fit::model::analytic::parse_analytic(spec).unwrap();
    let (tensor, _) = rgl_tensor(&src, &src.ndf, BsdfResolution::standard(), "").unwrap();
    let bytes = tensor.to_bytes();
    let cpu = Arc::new(RglBsdf::parse("ggx", bytes.clone()).unwrap());
    let material = Material {
        name: "rgl".into(),
        measured: Some(MeasuredMaterial {
            source: "ggx.bsdf".into(),
            path: None,
            data: Arc::new(Measurement::Rgl(Box::new(
                RglBsdf::parse("ggx", bytes).unwrap(),
            ))),
            fit: None,
            unfitted: None,
        }),
        ..Default::default()
    };
    (material, cpu, src)
}

/// An RGL `.bsdf` written by Facet from an analytic GGX, on a sphere under a point light,
/// depth 1: every pixel is f cos θi I / r² with f the CPU reader's; against the GGX itself, the
/// whole sphere's mean is within 1 % (0.06 % when written; block by block the file's own
/// interpolation error reaches 10 % in the lobe's dim tails, at the standard resolution).
#[test]
fn rgl_sphere_under_a_point_light_renders_like_its_ggx() {
    let Some(gpu) = gpu_for_tests("rgl_sphere_under_a_point_light_renders_like_its_ggx") else {
        return;
    };
    let (material, file, ggx) = rgl_material("ggx?alpha=0.25&f0=0.9");
    let (scene, images) = point_lit_sphere(&gpu, material);
    let expect = |f: &dyn Fn(DVec3, DVec3) -> DVec3| point_light_reference(&scene, f);
    let read = |wi: DVec3, wo: DVec3| viewed(&*file, wi, wo);
    // Broken: the blue channel halved.
    check_with_power(
        "RGL from GGX α 0.25, point light",
        &images,
        &expect(&read),
        &expect(&|wi, wo| read(wi, wo) * DVec3::new(1.0, 1.0, 0.5)),
        blocks,
        16,
    );
    let analytic = |wi: DVec3, wo: DVec3| viewed(&ggx, wi, wo);
    let whole = |_: u32, _: u32| Some(0);
    if let Err(e) = check(
        "RGL against its GGX",
        &images,
        &expect(&analytic),
        whole,
        16,
    ) {
        panic!("{e}");
    }
}

/// f(ωi, ωo) of `b` with the view ωo as its parameter direction (Mitsuba's si.wi, the way the
/// renderer reads an RGL file).
fn viewed(b: &dyn Brdf, wi: DVec3, wo: DVec3) -> DVec3 {
    DVec3::from_array(b.eval(wo, wi).unwrap_or([0.0; 3]))
}

/// The same file in a white furnace, BSDF sampling alone: the estimates f cos θ / pdf of the
/// file's own warps average to the directional albedo that the CPU integrates from its f, so
/// the sampling and its pdf agree.
#[test]
fn rgl_sphere_in_a_white_furnace_by_its_own_sampling() {
    let Some(gpu) = gpu_for_tests("rgl_sphere_in_a_white_furnace_by_its_own_sampling") else {
        return;
    };
    let (material, file, _) = rgl_material("ggx?alpha=0.25&f0=0.9");
    let scene = sphere_scene(material);
    let env = Environment::Constant(Vec3::ONE);
    let images = render_twice(&gpu, &scene, Some(&env), direct_config(32, Strategy::Bsdf));
    let expect = |scale: f64| {
        let albedo =
            albedo_table(|wi, wo| DVec3::from_array(file.eval(wo, wi).unwrap_or([0.0; 3])) * scale);
        reference(&scene, |o, d| {
            let n = hit_unit_sphere(o, d, 70.0)?;
            Some(interpolate(&albedo, n.dot(-d).acos()))
        })
    };
    check_with_power(
        "RGL from GGX α 0.25, white furnace",
        &images,
        &expect(1.0),
        &expect(0.95),
        theta_bands(&scene),
        16,
    );
}

// ---- several lights ---------------------------------------------------------------------------

/// A bright sun, a small point light and an environment light a plane and a sphere together:
/// the render with all three is, region by region, the sum of the renders with each alone
/// (light transport is linear; each light's share is unbiased whatever the selection gives it),
/// within 5 standard errors of the four renders' combined noise, at depth 3.
#[test]
fn three_lights_together_are_the_sum_of_each_alone() {
    let Some(gpu) = gpu_for_tests("three_lights_together_are_the_sum_of_each_alone") else {
        return;
    };
    let mut base = floor_scene(3.0, 60.0);
    base.materials.push(lambert([0.7, 0.5, 0.3]));
    base.add_uv_sphere(Vec3::new(0.3, 0.6, -0.2), 0.6, 64, 32, 1);
    let sun = Light::Directional {
        direction: Vec3::new(0.4, -1.0, 0.3).normalize(),
        irradiance: Vec3::splat(4.0),
    };
    let point = Light::Point {
        position: Vec3::new(-0.8, 0.4, 0.6),
        intensity: Vec3::new(0.6, 0.5, 0.4),
    };
    let sky = Environment::Constant(Vec3::new(0.2, 0.3, 0.45));
    let mut c = direct_config(32, Strategy::Mis);
    c.sampling.max_depth = 3;
    let with = |lights: Vec<Light>, env: Option<&Environment>| {
        let mut s = base.clone();
        s.lights = lights;
        render_twice(&gpu, &s, env, c)
    };
    let all = with(vec![sun, point], Some(&sky));
    let alone = [
        with(vec![sun], None),
        with(vec![point], None),
        with(vec![], Some(&sky)),
    ];
    assert_sum_of_parts("three lights", &all, &alone);
}

/// Per 8 × 8 block: the mean and the variance of the mean (from the two seeds) of a render.
fn block_stats(imgs: &[Image; 2]) -> Vec<(DVec3, DVec3)> {
    let mut out = vec![(DVec3::ZERO, DVec3::ZERO, 0usize); 64];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            let k = blocks(x, y).unwrap();
            let (a, b) = (dv(imgs[0].pixels[i]), dv(imgs[1].pixels[i]));
            out[k].0 += 0.5 * (a + b);
            out[k].1 += (a - b) * (a - b);
            out[k].2 += 1;
        }
    }
    out.into_iter()
        .map(|(s, d2, n)| {
            let n = n as f64;
            (s / n, d2 / n / (4.0 * n))
        })
        .collect()
}

/// Asserts that, block by block, the render `all` is the sum of the renders `parts` within
/// Z standard errors of their combined noise.
fn assert_sum_of_parts(what: &str, all: &[Image; 2], parts: &[[Image; 2]]) {
    let sa = block_stats(all);
    let parts: Vec<_> = parts.iter().map(block_stats).collect();
    let mut worst = 0.0f64;
    for k in 0..64 {
        let sum: DVec3 = parts.iter().map(|p| p[k].0).sum();
        let var: DVec3 = sa[k].1 + parts.iter().map(|p| p[k].1).sum::<DVec3>();
        for ch in 0..3 {
            let allowed = Z * var[ch].sqrt() + 1e-3 * sum[ch] + 1e-5;
            let r = (sa[k].0[ch] - sum[ch]).abs() / allowed;
            worst = worst.max(r);
            assert!(
                r <= 1.0,
                "{what}: block {k} channel {ch}: all {:.5}, sum of the parts {:.5} (se {:.5})",
                sa[k].0[ch],
                sum[ch],
                var[ch].sqrt()
            );
        }
    }
    println!("{what}: worst |all − Σ parts| / allowance {worst:.3}");
}

/// 100 point and spot lights at random over the floor, some behind a wall, and an emissive
/// quad, picked per shading point by the light BVH (the default selection): the render with
/// all of them is the sum of the renders of four groups of 25 lamps and of the quad alone (its
/// emission found by BSDF samples too: MIS with the tree's pmf). Each group makes another
/// tree, so a pmf that did not match its picks, or a light the tree starved to 0, would break
/// the sum.
#[test]
fn hundred_lights_together_are_the_sum_of_their_groups() {
    let Some(gpu) = gpu_for_tests("hundred_lights_together_are_the_sum_of_their_groups") else {
        return;
    };
    let mut base = floor_scene(3.0, 60.0);
    base.materials.push(lambert([0.7, 0.5, 0.3]));
    base.add_uv_sphere(Vec3::new(0.3, 0.5, -0.2), 0.5, 48, 24, 1);
    // A wall across the floor: the lamps behind it light only its far side and the floor there.
    base.add_quad(
        Vec3::new(-3.0, 0.0, 1.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(0.0, 1.2, 0.0),
        1.0,
        1,
    );
    base.add_quad(
        Vec3::new(3.0, 0.0, 1.0),
        Vec3::new(-6.0, 0.0, 0.0),
        Vec3::new(0.0, 1.2, 0.0),
        1.0,
        1,
    );
    // The quad, facing down: emissive in `all` and its own part, not in the others.
    let dark = base.materials.len() as u32;
    base.materials.push(lambert([0.2; 3]));
    base.add_quad(
        Vec3::new(-1.5, 1.2, -1.5),
        Vec3::new(1.4, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 1.2),
        1.0,
        dark,
    );
    // The same surface, emitting from its front (down).
    let glowing = |s: &mut Scene| s.materials[dark as usize].emissive = Vec3::new(4.0, 3.5, 3.0);
    let mut h = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        h ^= h << 13;
        h ^= h >> 7;
        h ^= h << 17;
        (h >> 40) as f32 / (1u64 << 24) as f32
    };
    let lamps: Vec<Light> = (0..100)
        .map(|k| {
            let position = Vec3::new(next() * 5.0 - 2.5, 0.4 + next(), next() * 5.0 - 2.5);
            let intensity = Vec3::new(0.02 + 0.1 * next(), 0.05, 0.02 + 0.1 * next());
            if k % 2 == 0 {
                Light::Point {
                    position,
                    intensity,
                }
            } else {
                Light::Spot {
                    position,
                    direction: Vec3::new(next() - 0.5, -1.0, next() - 0.5).normalize(),
                    intensity: 3.0 * intensity,
                    inner_cone: 0.3,
                    outer_cone: 0.5 + next(),
                }
            }
        })
        .collect();
    let mut c = direct_config(32, Strategy::Mis);
    c.sampling.max_depth = 2;
    let render = |lights: &[Light], glow: bool| {
        let mut s = base.clone();
        s.lights = lights.to_vec();
        if glow {
            glowing(&mut s);
        }
        render_twice(&gpu, &s, None, c)
    };
    let all = render(&lamps, true);
    let mut parts: Vec<[Image; 2]> = lamps.chunks(25).map(|g| render(g, false)).collect();
    parts.push(render(&[], true));
    assert_sum_of_parts("100 lights and a quad, light BVH", &all, &parts);
}

/// MIS with the light BVH weighs the emission a BSDF sample finds by the pmf the tree gives
/// that emitter at the sample's origin, which must be the pmf with which next-event estimation
/// picks it there (asked with the same normal); else the two weights do not sum to 1. A large
/// emissive quad among 40 lamps over a Lambertian floor, direct light only: MIS renders what
/// light sampling alone renders (which needs no pmf at the emitter), block by block within 5
/// standard errors.
#[test]
fn mis_with_the_light_bvh_matches_light_sampling_alone() {
    let Some(gpu) = gpu_for_tests("mis_with_the_light_bvh_matches_light_sampling_alone") else {
        return;
    };
    let mut scene = floor_scene(3.0, 60.0);
    let mut emitter = lambert([0.2; 3]);
    emitter.emissive = Vec3::new(3.0, 2.5, 2.0);
    scene.materials.push(emitter);
    // Facing down (edge_u × edge_v = −Y), just above the floor.
    scene.add_quad(
        Vec3::new(-2.0, 0.5, -1.0),
        Vec3::new(2.5, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 2.0),
        1.0,
        1,
    );
    // Dim lamps above and bright ones below the floor, which only the normal's term of the
    // tree's importance tells apart from the quad at the floor.
    scene.lights = (0..40)
        .map(|k| {
            let below = k % 2 == 1;
            Light::Point {
                position: Vec3::new(-2.5 + 0.125 * k as f32, if below { -0.5 } else { 1.0 }, 1.5),
                intensity: Vec3::splat(if below { 5.0 } else { 0.05 }),
            }
        })
        .collect();
    let mis = render_twice(&gpu, &scene, None, direct_config(256, Strategy::Mis));
    let light = render_twice(&gpu, &scene, None, direct_config(256, Strategy::Light));
    let (a, b) = (block_stats(&mis), block_stats(&light));
    let mut worst = 0.0f64;
    for k in 0..64 {
        for ch in 0..3 {
            let allowed = Z * (a[k].1[ch] + b[k].1[ch]).sqrt() + 1e-3 * b[k].0[ch] + 1e-5;
            let r = (a[k].0[ch] - b[k].0[ch]).abs() / allowed;
            worst = worst.max(r);
            assert!(
                r <= 1.0,
                "block {k} channel {ch}: MIS {:.5}, light sampling {:.5}",
                a[k].0[ch],
                b[k].0[ch]
            );
        }
    }
    println!("MIS against light sampling, light BVH: worst / allowance {worst:.3}");
}

/// Every selection is unbiased: on the many-light rooms (`assets/many_lights/`: 100 point and
/// spot lamps, some behind a partition; 100 emissive panels of 10⁴ triangles), full paths at
/// depth 5, the image means of `bvh`, `robust` and `power` agree within 5 standard errors
/// (from each render's two seeds, pixels independent).
#[test]
fn every_light_selection_renders_the_many_light_rooms_alike() {
    let Some(gpu) = gpu_for_tests("every_light_selection_renders_the_many_light_rooms_alike")
    else {
        return;
    };
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/many_lights");
    for file in ["room_points.gltf", "room_panels.gltf"] {
        let scene = facet_render::scene::load_gltf(&dir.join(file), &Default::default()).unwrap();
        let mut c = direct_config(16, Strategy::Mis);
        c.sampling.max_depth = 5;
        let stats: Vec<(f64, f64)> = [
            facet_render::LightSelection::Bvh,
            facet_render::LightSelection::Robust,
            facet_render::LightSelection::Power,
        ]
        .into_iter()
        .map(|light_selection| {
            let rc = ResourceConfig {
                light_selection,
                ..ResourceConfig::standard()
            };
            let res = SceneResources::new(&gpu, &scene, None, rc).unwrap();
            let integrator = Integrator::new(&gpu.device, &res).unwrap();
            let camera = CameraFrame::new(&scene.camera).unwrap();
            let images: Vec<Image> = (0..2)
                .map(|seed| {
                    let mut c = c;
                    c.sampling.seed = seed;
                    integrator
                        .render(&gpu, &res, &camera, &c, &mut |_| {})
                        .unwrap()
                        .0
                })
                .collect();
            let n = (images[0].pixels.len() * 3) as f64;
            let values = |im: &Image| {
                im.pixels
                    .iter()
                    .flatten()
                    .map(|v| *v as f64)
                    .collect::<Vec<_>>()
            };
            let (a, b) = (values(&images[0]), values(&images[1]));
            let mean = a.iter().chain(&b).sum::<f64>() / (2.0 * n);
            let var = a
                .iter()
                .zip(&b)
                .map(|(x, y)| 0.5 * (x - y).powi(2))
                .sum::<f64>()
                / n;
            (mean, var / (2.0 * n))
        })
        .collect();
        println!("{file}: (mean, squared standard error) of bvh, robust, power: {stats:?}");
        for (k, name) in [(1, "robust"), (2, "power")] {
            let z = (stats[0].0 - stats[k].0).abs() / (stats[0].1 + stats[k].1).sqrt();
            assert!(
                z <= Z,
                "{file}: bvh's mean {:.5} and {name}'s {:.5} are {z:.1} σ apart",
                stats[0].0,
                stats[k].0
            );
        }
    }
}

/// The gold scene of issue 12 (a GGX sphere on a Lambertian plane, a constant sky of 0.5 and a
/// 40 W/sr point light): the robust selection gives the point light a fair share, where the
/// flux-based one starved it.
#[test]
fn light_selection_does_not_starve_a_point_light() {
    let Some(gpu) = gpu_for_tests("light_selection_does_not_starve_a_point_light") else {
        return;
    };
    let mut scene = Scene {
        materials: vec![lambert([0.5; 3]), lambert([0.8, 0.6, 0.2])],
        lights: vec![Light::Point {
            position: Vec3::new(2.0, 3.0, 2.0),
            intensity: Vec3::splat(40.0),
        }],
        ..floor_scene(3.0, 60.0)
    };
    scene.positions.clear();
    scene.normals.clear();
    scene.uvs.clear();
    scene.tangents.clear();
    scene.indices.clear();
    scene.triangle_material.clear();
    // A 20 × 20 floor: the bounding sphere that sized the sky's flux is large.
    scene.add_quad(
        Vec3::new(-10.0, -1.0, 10.0),
        Vec3::new(20.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -20.0),
        1.0,
        0,
    );
    scene.add_uv_sphere(Vec3::ZERO, 1.0, 64, 32, 1);
    let env = Environment::Constant(Vec3::splat(0.5));
    let pmf = |selection| {
        let rc = ResourceConfig {
            light_selection: selection,
            ..ResourceConfig::standard()
        };
        SceneResources::new(&gpu, &scene, Some(&env), rc)
            .unwrap()
            .built
            .light_pmf
    };
    let (robust, power) = (
        pmf(facet_render::LightSelection::Robust),
        pmf(facet_render::LightSelection::Power),
    );
    println!("point light, environment: robust {robust:?}, by flux {power:?}");
    assert_eq!(robust.len(), 2);
    assert!((robust.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    assert!(
        robust[0] >= 0.25 && robust[0] > 2.0 * power[0],
        "{robust:?} vs {power:?}"
    );
}

/// The robust selection asks what the camera sees: of two equal point lights, each 2 above a
/// floor, one over the floor in view and one over a floor 40 away that no camera ray reaches,
/// the first gets ½ (its share of the irradiance at the camera's hits, 1 − O(10⁻⁴): the far
/// light reaches them at grazing incidence from 40 away) + ¼ (the uniform half), the second
/// only its uniform ¼.
#[test]
fn light_selection_weighs_what_the_camera_sees() {
    let Some(gpu) = gpu_for_tests("light_selection_weighs_what_the_camera_sees") else {
        return;
    };
    let mut scene = Scene {
        lights: vec![
            Light::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: Vec3::splat(10.0),
            },
            Light::Point {
                position: Vec3::new(43.0, 2.0, 0.0),
                intensity: Vec3::splat(10.0),
            },
        ],
        ..floor_scene(3.0, 60.0)
    };
    scene.add_quad(
        Vec3::new(40.0, 0.0, 3.0),
        Vec3::new(6.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -6.0),
        1.0,
        0,
    );
    let robust = ResourceConfig {
        light_selection: facet_render::LightSelection::Robust,
        ..ResourceConfig::standard()
    };
    let pmf = SceneResources::new(&gpu, &scene, None, robust)
        .unwrap()
        .built
        .light_pmf;
    println!("light in view, light out of view: {pmf:?}");
    assert!((pmf[0] - 0.75).abs() < 1e-3, "{pmf:?}");
    assert!((pmf[1] - 0.25).abs() < 1e-3, "{pmf:?}");
}
