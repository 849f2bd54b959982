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
//!
//! Hostile input is an error naming the file and the field at fault, or (for what only costs a
//! texture, a light or an unused camera) a warning; never a panic, a hang or a huge allocation:
//! - files are read through [`facet_brdf::io::input`]: regular files only (no FIFO, device,
//!   directory), each under its [`Cap`];
//! - buffers are loaded here (`gltf_buffers`): the GLB chunk, `data:` URIs, relative
//!   files; absolute paths and schemes refused ([`super::uri`]); their bytes cover byteLength;
//! - a GLB header is checked before the `gltf` crate reads it;
//! - every accessor read, every camera and every light is checked first ([`super::gltf_check`]);
//! - a scene holds at most [`MAX_VERTICES`] vertices and [`MAX_TRIANGLES`] triangles, counting a
//!   mesh once per node it is placed on;
//! - textures: see [`super::gltf_material`];
//! - whatever still panics inside the `gltf` crate is caught ([`load_gltf_bytes`]).

use super::gltf_buffers::Buffers;
use super::gltf_check::{
    Attribute, CameraKind, MAX_TRIANGLES, MAX_VERTICES, check_accessor, check_camera, check_light,
};
use super::gltf_material::MaterialLoader;
use super::mesh::{CleanPrimitive, RawPrimitive, clean_primitive};
use super::{Camera, Light, Material, Scene};
use crate::error::RenderError;
use facet_brdf::io::input::{self, Cap};
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
    /// The neural proxy file `nbrdf:` measurements resolve in (`--nbrdf`); `None`:
    /// `$FACET_NBRDF`, else the embedded proxies, as in every command.
    pub nbrdf: Option<PathBuf>,
}

/// Vertical field of view of the framing default camera: 45°.
pub const DEFAULT_YFOV: f32 = std::f32::consts::FRAC_PI_4;

/// Loads a glTF 2.0 file into a world-space [`Scene`]. Bad input is a [`RenderError::Input`]
/// naming the file; a scene without any renderable triangle is a [`RenderError::Scene`].
/// The file is read through [`facet_brdf::io::input`] (a regular file of at most
/// [`Cap::GLTF`](facet_brdf::io::input::Cap::GLTF) bytes), then [`load_gltf_bytes`].
pub fn load_gltf(path: &Path, options: &LoadOptions) -> Result<Scene, RenderError> {
    let (bytes, own) = input::recording(|| input::read(path, Cap::GLTF));
    let mut scene = load_gltf_bytes(path, &bytes?, options)?;
    scene.inputs.splice(0..0, own);
    Ok(scene)
}

/// [`load_gltf`] of a glTF JSON or `.glb` already in memory: `path` names it in messages and
/// is where relative URIs (buffers, images, fits) are resolved from. [`Scene::inputs`] lists
/// the files it read, as [`input::recording`] saw them (not `path`: its bytes were given).
///
/// Hostile input is an error naming the file and what is wrong with it (see
/// [`super::gltf_check`]); should the `gltf` crate still panic, the panic is caught and becomes
/// a [`RenderError::Input`] too ("internal error while reading the glTF …; please report it").
/// The default panic hook still prints that panic to stderr: silencing it would need the
/// process-wide hook, which other threads share.
pub fn load_gltf_bytes(
    path: &Path,
    bytes: &[u8],
    options: &LoadOptions,
) -> Result<Scene, RenderError> {
    let (scene, read) =
        input::recording(|| guard(path, "the glTF", || load_document(path, bytes, options)));
    let mut scene = scene?;
    scene.inputs = read;
    Ok(scene)
}

/// Runs `f`, turning a panic inside it into a [`RenderError::Input`] naming `path`:
/// "internal error while reading {what}: {panic message}; please report it".
pub(crate) fn guard<T>(
    path: &Path,
    what: &str,
    f: impl FnOnce() -> Result<T, RenderError>,
) -> Result<T, RenderError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        Err(RenderError::input(
            path,
            format!(
                "internal error while reading {what}: {}; please report it",
                panic_message(payload.as_ref())
            ),
        ))
    })
}

/// The message of a caught panic.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".into()
    }
}

/// The GLB header (magic, version, length) checked before the `gltf` crate reads it: its
/// `length − 12` underflows on a length under 12.
fn check_glb_header(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let word = |i: usize| {
        bytes
            .get(i..i + 4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(format!(
            "GLB header: {} bytes, shorter than the 12-byte header",
            bytes.len()
        ));
    };
    if version != 2 {
        return Err(format!("GLB header: version {version}, not 2"));
    }
    if length < 20 {
        return Err(format!(
            "GLB header: length {length} is shorter than a header and one chunk header (20 bytes)"
        ));
    }
    if length as usize > bytes.len() {
        return Err(format!(
            "GLB header: length {length} but the file has {} bytes (truncated?)",
            bytes.len()
        ));
    }
    Ok(())
}

fn load_document(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Scene, RenderError> {
    check_glb_header(bytes).map_err(|m| RenderError::input(path, m))?;
    let gltf::Gltf { document, blob } =
        gltf::Gltf::from_slice(bytes).map_err(|e| RenderError::input(path, describe(e)))?;
    let buffers = Buffers::load(path, &document, blob)?;

    let mut scene = Scene::default();
    let mut loader = MaterialLoader::new(path, &buffers, &options.materials);
    loader.nbrdf = options.nbrdf.as_deref();
    scene.materials = loader.load_all(&document, &mut scene.textures, &mut scene.warnings)?;

    let placed = walk_nodes(path, &document, &mut scene.warnings)?;
    let mut default_material = None;
    for (node, world) in &placed {
        if let Some(mesh) = node.mesh() {
            add_mesh(
                &mut scene,
                &document,
                &mesh,
                *world,
                &buffers,
                path,
                &mut default_material,
            )?;
        }
        if let Some(light) = node.light() {
            match check_light(&light) {
                Ok(()) => scene.lights.extend(world_light(&light, *world)),
                Err(problem) => scene.warnings.push(format!(
                    "light {} on node {}: {problem}; skipped",
                    light.index(),
                    node_name(node)
                )),
            }
        }
    }
    if scene.indices.is_empty() {
        let why = if scene.warnings.is_empty() {
            String::new()
        } else {
            let shown: Vec<&str> = scene.warnings.iter().take(8).map(String::as_str).collect();
            let more = scene.warnings.len().saturating_sub(shown.len());
            format!(
                " ({}{})",
                shown.join("; "),
                if more > 0 {
                    format!("; and {more} more")
                } else {
                    String::new()
                }
            )
        };
        return Err(RenderError::Scene(format!(
            "{} has no triangles{why}",
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
        // One entry per bad value: a hostile file can have millions.
        gltf::Error::Validation(list) => {
            let shown: Vec<String> = list
                .iter()
                .take(10)
                .map(|(p, e)| format!("{p}: {e}"))
                .collect();
            let more = list.len().saturating_sub(shown.len());
            format!(
                "invalid glTF: {}{}",
                shown.join("; "),
                if more > 0 {
                    format!("; and {more} more")
                } else {
                    String::new()
                }
            )
        }
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

/// Appends every triangle primitive of `mesh`, placed by `world`. Every accessor read is
/// checked first ([`check_accessor`]), and so are the counts against POSITION's and the scene's
/// totals against [`MAX_VERTICES`] and [`MAX_TRIANGLES`] (a mesh placed on many nodes is read
/// once per node).
fn add_mesh(
    scene: &mut Scene,
    doc: &gltf::Document,
    mesh: &gltf::Mesh,
    world: Mat4,
    buffers: &Buffers,
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
    let root = doc.as_json();
    for prim in mesh.primitives() {
        if prim.mode() != gltf::mesh::Mode::Triangles {
            scene.warnings.push(format!(
                "{mesh_name}: primitive {} has mode {:?}, not Triangles; skipped",
                prim.index(),
                prim.mode()
            ));
            continue;
        }
        let Some(position_accessor) = prim.get(&gltf::Semantic::Positions) else {
            scene.warnings.push(format!(
                "{mesh_name}: primitive {} has no POSITION; skipped",
                prim.index()
            ));
            continue;
        };
        check_primitive(
            scene,
            root,
            &prim,
            position_accessor,
            &mesh_name,
            path,
            buffers,
        )?;
        let reader = prim.reader(|b| buffers.get(b.index()));
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
        let indices = triangles(reader.read_indices(), n, mirrored).map_err(|what| bad(&what))?;
        let clean = clean_primitive(RawPrimitive {
            positions,
            normals,
            uvs,
            tangents,
            indices,
        });
        dropped += clean.dropped;
        let material = primitive_material(scene, &prim, default_material);
        append_primitive(scene, clean, material);
    }
    if dropped > 0 {
        scene.warnings.push(format!(
            "{mesh_name}: dropped {dropped} triangle(s) with zero area or non-finite positions"
        ));
    }
    Ok(())
}

/// The primitive's material, or the scene's default one (added on first use).
fn primitive_material(
    scene: &mut Scene,
    prim: &gltf::Primitive,
    default_material: &mut Option<u32>,
) -> u32 {
    match prim.material().index() {
        Some(i) => i as u32,
        None => *default_material.get_or_insert_with(|| {
            scene.materials.push(Material::default());
            scene.materials.len() as u32 - 1
        }),
    }
}

/// Appends a cleaned primitive to the scene, its triangles of `material`.
fn append_primitive(scene: &mut Scene, clean: CleanPrimitive, material: u32) {
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

/// Checks every accessor a triangle primitive is read through ([`check_accessor`]), their
/// counts against POSITION's, and the scene's totals with it against [`MAX_VERTICES`] and
/// [`MAX_TRIANGLES`], before any reader runs.
fn check_primitive(
    scene: &Scene,
    root: &gltf::json::Root,
    prim: &gltf::Primitive,
    position_accessor: gltf::Accessor,
    mesh_name: &str,
    path: &Path,
    buffers: &Buffers,
) -> Result<(), RenderError> {
    let buffer_len = |i: usize| buffers.len_of(i);
    // The accessors this primitive is read through, checked before any reader runs.
    let attributes = [
        (Attribute::Position, Some(position_accessor)),
        (Attribute::Normal, prim.get(&gltf::Semantic::Normals)),
        (Attribute::Tangent, prim.get(&gltf::Semantic::Tangents)),
        (
            Attribute::TexCoord0,
            prim.get(&gltf::Semantic::TexCoords(0)),
        ),
        (Attribute::Indices, prim.indices()),
    ];
    let n_positions = root
        .accessors
        .get(attributes[0].1.as_ref().map_or(0, |a| a.index()))
        .map_or(0, |a| a.count.0);
    for (attribute, accessor) in &attributes {
        let Some(accessor) = accessor else { continue };
        let at_fault = |problem: String| {
            RenderError::input(
                path,
                format!(
                    "accessor {} ({} of {mesh_name}, primitive {}): {problem}",
                    accessor.index(),
                    attribute.name(),
                    prim.index()
                ),
            )
        };
        check_accessor(root, accessor.index(), *attribute, &buffer_len).map_err(at_fault)?;
        let count = root.accessors[accessor.index()].count.0;
        if *attribute != Attribute::Indices && count != n_positions {
            return Err(at_fault(format!(
                "count {count} differs from POSITION's {n_positions}"
            )));
        }
        if *attribute == Attribute::Indices && !count.is_multiple_of(3) {
            return Err(at_fault(format!("count {count} is not a multiple of 3")));
        }
    }
    let n_triangles = match &attributes[4].1 {
        Some(a) => root.accessors[a.index()].count.0 / 3,
        None => n_positions / 3,
    };
    if scene.positions.len() as u64 + n_positions > MAX_VERTICES
        || scene.indices.len() as u64 + n_triangles > MAX_TRIANGLES
    {
        return Err(RenderError::input(
            path,
            format!(
                "{mesh_name}, primitive {}: the scene would have more than {MAX_VERTICES} vertices or {MAX_TRIANGLES} triangles (a mesh placed on many nodes counts once per node)",
                prim.index()
            ),
        ));
    }
    Ok(())
}

/// The primitive's triangles (its indices, or the vertices in order without), each in range
/// of `n` vertices, wound the other way under a mirroring transform.
fn triangles(
    read: Option<gltf::mesh::util::ReadIndices<'_>>,
    n: usize,
    mirrored: bool,
) -> Result<Vec<[u32; 3]>, String> {
    let flat: Vec<u32> = match read {
        Some(it) => it.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    if !flat.len().is_multiple_of(3) {
        return Err(format!("{} indices is not a multiple of 3", flat.len()));
    }
    if let Some(&i) = flat.iter().find(|&&i| i as usize >= n) {
        return Err(format!("index {i} out of range ({n} vertices)"));
    }
    Ok(flat
        .chunks_exact(3)
        .map(|t| {
            if mirrored {
                [t[0], t[2], t[1]]
            } else {
                [t[0], t[1], t[2]]
            }
        })
        .collect())
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

/// The requested camera, the first perspective one in the scene, or the framing default (with a
/// warning).
///
/// Every camera is checked from its JSON ([`check_camera`]) before the `gltf` crate's
/// `projection()` (which panics when `type` has no matching block) is ever called. The camera
/// used is `--camera`, or else the first placed node whose camera's `type` is perspective: if it
/// fails the check, that is an error naming it. Any other camera that fails is not used and only
/// gets a warning.
fn choose_camera(
    path: &Path,
    doc: &gltf::Document,
    placed: &[(gltf::Node, Mat4)],
    options: &LoadOptions,
    scene: &mut Scene,
) -> Result<Camera, RenderError> {
    let cameras = &doc.as_json().cameras;
    let label = |c: &gltf::Camera| match c.name() {
        Some(n) => format!("camera {} `{n}`", c.index()),
        None => format!("camera {}", c.index()),
    };
    let from_node = |label: &str, yfov: f32, world: Mat4| -> Result<Camera, RenderError> {
        let position = world.transform_point3(Vec3::ZERO);
        let forward = world.transform_vector3(Vec3::NEG_Z).try_normalize();
        let up = world.transform_vector3(Vec3::Y);
        // Gram–Schmidt: up ⟂ forward.
        let up = forward.and_then(|f| (up - f * f.dot(up)).try_normalize());
        // The pinhole of [`crate::scene::camera_frame::CameraFrame`] needs yfov in [1e-4, π − 1e-3].
        if !(yfov > 1e-4 && yfov < std::f32::consts::PI - 1e-3) {
            return Err(RenderError::input(
                path,
                format!("{label}: yfov {yfov} is too close to 0 or π to render"),
            ));
        }
        match (forward, up) {
            (Some(forward), Some(up)) if position.is_finite() => Ok(Camera {
                position,
                forward,
                up,
                yfov,
            }),
            _ => Err(RenderError::Scene(format!(
                "{}: {label}: its node transform is degenerate",
                path.display()
            ))),
        }
    };
    // The camera used, with its world matrix.
    let (used, world) = if let Some(wanted) = &options.camera {
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
        (Some(camera), world)
    } else {
        let perspective = |c: &gltf::Camera| {
            matches!(
                cameras[c.index()].type_,
                gltf::json::validation::Checked::Valid(gltf::json::camera::Type::Perspective)
            )
        };
        placed
            .iter()
            .find_map(|(n, w)| n.camera().filter(perspective).map(|c| (Some(c), *w)))
            .unwrap_or((None, Mat4::IDENTITY))
    };
    for c in doc.cameras() {
        if used.as_ref().is_some_and(|u| u.index() == c.index()) {
            continue;
        }
        if let Err(problem) = check_camera(&cameras[c.index()]) {
            scene
                .warnings
                .push(format!("{}: {problem}; not used", label(&c)));
        }
    }
    let Some(camera) = used else {
        scene
            .warnings
            .push("no camera in the scene; using a framing default".into());
        return Ok(framing_camera(scene.bounds()));
    };
    let name = label(&camera);
    match check_camera(&cameras[camera.index()]) {
        Ok(CameraKind::Perspective(yfov)) => from_node(&name, yfov, world),
        Ok(CameraKind::Orthographic) => Err(RenderError::input(
            path,
            format!("{name} is not perspective (orthographic cameras are not supported)"),
        )),
        Err(problem) => Err(RenderError::input(path, format!("{name}: {problem}"))),
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_an_error_naming_the_file() {
        let e = guard(Path::new("s.gltf"), "the glTF", || -> Result<(), _> {
            panic!("index out of bounds: the len is 3 but the index is 7")
        })
        .unwrap_err()
        .to_string();
        assert_eq!(
            e,
            "s.gltf: internal error while reading the glTF: index out of bounds: the len is 3 but the index is 7; please report it"
        );
        let n = 7;
        let e = guard(
            Path::new("e.exr"),
            "the OpenEXR image",
            || -> Result<(), _> { panic!("formatted {n}") },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("e.exr") && e.contains("formatted 7"), "{e}");
        assert_eq!(guard(Path::new("x"), "x", || Ok(3)).unwrap(), 3);
    }
}
