//! glTF 2.0 (`.gltf` and `.glb`) → [`Scene`].
//!
//! The default scene (or the first) is walked from its roots; every node's world matrix is
//! `M_world = M_parent · M_local` (glTF column vectors, `matrix` or `T · R · S`). Each mesh
//! primitive of mode Triangles is flattened into world space: positions `p' = M p`, normals
//! `n' = normalize((M₃⁻¹)ᵀ n)`, tangents `t' = normalize(M₃ t)` (w kept, negated with the winding);
//! a transform with `det M₃ < 0` mirrors, so its triangles' winding is flipped to keep the
//! front faces where the normals point. Degenerate triangles are dropped with one warning per
//! mesh ([`super::mesh::clean_primitive`]).
//!
//! Camera: the first node with a perspective camera, or [`LoadOptions::camera`] by camera index
//! or name; position = the node's origin, forward = its −Z, up = its +Y. Without any, a
//! framing default looks at the bounds' centre from direction `normalize(0, 0.35, 1)`,
//! `distance = r / sin(yfov / 2)` with r the bounding-sphere radius and yfov = 45°.
//!
//! Lights: KHR_lights_punctual on nodes, `intensity × color` (candela for point and spot, lux
//! for directional), direction = the node's −Z. `range` is ignored: the renderer uses the
//! physical inverse-square falloff everywhere, which is what glTF prescribes inside the range.

use super::gltf_material::MaterialLoader;
use super::mesh::{RawPrimitive, clean_primitive};
use super::{Camera, Light, Material, Scene};
use crate::error::RenderError;
use facet_fit::input::{self, Cap};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::khr_lights_punctual::Kind;
use std::path::{Path, PathBuf};

/// How to load a glTF scene.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// The camera to use, by camera index or name; `None`: the first node with a perspective
    /// camera.
    pub camera: Option<String>,
    /// `--material NAME=FILE`: attach the fitted material FILE to the glTF material NAME
    /// (model tabulated unless the material's extras say otherwise). An unknown NAME is an error.
    pub materials: Vec<(String, PathBuf)>,
}

/// Vertical field of view of the framing default camera: 45°.
pub const DEFAULT_YFOV: f32 = std::f32::consts::FRAC_PI_4;

/// Loads a glTF 2.0 file into a world-space [`Scene`]. Bad input is a [`RenderError::Input`]
/// naming the file; a scene without any renderable triangle is a [`RenderError::Scene`].
/// The file is read through [`facet_fit::input`] (a regular file of at most
/// [`Cap::GLTF`](facet_fit::input::Cap::GLTF) bytes), then [`load_gltf_bytes`].
pub fn load_gltf(path: &Path, options: &LoadOptions) -> Result<Scene, RenderError> {
    let bytes = input::read(path, Cap::GLTF)?;
    load_gltf_bytes(path, &bytes, options)
}

/// [`load_gltf`] of a glTF JSON or `.glb` already in memory: `path` names it in messages and
/// is where relative URIs (buffers, images, fits) are resolved from.
pub fn load_gltf_bytes(
    path: &Path,
    bytes: &[u8],
    options: &LoadOptions,
) -> Result<Scene, RenderError> {
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice(bytes).map_err(|e| RenderError::input(path, describe(e)))?;
    let base = path.parent().unwrap_or(Path::new(""));
    let buffers = gltf::import_buffers(&document, Some(base), blob)
        .map_err(|e| RenderError::input(path, format!("loading buffers: {}", describe(e))))?;

    let mut scene = Scene::default();
    let mut loader = MaterialLoader::new(path, &buffers, &options.materials);
    scene.materials = loader.load_all(&document, &mut scene.textures, &mut scene.warnings)?;

    let placed = walk_nodes(path, &document, &mut scene.warnings)?;
    let mut default_material = None;
    for (node, world) in &placed {
        if let Some(mesh) = node.mesh() {
            add_mesh(
                &mut scene,
                &mesh,
                *world,
                &buffers,
                path,
                &mut default_material,
            )?;
        }
        if let Some(light) = node.light() {
            scene.lights.extend(world_light(&light, *world));
        }
    }
    if scene.indices.is_empty() {
        return Err(RenderError::Scene(format!(
            "{} has no triangles",
            path.display()
        )));
    }
    scene.camera = choose_camera(path, &document, &placed, options, &mut scene)?;
    Ok(scene)
}

/// A gltf error in words (its Display for I/O says only "Io error").
fn describe(e: gltf::Error) -> String {
    match e {
        gltf::Error::Io(io) => io.to_string(),
        other => other.to_string(),
    }
}

/// Nodes of the default (or first) scene with their world matrices, depth-first, parents first.
/// Nodes under a non-finite transform are skipped with a warning.
fn walk_nodes<'a>(
    path: &Path,
    doc: &'a gltf::Document,
    warnings: &mut Vec<String>,
) -> Result<Vec<(gltf::Node<'a>, Mat4)>, RenderError> {
    let Some(root) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Ok(Vec::new());
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, Mat4)> = root.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    let mut placed = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        // glTF forbids a node with two parents; a file that has one (or a cycle) would make
        // this walk repeat or never end.
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(RenderError::input(
                path,
                format!(
                    "node {} is reached twice (a cycle or two parents)",
                    node.index()
                ),
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            warnings.push(format!(
                "node {} has a non-finite transform; it and its children are skipped",
                node_name(&node)
            ));
            continue;
        }
        let first_child = stack.len();
        stack.extend(node.children().map(|c| (c, world)));
        stack[first_child..].reverse();
        placed.push((node, world));
    }
    Ok(placed)
}

fn node_name(n: &gltf::Node) -> String {
    n.name()
        .map_or(format!("{}", n.index()), |s| format!("`{s}`"))
}

/// Appends every triangle primitive of `mesh`, placed by `world`.
fn add_mesh(
    scene: &mut Scene,
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &[gltf::buffer::Data],
    path: &Path,
    default_material: &mut Option<u32>,
) -> Result<(), RenderError> {
    let mesh_name = mesh
        .name()
        .map_or(format!("mesh {}", mesh.index()), |n| format!("mesh `{n}`"));
    let m3 = Mat3::from_mat4(world);
    // Normals transform by the inverse transpose; a singular M leaves them to be generated.
    let normal_matrix = (m3.determinant() != 0.0).then(|| m3.inverse().transpose());
    let mirrored = m3.determinant() < 0.0;
    let mut dropped = 0;
    for prim in mesh.primitives() {
        if prim.mode() != gltf::mesh::Mode::Triangles {
            scene.warnings.push(format!(
                "{mesh_name}: primitive {} has mode {:?}, not Triangles; skipped",
                prim.index(),
                prim.mode()
            ));
            continue;
        }
        let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let Some(positions) = reader.read_positions() else {
            scene.warnings.push(format!(
                "{mesh_name}: primitive {} has no readable POSITION; skipped",
                prim.index()
            ));
            continue;
        };
        let positions: Vec<Vec3> = positions
            .map(|p| world.transform_point3(p.into()))
            .collect();
        let n = positions.len();
        let bad = |what: &str| {
            RenderError::input(
                path,
                format!("{mesh_name}, primitive {}: {what}", prim.index()),
            )
        };
        // An attribute whose count differs from POSITION's is broken: refuse it.
        let same_count = |len: usize, what: &str| {
            if len == n {
                Ok(())
            } else {
                Err(bad(&format!("{what} has {len} elements for {n} positions")))
            }
        };
        let normals = match (reader.read_normals(), normal_matrix) {
            (Some(it), Some(nm)) => {
                let v: Vec<Vec3> = it.map(|v| nm * Vec3::from(v)).collect();
                same_count(v.len(), "NORMAL")?;
                Some(v)
            }
            _ => None,
        };
        let uvs = match reader.read_tex_coords(0) {
            Some(it) => {
                let v: Vec<Vec2> = it.into_f32().map(Vec2::from).collect();
                same_count(v.len(), "TEXCOORD_0")?;
                Some(v)
            }
            None => None,
        };
        let tangents = match reader.read_tangents() {
            Some(it) => {
                // t' = M₃ t; a mirror reverses the bitangent's handedness: w' = −w.
                let sign = if mirrored { -1.0 } else { 1.0 };
                let v: Vec<Vec4> = it
                    .map(|t| (m3 * Vec3::new(t[0], t[1], t[2])).extend(t[3] * sign))
                    .collect();
                same_count(v.len(), "TANGENT")?;
                Some(v)
            }
            None => None,
        };
        let flat: Vec<u32> = match reader.read_indices() {
            Some(it) => it.into_u32().collect(),
            None => (0..n as u32).collect(),
        };
        if !flat.len().is_multiple_of(3) {
            return Err(bad(&format!(
                "{} indices is not a multiple of 3",
                flat.len()
            )));
        }
        if let Some(&i) = flat.iter().find(|&&i| i as usize >= n) {
            return Err(bad(&format!("index {i} out of range ({n} vertices)")));
        }
        let indices = flat
            .chunks_exact(3)
            .map(|t| {
                if mirrored {
                    [t[0], t[2], t[1]]
                } else {
                    [t[0], t[1], t[2]]
                }
            })
            .collect();
        let clean = clean_primitive(RawPrimitive {
            positions,
            normals,
            uvs,
            tangents,
            indices,
        });
        dropped += clean.dropped;
        let material = match prim.material().index() {
            Some(i) => i as u32,
            None => *default_material.get_or_insert_with(|| {
                scene.materials.push(Material::default());
                scene.materials.len() as u32 - 1
            }),
        };
        let offset = scene.positions.len() as u32;
        scene
            .indices
            .extend(clean.indices.iter().map(|t| t.map(|i| i + offset)));
        scene
            .triangle_material
            .extend(std::iter::repeat_n(material, clean.indices.len()));
        scene.positions.extend(clean.positions);
        scene.normals.extend(clean.normals);
        scene.uvs.extend(clean.uvs);
        scene.tangents.extend(clean.tangents);
    }
    if dropped > 0 {
        scene.warnings.push(format!(
            "{mesh_name}: dropped {dropped} triangle(s) with zero area or non-finite positions"
        ));
    }
    Ok(())
}

/// A punctual light placed by its node's world matrix; `None` when it is not finite.
fn world_light(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Option<Light> {
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z).try_normalize()?;
    // Radiometric strength = colour × intensity (cd for point/spot, lx for directional).
    let intensity = Vec3::from(light.color()) * light.intensity();
    if !(intensity.is_finite() && position.is_finite()) {
        return None;
    }
    Some(match light.kind() {
        Kind::Directional => Light::Directional {
            direction,
            irradiance: intensity,
        },
        Kind::Point => Light::Point {
            position,
            intensity,
        },
        Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => Light::Spot {
            position,
            direction,
            intensity,
            inner_cone: inner_cone_angle,
            outer_cone: outer_cone_angle,
        },
    })
}

/// The requested camera, the first one in the scene, or the framing default (with a warning).
fn choose_camera(
    path: &Path,
    doc: &gltf::Document,
    placed: &[(gltf::Node, Mat4)],
    options: &LoadOptions,
    scene: &mut Scene,
) -> Result<Camera, RenderError> {
    let perspective = |c: &gltf::Camera| match c.projection() {
        gltf::camera::Projection::Perspective(p) => Some(p.yfov()),
        gltf::camera::Projection::Orthographic(_) => None,
    };
    let from_node = |yfov: f32, world: Mat4| -> Result<Camera, RenderError> {
        let position = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(Vec3::NEG_Z).try_normalize();
        let up = world.transform_vector3(Vec3::Y);
        // Gram–Schmidt: up ⟂ forward.
        let up = forward.and_then(|f| (up - f * f.dot(up)).try_normalize());
        match (forward, up) {
            (Some(forward), Some(up))
                if position.is_finite() && yfov.is_finite() && yfov > 0.0 && yfov < 3.1 =>
            {
                Ok(Camera {
                    position,
                    forward,
                    up,
                    yfov,
                })
            }
            _ => Err(RenderError::Scene(format!(
                "{}: the camera's node transform or yfov ({yfov}) is degenerate",
                path.display()
            ))),
        }
    };
    if let Some(wanted) = &options.camera {
        let camera = doc
            .cameras()
            .find(|c| c.index().to_string() == *wanted || c.name().is_some_and(|n| n == wanted));
        let available: Vec<String> = doc
            .cameras()
            .map(|c| match c.name() {
                Some(n) => format!("{} `{n}`", c.index()),
                None => c.index().to_string(),
            })
            .collect();
        let Some(camera) = camera else {
            return Err(RenderError::input(
                path,
                format!("no camera `{wanted}` (available: {available:?})"),
            ));
        };
        let yfov = perspective(&camera).ok_or_else(|| {
            RenderError::input(path, format!("camera `{wanted}` is not perspective"))
        })?;
        let world = placed
            .iter()
            .find(|(n, _)| n.camera().is_some_and(|c| c.index() == camera.index()))
            .map(|(_, w)| *w)
            .ok_or_else(|| {
                RenderError::input(
                    path,
                    format!("camera `{wanted}` is on no node of the scene"),
                )
            })?;
        return from_node(yfov, world);
    }
    for (node, world) in placed {
        if let Some(yfov) = node.camera().as_ref().and_then(perspective) {
            return from_node(yfov, *world);
        }
    }
    scene
        .warnings
        .push("no camera in the scene; using a framing default".into());
    Ok(framing_camera(scene.bounds()))
}

/// Looks at the centre of `(lo, hi)` from `normalize(0, 0.35, 1)`, far enough that the bounding
/// sphere (radius r = |hi − lo| / 2) fits a 45° yfov: `distance = r / sin(yfov / 2)`.
pub fn framing_camera((lo, hi): (Vec3, Vec3)) -> Camera {
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let dir = Vec3::new(0.0, 0.35, 1.0).normalize();
    let forward = -dir;
    let up = (Vec3::Y - forward * forward.dot(Vec3::Y)).normalize();
    Camera {
        position: centre + dir * (radius / (DEFAULT_YFOV * 0.5).sin()),
        forward,
        up,
        yfov: DEFAULT_YFOV,
    }
}
