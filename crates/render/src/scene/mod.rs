//! Scenes: what the renderer consumes, loaded from glTF 2.0 ([`load_gltf`]) or built in code.
//!
//! Everything is flattened to world space: one indexed triangle list for the whole scene, one
//! material per triangle, textures as RGBA8, punctual lights, one camera. glTF is Y-up and
//! right-handed; so is the scene.

pub use facet_brdf::io::input::FileRead;
use facet_brdf::model::material::ModelChoice;
use glam::{Vec2, Vec3, Vec4};
use std::path::PathBuf;
use std::sync::Arc;

pub mod camera_frame;
pub mod data_uri;
pub mod environment;
pub(crate) mod gltf_buffers;
pub mod gltf_check;
pub mod gltf_file;
pub mod gltf_material;
pub mod measured;
pub mod mesh;
pub mod shapes;
pub mod sphere;
pub mod uri;

pub use camera_frame::CameraFrame;
pub use environment::{Environment, EnvironmentMap};
pub use gltf_file::{LoadOptions, load_gltf, load_gltf_bytes};
pub use measured::{MeasuredMaterial, Measurement};

/// A whole scene in world space.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// World-space vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit shading normals per vertex (generated, area-weighted, when the mesh has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates per vertex (zero when the mesh has none).
    pub uvs: Vec<Vec2>,
    /// Tangent per vertex, xyz unit and w = ±1 the bitangent sign (glTF convention);
    /// generated from UVs when absent (any orthogonal tangent where UVs are degenerate).
    pub tangents: Vec<Vec4>,
    /// Triangles as vertex indices.
    pub indices: Vec<[u32; 3]>,
    /// Index into `materials` per triangle.
    pub triangle_material: Vec<u32>,
    /// The materials that `triangle_material` indexes.
    pub materials: Vec<Material>,
    /// The textures that materials index.
    pub textures: Vec<Texture>,
    /// Punctual lights.
    pub lights: Vec<Light>,
    /// The camera.
    pub camera: Camera,
    /// Messages about things skipped or defaulted (a missing texture, a dropped triangle).
    pub warnings: Vec<String>,
    /// Every file the load read, with the SHA-256 of the bytes it read, in the order first
    /// read: the glTF itself (when [`load_gltf`] read it), its buffers, images, fits,
    /// measurements and the neural proxies' file. A file it could not read and went on
    /// without (a missing texture) is here without a digest. What a render shard's digest is
    /// made of, and what no output of a run may replace.
    pub inputs: Vec<FileRead>,
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position, world space.
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit up vector, orthogonal to `forward`.
    pub up: Vec3,
    /// Vertical field of view, radians.
    pub yfov: f32,
}

impl Default for Camera {
    /// At the origin looking down −Z with +Y up, 45° yfov (glTF's camera convention).
    fn default() -> Self {
        Camera {
            position: Vec3::ZERO,
            forward: Vec3::NEG_Z,
            up: Vec3::Y,
            yfov: std::f32::consts::FRAC_PI_4,
        }
    }
}

/// KHR_materials_clearcoat over a glTF metallic-roughness material, layered as the extension
/// specifies: f = (1 − c F) f_base + c F D_c G2_c / (4 |n_c·ωi| |n_c·ωo|), F = 0.04 + 0.96
/// (1 − |ωo·h|)⁵, D_c GGX of α = roughness² about the coat's normal n_c (the vertex normal, or
/// its own normal map; not the base's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearcoat {
    /// `clearcoatFactor` c (> 0: a factor of 0 is no coat and is not stored).
    pub factor: f32,
    /// `clearcoatTexture`: its R channel multiplies the factor.
    pub texture: Option<u32>,
    /// `clearcoatRoughnessFactor`.
    pub roughness: f32,
    /// `clearcoatRoughnessTexture`: its G channel multiplies the roughness.
    pub roughness_texture: Option<u32>,
    /// `clearcoatNormalTexture`: the coat's tangent-space normal map.
    pub normal_texture: Option<u32>,
    /// The normal map's `scale`.
    pub normal_scale: f32,
}

/// A glTF metallic-roughness material, optionally replaced by a Facet material.
#[derive(Clone, Debug)]
pub struct Material {
    /// The material's name.
    pub name: String,
    /// Linear RGBA base colour factor.
    pub base_color: Vec4,
    /// Texture index of the base colour.
    pub base_color_texture: Option<u32>,
    /// Metalness factor in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness factor in [0, 1].
    pub roughness: f32,
    /// Weight of the dielectric specular layer (KHR_materials_specular `specularFactor`, 1 when
    /// absent); 0 with metallic 0 makes a pure Lambertian surface. Its texture is not read.
    pub specular: f32,
    /// glTF layout: roughness in G, metallic in B.
    pub metallic_roughness_texture: Option<u32>,
    /// Texture index of the tangent-space normal map.
    pub normal_texture: Option<u32>,
    /// Scale of the normal map's xy.
    pub normal_scale: f32,
    /// Linear emitted radiance factor (emissiveFactor × KHR_materials_emissive_strength).
    pub emissive: Vec3,
    /// Texture index of the emission.
    pub emissive_texture: Option<u32>,
    /// KHR_materials_clearcoat: a clear coat over the metallic-roughness material.
    pub clearcoat: Option<Clearcoat>,
    /// A fitted material from `extras.facet` or `--material NAME=FILE`.
    pub facet: Option<FacetMaterial>,
    /// A measured material (`extras.facet.model: "measured"`, or `--material NAME=FILE` naming
    /// a measurement); it takes the place of `facet`.
    pub measured: Option<MeasuredMaterial>,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: "default".into(),
            base_color: Vec4::splat(0.8),
            base_color_texture: None,
            metallic: 0.0,
            roughness: 1.0,
            specular: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emissive: Vec3::ZERO,
            emissive_texture: None,
            clearcoat: None,
            facet: None,
            measured: None,
        }
    }
}

/// A fitted material attached to a glTF material.
#[derive(Clone, Debug)]
pub struct FacetMaterial {
    /// The fit JSON it was loaded from.
    pub source: PathBuf,
    /// The fit.
    pub fit: Arc<facet_brdf::model::material::FittedMaterial>,
    /// Which of its models to render.
    pub model: ModelChoice,
    /// Glint parameters: render the model's NDF as discrete flakes.
    pub glint: Option<GlintParams>,
}

/// Glint parameters of a Facet material (the NDF is the material's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlintParams {
    /// Flakes per unit UV area.
    pub density: f32,
    /// Cone half-angle γ, degrees.
    pub gamma_deg: f32,
    /// Expected count above which the count is replaced by its mean.
    pub threshold: f32,
}

/// An RGBA8 texture; `srgb` says whether RGB is sRGB-encoded (base colour, emissive).
#[derive(Clone, Debug)]
pub struct Texture {
    /// The texture's name (for messages).
    pub name: String,
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Texels, row-major.
    pub texels: Vec<[u8; 4]>,
    /// Whether RGB is sRGB-encoded.
    pub srgb: bool,
}

/// KHR_lights_punctual, in world space. Intensity already multiplied into `color`
/// (W/sr-like radiometric units as glTF defines: candela for point/spot, lux for directional).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// A point light.
    Point {
        /// Position, world space.
        position: Vec3,
        /// Radiant intensity per channel.
        intensity: Vec3,
    },
    /// A spot light.
    Spot {
        /// Position, world space.
        position: Vec3,
        /// Unit direction the light points to.
        direction: Vec3,
        /// Radiant intensity per channel.
        intensity: Vec3,
        /// Angle from the axis where the falloff starts, radians.
        inner_cone: f32,
        /// Angle from the axis where the light ends, radians.
        outer_cone: f32,
    },
    /// `direction` is where the light travels (glTF: the node's −Z).
    Directional {
        /// Unit direction the light travels.
        direction: Vec3,
        /// Irradiance per channel on a surface facing the light.
        irradiance: Vec3,
    },
}

impl Scene {
    /// Axis-aligned bounds of all vertices (min, max).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        )
    }
}
