//! The demo scene (`assets/demo/demo.gltf`) and its sky (`assets/demo/sky.exr`), made in code.
//!
//! Regenerate the committed files with
//! `cargo test -p facet-render --test scene -- --ignored regenerate_demo_assets`.

use super::GltfBuilder;
use glam::{Mat3, Quat, Vec3};
use serde_json::json;
use std::f32::consts::PI;
use std::path::Path;

/// Segments around (φ) and rings (θ) of each sphere.
pub const SPHERE_SEGMENTS: usize = 96;
pub const SPHERE_RINGS: usize = 48;
/// Triangles of one sphere: one per segment in the two polar rings, two elsewhere.
pub const SPHERE_TRIANGLES: usize = SPHERE_SEGMENTS * (2 * SPHERE_RINGS - 2);
/// Floor (2) + three spheres.
pub const DEMO_TRIANGLES: usize = 2 + 3 * SPHERE_TRIANGLES;
/// Sphere materials, left to right.
pub const SPHERE_MATERIALS: [&str; 3] = ["tabulated", "ggx", "glint"];

/// Where the sun is and where the directional light comes from: upper left front, 35° up.
pub fn sun_direction() -> Vec3 {
    let elevation = 35f32.to_radians();
    let horizontal = Vec3::new(-1.0, 0.0, 1.0).normalize();
    (horizontal * elevation.cos() + Vec3::Y * elevation.sin()).normalize()
}

/// A UV sphere of radius `r`: positions, normals, uvs, tangents, indices (CCW seen from outside).
/// Vertex (i, j): θ = π i / rings, φ = 2π j / segments, p = r (sin θ cos φ, cos θ, −sin θ sin φ),
/// u = j / segments, v = i / rings; tangent = ∂p/∂u direction, w from ∂p/∂v.
#[allow(clippy::type_complexity)]
pub fn uv_sphere(r: f32) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<f32>, Vec<f32>, Vec<u32>) {
    let (mut p, mut n, mut uv, mut t) = (vec![], vec![], vec![], vec![]);
    for i in 0..=SPHERE_RINGS {
        let theta = PI * i as f32 / SPHERE_RINGS as f32;
        for j in 0..=SPHERE_SEGMENTS {
            let phi = 2.0 * PI * j as f32 / SPHERE_SEGMENTS as f32;
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            p.push((d * r).to_array());
            n.push(d.to_array());
            uv.extend([
                j as f32 / SPHERE_SEGMENTS as f32,
                i as f32 / SPHERE_RINGS as f32,
            ]);
            // ∂p/∂φ ∝ (−sin φ, 0, −cos φ) (defined at the poles too); ∂p/∂θ ∝ (cos θ cos φ, −sin θ, −cos θ sin φ).
            let tangent = Vec3::new(-phi.sin(), 0.0, -phi.cos());
            let dpdv = Vec3::new(
                theta.cos() * phi.cos(),
                -theta.sin(),
                -theta.cos() * phi.sin(),
            );
            let w = if d.cross(tangent).dot(dpdv) < 0.0 {
                -1.0
            } else {
                1.0
            };
            t.extend([tangent.x, tangent.y, tangent.z, w]);
        }
    }
    let row = SPHERE_SEGMENTS as u32 + 1;
    let mut idx = Vec::new();
    let mut tri = |a: u32, b: u32, c: u32| {
        // Keep every triangle counter-clockwise seen from outside.
        let [pa, pb, pc] = [a, b, c].map(|k| Vec3::from(p[k as usize]));
        if (pb - pa).cross(pc - pa).dot(pa + pb + pc) < 0.0 {
            idx.extend([a, c, b]);
        } else {
            idx.extend([a, b, c]);
        }
    };
    for i in 0..SPHERE_RINGS as u32 {
        for j in 0..SPHERE_SEGMENTS as u32 {
            let (a, b) = (i * row + j, i * row + j + 1);
            let (c, d) = (a + row, b + row);
            if i != 0 {
                tri(a, c, b);
            }
            if i != SPHERE_RINGS as u32 - 1 {
                tri(b, c, d);
            }
        }
    }
    (p, n, uv, t, idx)
}

/// Writes `demo.gltf` into `dir`.
pub fn write_demo_gltf(dir: &Path) {
    let mut g = GltfBuilder::default();
    let floor_mat = g.material(json!({
        "name": "floor",
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}
    }));
    let fit = |model: &str| json!({"fit": "default_fit.json", "model": model});
    let mut glint = fit("ggx");
    glint["glint"] = json!({"density": 2e6, "gamma_deg": 2.0, "threshold": 50});
    let sphere_mats: Vec<usize> = [fit("tabulated"), fit("ggx"), glint]
        .into_iter()
        .zip(SPHERE_MATERIALS)
        .map(|(facet, name)| {
            g.material(json!({
                "name": name,
                "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.3},
                "extras": {"facet": facet}
            }))
        })
        .collect();

    // Floor: 8 × 8 at y = 0, facing +Y, UVs over [0, 1]².
    let fp = g.vec3s(&[
        [-4.0, 0.0, -4.0],
        [-4.0, 0.0, 4.0],
        [4.0, 0.0, 4.0],
        [4.0, 0.0, -4.0],
    ]);
    let fnorm = g.vec3s(&[[0.0, 1.0, 0.0]; 4]);
    let fuv = g.floats(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0], "VEC2");
    let ft = g.floats(&[1.0, 0.0, 0.0, -1.0].repeat(4), "VEC4");
    let fi = g.indices(&[0, 1, 2, 0, 2, 3]);
    let floor_mesh = g.mesh(
        "floor",
        json!({"POSITION": fp, "NORMAL": fnorm, "TEXCOORD_0": fuv, "TANGENT": ft}),
        Some(fi),
        Some(floor_mat),
    );
    let mut roots = vec![g.node(json!({"name": "floor", "mesh": floor_mesh}))];

    // Three spheres sharing one set of accessors.
    let (p, n, uv, t, idx) = uv_sphere(0.5);
    let attrs = json!({
        "POSITION": g.vec3s(&p), "NORMAL": g.vec3s(&n),
        "TEXCOORD_0": g.floats(&uv, "VEC2"), "TANGENT": g.floats(&t, "VEC4")
    });
    let si = g.indices(&idx);
    for (k, (mat, name)) in sphere_mats.into_iter().zip(SPHERE_MATERIALS).enumerate() {
        let mesh = g.mesh(
            &format!("sphere_{name}"),
            attrs.clone(),
            Some(si),
            Some(mat),
        );
        let x = -1.2 + 1.2 * k as f32;
        roots.push(g.node(
            json!({"name": format!("sphere_{name}"), "mesh": mesh, "translation": [x, 0.5, 0.0]}),
        ));
    }

    // Camera at (0, 1.3, 4.2) looking at (0, 0.45, 0): columns (right, up, −forward).
    let eye = Vec3::new(0.0, 1.3, 4.2);
    let forward = (Vec3::new(0.0, 0.45, 0.0) - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let q = Quat::from_mat3(&Mat3::from_cols(right, up, -forward)).normalize();
    g.cameras.push(
        json!({"name": "main", "type": "perspective", "perspective": {
        "yfov": 30f32.to_radians(), "aspectRatio": 16.0 / 9.0, "znear": 0.05, "zfar": 100.0}}),
    );
    roots.push(g.node(json!({"name": "camera", "camera": 0, "translation": eye.to_array(), "rotation": q.to_array()})));

    // Sunlight: 3 lx, white, travelling away from the sun (the node's −Z).
    g.lights.push(
        json!({"name": "sun", "type": "directional", "color": [1.0, 1.0, 1.0], "intensity": 3.0}),
    );
    let q = Quat::from_rotation_arc(Vec3::NEG_Z, -sun_direction());
    roots.push(g.node(json!({"name": "sun", "rotation": q.to_array(), "extensions": {"KHR_lights_punctual": {"light": 0}}})));
    g.extensions_used.push("KHR_lights_punctual");

    let mut doc = g.finish(&roots);
    doc["asset"]["generator"] = json!("facet-render tests/common/demo.rs (regenerate_demo_assets)");
    std::fs::write(dir.join("demo.gltf"), serde_json::to_string(&doc).unwrap()).unwrap();
}

/// Sky radiance (no sun): a blue gradient above the horizon, brownish ground below.
pub fn sky_radiance(d: Vec3) -> Vec3 {
    if d.y >= 0.0 {
        let horizon = Vec3::new(0.75, 0.85, 1.0);
        let zenith = Vec3::new(0.18, 0.35, 0.85);
        horizon.lerp(zenith, d.y.sqrt())
    } else {
        Vec3::new(0.22, 0.17, 0.12)
    }
}

/// The sky map: 256 × 128, sun disc of 1.5° radius at [`sun_direction`], bright enough that its
/// irradiance at normal incidence is 3× the sky's on a horizontal plane:
/// `L_sun · Ω_sun = 3 ∫_{y>0} L_sky cos θ dω`, Ω_sun = 2π (1 − cos 1.5°). Returns
/// (texels, sun radiance).
pub fn sky_texels() -> (Vec<Vec3>, f32) {
    use facet_render::scene::environment::{luminance, uv_to_direction};
    let (w, h) = (256usize, 128usize);
    let sun = sun_direction();
    let cos_sun = 1.5f32.to_radians().cos();
    let sun_solid_angle = 2.0 * PI * (1.0 - cos_sun);
    // Pixel solid angle: (2π / w)(π / h) sin θ.
    let mut sky_irradiance = 0.0f64;
    let mut texels = Vec::with_capacity(w * h);
    let mut coverage = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            // 8 × 8 supersamples: the disc spans only ~2 pixels.
            let (mut sky, mut hits) = (Vec3::ZERO, 0u32);
            for sy in 0..8 {
                for sx in 0..8 {
                    let uv = glam::Vec2::new(
                        (x as f32 + (sx as f32 + 0.5) / 8.0) / w as f32,
                        (y as f32 + (sy as f32 + 0.5) / 8.0) / h as f32,
                    );
                    let d = uv_to_direction(uv);
                    sky += sky_radiance(d) / 64.0;
                    hits += u32::from(d.dot(sun) >= cos_sun);
                }
            }
            let d = uv_to_direction(glam::Vec2::new(
                (x as f32 + 0.5) / w as f32,
                (y as f32 + 0.5) / h as f32,
            ));
            let d_omega =
                (2.0 * PI / w as f32) * (PI / h as f32) * d.y.clamp(-1.0, 1.0).acos().sin();
            if d.y > 0.0 {
                sky_irradiance += f64::from(luminance(sky) * d.y * d_omega);
            }
            texels.push(sky);
            coverage.push(hits as f32 / 64.0);
        }
    }
    let sun_radiance = 3.0 * sky_irradiance as f32 / sun_solid_angle;
    for (t, c) in texels.iter_mut().zip(coverage) {
        *t = *t * (1.0 - c) + Vec3::splat(sun_radiance) * c;
    }
    (texels, sun_radiance)
}

/// Writes `sky.exr` (f32 RGB, ZIP) into `dir`.
pub fn write_sky_exr(dir: &Path) {
    use exr::prelude::*;
    let (texels, _) = sky_texels();
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let t = texels[y * 256 + x];
        (t.x, t.y, t.z)
    });
    let layer = Layer::new(
        (256, 128),
        LayerAttributes::named("sky"),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    Image::from_layer(layer)
        .write()
        .to_file(dir.join("sky.exr"))
        .unwrap();
}
