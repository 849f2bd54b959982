//! Oracles of the renderer's loaders: a glTF scene and an OpenEXR environment map as loaded.

use crate::brdf::brdf_sane;
use facet_render::scene::{EnvironmentMap, Light, Scene};
use glam::{Vec2, Vec3};

/// Everything the renderer relies on in a loaded scene: attributes per vertex, unit normals and
/// tangents, indices and materials in range, finite factors, sane fits, textures of their size,
/// a usable camera and finite lights.
pub fn scene_sane(scene: &Scene) -> Result<(), String> {
    vertices_sane(scene)?;
    materials_sane(scene)?;
    camera_and_lights_sane(scene)
}

/// Attributes per vertex, unit normals and tangents, triangles whose vertices exist.
fn vertices_sane(scene: &Scene) -> Result<(), String> {
    let n = scene.positions.len();
    if scene.normals.len() != n || scene.uvs.len() != n || scene.tangents.len() != n {
        return Err(format!(
            "{n} positions, {} normals, {} UVs, {} tangents",
            scene.normals.len(),
            scene.uvs.len(),
            scene.tangents.len()
        ));
    }
    if scene.indices.is_empty() || scene.triangle_material.len() != scene.indices.len() {
        return Err(format!(
            "{} triangles, {} triangle materials",
            scene.indices.len(),
            scene.triangle_material.len()
        ));
    }
    if let Some(p) = scene.positions.iter().find(|p| !p.is_finite()) {
        return Err(format!("a position is {p}"));
    }
    if let Some(v) = scene.normals.iter().find(|v| !unit(**v)) {
        return Err(format!("a normal is {v}"));
    }
    if let Some(t) = scene
        .tangents
        .iter()
        .find(|t| !unit(t.truncate()) || t.w.abs() != 1.0)
    {
        return Err(format!("a tangent is {t}"));
    }
    if let Some(uv) = scene.uvs.iter().find(|uv: &&Vec2| !uv.is_finite()) {
        return Err(format!("a UV is {uv}"));
    }
    if let Some(t) = scene
        .indices
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(format!("triangle {t:?} with {n} vertices"));
    }
    Ok(())
}

/// Triangle materials that exist; finite factors, textures that exist and sane fits; textures
/// of their size.
fn materials_sane(scene: &Scene) -> Result<(), String> {
    let materials = scene.materials.len();
    if let Some(m) = scene
        .triangle_material
        .iter()
        .find(|&&m| m as usize >= materials)
    {
        return Err(format!("triangle material {m} of {materials}"));
    }
    for m in &scene.materials {
        let scalars = [m.metallic, m.roughness, m.specular, m.normal_scale];
        if !(m.base_color.is_finite()
            && m.emissive.is_finite()
            && scalars.iter().all(|x| x.is_finite()))
        {
            return Err(format!(
                "material `{}` has a non-finite factor: {m:?}",
                m.name
            ));
        }
        let textures = [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.normal_texture,
            m.emissive_texture,
        ];
        if let Some(t) = textures
            .iter()
            .flatten()
            .find(|&&t| t as usize >= scene.textures.len())
        {
            return Err(format!(
                "material `{}` uses texture {t} of {}",
                m.name,
                scene.textures.len()
            ));
        }
        if let Some(facet) = &m.facet {
            brdf_sane(&format!("the fit of material `{}`", m.name), &*facet.fit)?;
        }
    }
    for t in &scene.textures {
        if t.texels.len() != t.width as usize * t.height as usize || t.texels.is_empty() {
            return Err(format!(
                "texture `{}`: {} texels for {}×{}",
                t.name,
                t.texels.len(),
                t.width,
                t.height
            ));
        }
    }
    Ok(())
}

/// A camera with unit, orthogonal axes and a field of view in (0, π); finite lights.
fn camera_and_lights_sane(scene: &Scene) -> Result<(), String> {
    let c = &scene.camera;
    if !(c.position.is_finite()
        && unit(c.forward)
        && unit(c.up)
        && c.forward.dot(c.up).abs() < 1e-3
        && c.yfov > 0.0
        && c.yfov < std::f32::consts::PI)
    {
        return Err(format!("camera {c:?}"));
    }
    for light in &scene.lights {
        let ok = match *light {
            Light::Point {
                position,
                intensity,
            } => position.is_finite() && intensity.is_finite(),
            Light::Spot {
                position,
                direction,
                intensity,
                inner_cone,
                outer_cone,
            } => {
                position.is_finite()
                    && unit(direction)
                    && intensity.is_finite()
                    && inner_cone.is_finite()
                    && outer_cone.is_finite()
            }
            Light::Directional {
                direction,
                irradiance,
            } => unit(direction) && irradiance.is_finite(),
        };
        if !ok {
            return Err(format!("light {light:?}"));
        }
    }
    Ok(())
}

/// Everything the renderer relies on in a loaded environment map: texels finite and
/// non-negative, a marginal CDF monotone in [0, 1] with a finite positive total, and samples,
/// pdfs and lookups that are finite.
pub fn env_sane(map: &EnvironmentMap) -> Result<(), String> {
    let (w, h) = (map.width as usize, map.height as usize);
    if w == 0 || h == 0 || map.texels.len() != w * h {
        return Err(format!("{} texels for {w}×{h}", map.texels.len()));
    }
    if let Some(t) = map
        .texels
        .iter()
        .find(|t| !(t.is_finite() && t.min_element() >= 0.0))
    {
        return Err(format!("a texel is {t}"));
    }
    let monotone = |cdf: &[f32]| {
        cdf.windows(2).all(|p| p[0] <= p[1]) && cdf.iter().all(|x| (0.0..=1.0).contains(x))
    };
    if map.marginal_cdf.len() != h + 1
        || !monotone(&map.marginal_cdf)
        || !(map.total.is_finite() && map.total > 0.0)
    {
        return Err(format!(
            "marginal CDF {:?}…, total {}",
            &map.marginal_cdf[..map.marginal_cdf.len().min(4)],
            map.total
        ));
    }
    for u in [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.999, 0.001),
    ] {
        let (d, pdf, radiance) = map.sample(u);
        if !(unit(d) && pdf.is_finite() && pdf >= 0.0 && radiance.is_finite()) {
            return Err(format!("sample({u}) = ({d}, {pdf}, {radiance})"));
        }
        if !map.pdf(d).is_finite() || !map.lookup(d).is_finite() {
            return Err(format!("pdf or lookup at {d} not finite"));
        }
    }
    Ok(())
}

/// A finite vector of unit length (to 1e-3).
fn unit(v: Vec3) -> bool {
    v.is_finite() && (v.length() - 1.0).abs() < 1e-3
}
