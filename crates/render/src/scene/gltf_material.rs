//! glTF materials → [`Material`]: metallic-roughness factors and textures, emissive strength,
//! and the Facet extension carried in `extras`:
//!
//! ```json
//! "extras": {"facet": {"fit": "path/to/fit.json", "model": "tabulated|ggx|beckmann",
//!                      "glint": {"density": 1e6, "gamma_deg": 2.0, "threshold": 50.0}}}
//! ```
//!
//! The fit path is relative to the glTF file's folder; `model` defaults to `tabulated`;
//! `glint.density` is required, `gamma_deg` defaults to 2 and `threshold` to 50.
//! Images are decoded here, one at a time, so that a missing or broken image only costs its
//! texture (a warning naming the image and the material), never the whole scene.

use super::data_uri::decode_data_uri;
use super::{FacetMaterial, FacetModel, GlintParams, Material, Texture};
use crate::error::RenderError;
use facet_fit::material::{FittedMaterial, ModelChoice};
use glam::{Vec3, Vec4};
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `extras.facet` of one material, validated; `fit` already resolved against the glTF folder.
#[derive(Clone, Debug, PartialEq)]
pub struct FacetExtras {
    pub fit: Option<PathBuf>,
    pub model: FacetModel,
    pub glint: Option<GlintParams>,
}

/// Parses `extras` (the whole object) of material `material`. `Ok(None)` when it has no `facet`.
pub fn parse_facet_extras(
    gltf_path: &Path,
    material: &str,
    extras: &Value,
) -> Result<Option<FacetExtras>, RenderError> {
    let Some(facet) = extras.get("facet") else {
        return Ok(None);
    };
    let bad = |m: String| RenderError::input(gltf_path, format!("material `{material}`: {m}"));
    let facet = facet
        .as_object()
        .ok_or_else(|| bad("extras.facet is not an object".into()))?;
    let base = gltf_path.parent().unwrap_or(Path::new(""));
    let fit = match facet.get("fit") {
        None => None,
        Some(Value::String(s)) => Some(base.join(s)),
        Some(other) => return Err(bad(format!("extras.facet.fit is not a string: {other}"))),
    };
    let model = match facet.get("model") {
        None => FacetModel::Tabulated,
        Some(Value::String(s)) => match s.as_str() {
            "tabulated" => FacetModel::Tabulated,
            "ggx" => FacetModel::Ggx,
            "beckmann" => FacetModel::Beckmann,
            other => {
                return Err(bad(format!(
                    "unknown extras.facet.model `{other}` (tabulated, ggx or beckmann)"
                )));
            }
        },
        Some(other) => return Err(bad(format!("extras.facet.model is not a string: {other}"))),
    };
    let glint = match facet.get("glint") {
        None => None,
        Some(g) => Some(parse_glint(g).map_err(|m| bad(format!("extras.facet.glint: {m}")))?),
    };
    Ok(Some(FacetExtras { fit, model, glint }))
}

/// Validates glint parameters: density > 0, 0 < γ ≤ 90°, threshold ≥ 0.
fn parse_glint(g: &Value) -> Result<GlintParams, String> {
    let g = g.as_object().ok_or("not an object")?;
    let num = |key: &str, default: Option<f64>| -> Result<f32, String> {
        match g.get(key) {
            None => default
                .map(|d| d as f32)
                .ok_or(format!("`{key}` is required")),
            Some(v) => v
                .as_f64()
                .filter(|x| x.is_finite())
                .map(|x| x as f32)
                .ok_or(format!("`{key}` is not a finite number: {v}")),
        }
    };
    let p = GlintParams {
        density: num("density", None)?,
        gamma_deg: num("gamma_deg", Some(2.0))?,
        threshold: num("threshold", Some(50.0))?,
    };
    if !(p.density > 0.0) {
        return Err(format!("density must be > 0, got {}", p.density));
    }
    if !(p.gamma_deg > 0.0 && p.gamma_deg <= 90.0) {
        return Err(format!("gamma_deg must be in (0, 90], got {}", p.gamma_deg));
    }
    if !(p.threshold >= 0.0) {
        return Err(format!("threshold must be ≥ 0, got {}", p.threshold));
    }
    Ok(p)
}

/// A decoded image: width, height, RGBA8 texels row by row.
type Decoded = (u32, u32, Vec<[u8; 4]>);

/// Builds every material of the document (same indices), its textures and Facet fits.
pub(crate) struct MaterialLoader<'a> {
    pub gltf_path: &'a Path,
    pub buffers: &'a [gltf::buffer::Data],
    /// `--material NAME=FILE` overrides.
    pub overrides: &'a [(String, PathBuf)],
    /// Decoded images by image index (`None`: not tried yet).
    images: HashMap<usize, Result<Decoded, String>>,
    /// Scene texture index by (image index, sRGB).
    textures: HashMap<(usize, bool), u32>,
    fits: HashMap<PathBuf, Arc<FittedMaterial>>,
}

impl<'a> MaterialLoader<'a> {
    pub fn new(
        gltf_path: &'a Path,
        buffers: &'a [gltf::buffer::Data],
        overrides: &'a [(String, PathBuf)],
    ) -> Self {
        MaterialLoader {
            gltf_path,
            buffers,
            overrides,
            images: HashMap::new(),
            textures: HashMap::new(),
            fits: HashMap::new(),
        }
    }

    /// All materials of `doc`, textures appended to `textures`, warnings to `warnings`.
    pub fn load_all(
        &mut self,
        doc: &gltf::Document,
        textures: &mut Vec<Texture>,
        warnings: &mut Vec<String>,
    ) -> Result<Vec<Material>, RenderError> {
        let names: Vec<String> = doc.materials().map(|m| material_name(&m)).collect();
        for (name, _) in self.overrides {
            if !names.contains(name) {
                return Err(RenderError::input(
                    self.gltf_path,
                    format!("--material {name}: no such material (the scene has: {names:?})"),
                ));
            }
        }
        doc.materials()
            .map(|m| self.material(&m, textures, warnings))
            .collect()
    }

    fn material(
        &mut self,
        m: &gltf::Material,
        textures: &mut Vec<Texture>,
        warnings: &mut Vec<String>,
    ) -> Result<Material, RenderError> {
        let name = material_name(m);
        let pbr = m.pbr_metallic_roughness();
        let mut tex = |info: Option<gltf::texture::Texture>, srgb: bool| {
            info.and_then(|t| self.texture(&t.source(), srgb, &name, textures, warnings))
        };
        let base_color_texture = tex(pbr.base_color_texture().map(|i| i.texture()), true);
        let metallic_roughness_texture =
            tex(pbr.metallic_roughness_texture().map(|i| i.texture()), false);
        let normal = m.normal_texture();
        let normal_texture = tex(normal.as_ref().map(|n| n.texture()), false);
        let emissive_texture = tex(m.emissive_texture().map(|i| i.texture()), true);
        // Emitted radiance factor: emissiveFactor × KHR_materials_emissive_strength (default 1).
        let emissive = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        let finite_or = |x: f32, d: f32| if x.is_finite() { x } else { d };
        let base_color = Vec4::from(pbr.base_color_factor());
        Ok(Material {
            base_color: if base_color.is_finite() {
                base_color
            } else {
                Vec4::splat(0.8)
            },
            base_color_texture,
            metallic: finite_or(pbr.metallic_factor(), 0.0).clamp(0.0, 1.0),
            roughness: finite_or(pbr.roughness_factor(), 1.0).clamp(0.0, 1.0),
            specular: finite_or(m.specular().map_or(1.0, |s| s.specular_factor()), 1.0)
                .clamp(0.0, 1.0),
            metallic_roughness_texture,
            normal_texture,
            normal_scale: finite_or(normal.map_or(1.0, |n| n.scale()), 1.0),
            emissive: if emissive.is_finite() {
                emissive.max(Vec3::ZERO)
            } else {
                Vec3::ZERO
            },
            emissive_texture,
            facet: self.facet(m, &name)?,
            name,
        })
    }

    /// The Facet material from extras and/or an override; the override's file wins, the
    /// extras' model and glint stay.
    fn facet(
        &mut self,
        m: &gltf::Material,
        name: &str,
    ) -> Result<Option<FacetMaterial>, RenderError> {
        let extras = match m.extras() {
            Some(raw) => {
                let v: Value = serde_json::from_str(raw.get()).map_err(|e| {
                    RenderError::input(self.gltf_path, format!("material `{name}` extras: {e}"))
                })?;
                parse_facet_extras(self.gltf_path, name, &v)?
            }
            None => None,
        };
        let overridden = self.overrides.iter().rev().find(|(n, _)| n == name);
        let (model, glint) = extras
            .as_ref()
            .map_or((FacetModel::Tabulated, None), |e| (e.model, e.glint));
        let source = match (overridden, extras.as_ref().and_then(|e| e.fit.clone())) {
            (Some((_, file)), _) => file.clone(),
            (None, Some(fit)) => fit,
            (None, None) if extras.is_some() => {
                return Err(RenderError::input(
                    self.gltf_path,
                    format!(
                        "material `{name}`: extras.facet has no `fit` and no --material override"
                    ),
                ));
            }
            (None, None) => return Ok(None),
        };
        let fit = match self.fits.get(&source) {
            Some(f) => f.clone(),
            None => {
                let f = FittedMaterial::load(&source).map_err(|e| {
                    RenderError::input(&source, format!("fit of material `{name}`: {e}"))
                })?;
                let f = Arc::new(f);
                self.fits.insert(source.clone(), f.clone());
                f
            }
        };
        let choice = match model {
            FacetModel::Tabulated => ModelChoice::Tabulated,
            FacetModel::Ggx => ModelChoice::Ggx,
            FacetModel::Beckmann => ModelChoice::Beckmann,
        };
        if fit.model(choice).is_none() {
            return Err(RenderError::input(
                &source,
                format!(
                    "material `{name}` asks for model {choice:?}, which this fit does not have"
                ),
            ));
        }
        Ok(Some(FacetMaterial {
            source,
            fit,
            model,
            glint,
        }))
    }

    /// The scene texture of `image` in the given encoding, decoding the image on first use.
    /// `None` (with a warning) when the image cannot be read.
    fn texture(
        &mut self,
        image: &gltf::Image,
        srgb: bool,
        material: &str,
        textures: &mut Vec<Texture>,
        warnings: &mut Vec<String>,
    ) -> Option<u32> {
        let label = image_label(image);
        if let Some(&t) = self.textures.get(&(image.index(), srgb)) {
            return Some(t);
        }
        let decoded = self
            .images
            .entry(image.index())
            .or_insert_with(|| decode_image(image, self.gltf_path, self.buffers));
        match decoded {
            Ok((width, height, texels)) => {
                let t = textures.len() as u32;
                textures.push(Texture {
                    name: label,
                    width: *width,
                    height: *height,
                    texels: texels.clone(),
                    srgb,
                });
                self.textures.insert((image.index(), srgb), t);
                Some(t)
            }
            Err(e) => {
                warnings.push(format!(
                    "texture {label} of material `{material}` not loaded ({e}); using the factor alone"
                ));
                None
            }
        }
    }
}

/// A material's name, or `material N` when it has none.
pub(crate) fn material_name(m: &gltf::Material) -> String {
    match (m.name(), m.index()) {
        (Some(n), _) => n.to_string(),
        (None, Some(i)) => format!("material {i}"),
        (None, None) => "default".into(),
    }
}

/// What a warning calls an image: its URI (file) or its name and index.
fn image_label(image: &gltf::Image) -> String {
    match (image.source(), image.name()) {
        (gltf::image::Source::Uri { uri, .. }, _) if !uri.starts_with("data:") => uri.to_string(),
        (_, Some(n)) => format!("`{n}` (image {})", image.index()),
        (_, None) => format!("image {}", image.index()),
    }
}

/// Reads and decodes one image to RGBA8 (file, data URI or buffer view).
fn decode_image(
    image: &gltf::Image,
    gltf_path: &Path,
    buffers: &[gltf::buffer::Data],
) -> Result<Decoded, String> {
    let bytes: Vec<u8> = match image.source() {
        gltf::image::Source::Uri { uri, .. } => match decode_data_uri(uri) {
            Some(decoded) => decoded?,
            None => {
                let file = gltf_path
                    .parent()
                    .unwrap_or(Path::new(""))
                    .join(percent_decode(uri));
                std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?
            }
        },
        gltf::image::Source::View { view, .. } => {
            let data = buffers
                .get(view.buffer().index())
                .ok_or("buffer view points to a missing buffer")?;
            data.get(view.offset()..view.offset() + view.length())
                .ok_or("buffer view lies outside its buffer")?
                .to_vec()
        }
    };
    let rgba = image::load_from_memory(&bytes)
        .map_err(|e| format!("cannot decode: {e}"))?
        .to_rgba8();
    let (w, h) = rgba.dimensions();
    if w == 0 || h == 0 {
        return Err("zero-sized image".into());
    }
    let texels = rgba.pixels().map(|p| p.0).collect();
    Ok((w, h, texels))
}

/// `%XX` escapes of a relative URI → bytes; anything malformed is kept as written.
fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|&c| hex(c)),
            b.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}
