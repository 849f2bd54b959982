//! glTF materials → [`Material`]: metallic-roughness factors and textures, emissive strength,
//! KHR_materials_clearcoat ([`Clearcoat`]: factors, textures, the coat's normal map), and the
//! Facet extension carried in `extras`:
//!
//! ```json
//! "extras": {"facet": {"fit": "path/to/fit.json", "model": "tabulated|ggx|beckmann",
//!                      "glint": {"density": 1e6, "gamma_deg": 2.0, "threshold": 50.0}}}
//! "extras": {"facet": {"model": "measured", "source": "gold-paint.binary|nbrdf:NAME|x.bsdf",
//!                      "fit": "optional/fit.json"}}
//! ```
//!
//! Paths are relative to the glTF file's folder; `model` defaults to `tabulated`;
//! `glint.density` is required, `gamma_deg` defaults to 2 and `threshold` to 50. A `measured`
//! material renders its `source` ([`MeasuredMaterial`]); its `fit`, optional, is the NDF that
//! samples a MERL-grid table (without it the caller fits one after loading:
//! [`Scene::fit_measured`](super::Scene::fit_measured); loading never fits).
//! Images are decoded here, one at a time, so that a missing or broken image only costs its
//! texture (a warning naming the image, its file and the problem, and the material), never the
//! whole scene. An image file is read through [`facet_brdf::io::input`] ([`Cap::TEXTURE`]); its header
//! is read first and a size over [`MAX_TEXTURE_SIDE`] on a side, or one that would bring the
//! scene's textures past [`MAX_SCENE_TEXELS`], is refused before any pixel is decoded; the
//! decoder then runs under [`image::Limits`] (the same sides, [`MAX_DECODE_BYTES`]).

use super::gltf_buffers::Buffers;
use super::uri::{UriTarget, resolve};
use super::{Clearcoat, FacetMaterial, GlintParams, Material, MeasuredMaterial, Texture};
use crate::error::RenderError;
use facet_brdf::io::input::{self, Cap};
use facet_brdf::model::material::{FittedMaterial, ModelChoice};
use facet_brdf::sources::InputSpec;
use glam::{Vec3, Vec4};
use serde_json::Value;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// `extras.facet` of one material, validated; `fit` already resolved against the glTF folder.
#[derive(Clone, Debug, PartialEq)]
pub struct FacetExtras {
    /// The fit JSON.
    pub fit: Option<PathBuf>,
    /// Which model of the fit to render.
    pub model: ModelChoice,
    /// Glint parameters, for a glint material.
    pub glint: Option<GlintParams>,
    /// `model: "measured"`: the measurement named by `source`, as written (a path relative to
    /// the glTF's folder, or `nbrdf:NAME`).
    pub measured: Option<String>,
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
    let (model, is_measured) = match facet.get("model") {
        None => (ModelChoice::Tabulated, false),
        Some(Value::String(s)) if s == "measured" => (ModelChoice::Tabulated, true),
        Some(Value::String(s)) => (
            ModelChoice::parse(s).ok_or_else(|| {
                bad(format!(
                    "unknown extras.facet.model `{s}` (tabulated, ggx, beckmann or measured)"
                ))
            })?,
            false,
        ),
        Some(other) => return Err(bad(format!("extras.facet.model is not a string: {other}"))),
    };
    let measured = match (facet.get("source"), is_measured) {
        (Some(Value::String(s)), true) => Some(s.clone()),
        (None, true) => {
            return Err(bad(
                "extras.facet.model is \"measured\" but no `source` names the measurement".into(),
            ));
        }
        (Some(Value::String(_)), false) => {
            return Err(bad(
                "extras.facet.source names a measurement, which only model \"measured\" renders"
                    .into(),
            ));
        }
        (Some(other), _) => {
            return Err(bad(format!("extras.facet.source is not a string: {other}")));
        }
        (None, false) => None,
    };
    let glint = match facet.get("glint") {
        None => None,
        Some(_) if is_measured => {
            return Err(bad(
                "extras.facet.glint: glints render a model's NDF as flakes; a measured material \
                 has no model"
                    .into(),
            ));
        }
        Some(g) => Some(parse_glint(g).map_err(|m| bad(format!("extras.facet.glint: {m}")))?),
    };
    Ok(Some(FacetExtras {
        fit,
        model,
        glint,
        measured,
    }))
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

/// The widest and tallest texture read: 16384 texels.
pub const MAX_TEXTURE_SIDE: u32 = 16384;
/// The most texels all textures of a scene may hold together: 2²⁸ (1 GiB of RGBA8).
pub const MAX_SCENE_TEXELS: u64 = 1 << 28;
/// The most memory the image decoder may allocate for one image: 1 GiB.
pub const MAX_DECODE_BYTES: u64 = 1 << 30;

/// A decoded image: width, height, RGBA8 texels row by row.
type Decoded = Arc<(u32, u32, Vec<[u8; 4]>)>;

/// What an image is read from, for the cache: a file is decoded once however many images name
/// it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum ImageKey {
    File(PathBuf),
    Image(usize),
}

/// Builds every material of the document (same indices), its textures and Facet fits.
pub(crate) struct MaterialLoader<'a> {
    pub gltf_path: &'a Path,
    pub buffers: &'a Buffers,
    /// `--material NAME=FILE` overrides.
    pub overrides: &'a [(String, PathBuf)],
    /// The neural proxy file of `nbrdf:` measurements (`None`: `$FACET_NBRDF`, else embedded).
    pub nbrdf: Option<&'a Path>,
    /// Decoded images (or why not) by what they were read from.
    images: HashMap<ImageKey, Result<Decoded, String>>,
    /// Texels of the scene textures made so far (against [`MAX_SCENE_TEXELS`]).
    texels: u64,
    /// Scene texture index by (image index, sRGB).
    textures: HashMap<(usize, bool), u32>,
    fits: HashMap<PathBuf, Arc<FittedMaterial>>,
    /// Measured materials by source (resolved) and sampling fit.
    measurements: HashMap<(PathBuf, Option<*const FittedMaterial>), MeasuredMaterial>,
}

impl<'a> MaterialLoader<'a> {
    pub fn new(
        gltf_path: &'a Path,
        buffers: &'a Buffers,
        overrides: &'a [(String, PathBuf)],
    ) -> Self {
        MaterialLoader {
            gltf_path,
            buffers,
            overrides,
            nbrdf: None,
            images: HashMap::new(),
            texels: 0,
            textures: HashMap::new(),
            fits: HashMap::new(),
            measurements: HashMap::new(),
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
            .map(|m| self.material(doc, &m, textures, warnings))
            .collect()
    }

    fn material(
        &mut self,
        doc: &gltf::Document,
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
        let (facet, measured) = self.facet(m, &name)?;
        let clearcoat = self.clearcoat(doc, m, &name, textures, warnings)?;
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
            clearcoat,
            facet,
            measured,
            name,
        })
    }

    /// KHR_materials_clearcoat of `m`, if any with a factor above 0. A texture index past the
    /// file's textures, or a field of the wrong type, is an error naming the material; a
    /// texture that cannot be loaded is a warning (the factor alone is used).
    fn clearcoat(
        &mut self,
        doc: &gltf::Document,
        m: &gltf::Material,
        name: &str,
        textures: &mut Vec<Texture>,
        warnings: &mut Vec<String>,
    ) -> Result<Option<Clearcoat>, RenderError> {
        let Some(ext) = m.extension_value("KHR_materials_clearcoat") else {
            return Ok(None);
        };
        let gltf_path = self.gltf_path;
        let bad = |problem: String| {
            RenderError::input(
                gltf_path,
                format!("material `{name}` KHR_materials_clearcoat: {problem}"),
            )
        };
        let number = |key: &str, default: f64| match ext.get(key) {
            None => Ok(default),
            Some(v) => v
                .as_f64()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad(format!("{key} is {v}, not a finite number"))),
        };
        let factor = number("clearcoatFactor", 0.0)?.clamp(0.0, 1.0) as f32;
        let roughness = number("clearcoatRoughnessFactor", 0.0)?.clamp(0.0, 1.0) as f32;
        if factor == 0.0 {
            return Ok(None);
        }
        let mut texture = |key: &str| -> Result<Option<u32>, RenderError> {
            let Some(info) = ext.get(key) else {
                return Ok(None);
            };
            let index = info
                .get("index")
                .and_then(Value::as_u64)
                .ok_or_else(|| bad(format!("{key} has no texture index")))?;
            let t = doc.textures().nth(index as usize).ok_or_else(|| {
                let n = doc.textures().len();
                bad(format!("{key}.index {index}: the file has {n} textures"))
            })?;
            Ok(self.texture(&t.source(), false, name, textures, warnings))
        };
        let coat = Clearcoat {
            factor,
            texture: texture("clearcoatTexture")?,
            roughness,
            roughness_texture: texture("clearcoatRoughnessTexture")?,
            normal_texture: texture("clearcoatNormalTexture")?,
            normal_scale: ext
                .get("clearcoatNormalTexture")
                .and_then(|n| n.get("scale"))
                .and_then(Value::as_f64)
                .filter(|x| x.is_finite())
                .unwrap_or(1.0) as f32,
        };
        Ok(Some(coat))
    }

    /// The Facet material from extras and/or an override: a fitted model, or a measurement.
    /// An override naming a fit JSON replaces the extras' fit (a measured material's sampling
    /// fit included); one naming a measurement makes the material measured, with a fit made
    /// from that measurement.
    fn facet(
        &mut self,
        m: &gltf::Material,
        name: &str,
    ) -> Result<(Option<FacetMaterial>, Option<MeasuredMaterial>), RenderError> {
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
            .map_or((ModelChoice::Tabulated, None), |e| (e.model, e.glint));
        if let Some((_, file)) = overridden.filter(|(_, f)| !is_fit_file(f)) {
            if glint.is_some() {
                return Err(RenderError::input(
                    self.gltf_path,
                    format!(
                        "--material {name}={}: a measurement cannot replace a glint material's \
                         fit (glints render a model's NDF)",
                        file.display()
                    ),
                ));
            }
            let source = file.to_string_lossy().into_owned();
            return Ok((
                None,
                Some(self.measured(name, &source, Path::new(""), None)?),
            ));
        }
        let fit_file = overridden
            .map(|(_, f)| f.clone())
            .or_else(|| extras.as_ref().and_then(|e| e.fit.clone()));
        if let Some(source) = extras.as_ref().and_then(|e| e.measured.clone()) {
            // Relative to the glTF, as its buffers and images are.
            if InputSpec::parse(&source)
                .path()
                .is_some_and(|p| p.has_root() || p.is_absolute())
            {
                return Err(RenderError::input(
                    self.gltf_path,
                    format!(
                        "material `{name}`: the measurement `{}` is an absolute path; a \
                         scene's files are relative to the glTF",
                        source.escape_debug()
                    ),
                ));
            }
            let fit = fit_file.map(|f| self.fit(name, &f)).transpose()?;
            let base = self.gltf_path.parent().unwrap_or(Path::new("")).to_owned();
            return Ok((None, Some(self.measured(name, &source, &base, fit)?)));
        }
        let source = match fit_file {
            Some(fit) => fit,
            None if extras.is_some() => {
                return Err(RenderError::input(
                    self.gltf_path,
                    format!(
                        "material `{name}`: extras.facet has no `fit` and no --material override"
                    ),
                ));
            }
            None => return Ok((None, None)),
        };
        let fit = self.fit(name, &source)?;
        if fit.model(model).is_none() {
            return Err(RenderError::input(
                &source,
                format!("material `{name}` asks for model {model:?}, which this fit does not have"),
            ));
        }
        Ok((
            Some(FacetMaterial {
                source,
                fit,
                model,
                glint,
            }),
            None,
        ))
    }

    /// The fit JSON at `source`, loaded once however many materials name it.
    fn fit(&mut self, name: &str, source: &Path) -> Result<Arc<FittedMaterial>, RenderError> {
        if let Some(f) = self.fits.get(source) {
            return Ok(f.clone());
        }
        // The glTF, then the fit's own error, which names the fit file.
        let f = FittedMaterial::load(source)
            .map_err(|e| RenderError::input(self.gltf_path, format!("material `{name}`: {e}")))?;
        let f = Arc::new(f);
        self.fits.insert(source.to_owned(), f.clone());
        Ok(f)
    }

    /// The measurement `source` (relative to `base`) with its sampling fit, opened once per
    /// source and fit however many materials name them.
    fn measured(
        &mut self,
        name: &str,
        source: &str,
        base: &Path,
        fit: Option<Arc<FittedMaterial>>,
    ) -> Result<MeasuredMaterial, RenderError> {
        let key = (base.join(source), fit.as_ref().map(Arc::as_ptr));
        if let Some(m) = self.measurements.get(&key) {
            return Ok(m.clone());
        }
        let mut m = MeasuredMaterial::open(source, base, fit, self.nbrdf)
            .map_err(|e| RenderError::input(self.gltf_path, format!("material `{name}`: {e}")))?;
        // The same measurement with another fit: one table on the GPU for both.
        if let Some(same) = self.measurements.iter().find(|(k, _)| k.0 == key.0) {
            m.data = same.1.data.clone();
        }
        self.measurements.insert(key, m.clone());
        Ok(m)
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
        let (key, source) = match image_source(image, self.gltf_path) {
            Ok(found) => found,
            Err(e) => {
                warnings.push(format!(
                    "texture {label} of material `{material}` not loaded ({e}); using the factor alone"
                ));
                return None;
            }
        };
        let budget = MAX_SCENE_TEXELS - self.texels;
        let decoded = self
            .images
            .entry(key)
            .or_insert_with(|| decode_image(source, self.buffers, budget))
            .clone();
        let fits = |d: &Decoded| {
            let n = u64::from(d.0) * u64::from(d.1);
            if n <= budget {
                Ok(d.clone())
            } else {
                Err(format!(
                    "{}×{} texels would bring the scene's textures past {MAX_SCENE_TEXELS} texels",
                    d.0, d.1
                ))
            }
        };
        match decoded.and_then(|d| fits(&d)) {
            Ok(d) => {
                let (width, height, texels) = &*d;
                let t = textures.len() as u32;
                self.texels += u64::from(*width) * u64::from(*height);
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

/// Whether an override names a fit JSON (else a measurement).
fn is_fit_file(file: &Path) -> bool {
    matches!(
        facet_brdf::sources::InputSpec::parse(&file.to_string_lossy()),
        facet_brdf::sources::InputSpec::Fit(_)
    )
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

/// Where an image's bytes are.
enum ImageSource<'a> {
    Data(Vec<u8>),
    File(PathBuf),
    View(gltf::buffer::View<'a>),
}

/// The cache key and source of `image`; `Err` for a URI that is refused.
fn image_source<'a>(
    image: &gltf::Image<'a>,
    gltf_path: &Path,
) -> Result<(ImageKey, ImageSource<'a>), String> {
    let by_index = ImageKey::Image(image.index());
    match image.source() {
        gltf::image::Source::Uri { uri, .. } => match resolve(gltf_path, uri)? {
            UriTarget::Data(d) => Ok((by_index, ImageSource::Data(d))),
            UriTarget::File(f) => Ok((ImageKey::File(f.clone()), ImageSource::File(f))),
        },
        gltf::image::Source::View { view, .. } => Ok((by_index, ImageSource::View(view))),
    }
}

/// Reads and decodes one image to RGBA8 (file, data URI or buffer view); at most `budget`
/// texels. A file's errors name it.
fn decode_image(source: ImageSource, buffers: &Buffers, budget: u64) -> Result<Decoded, String> {
    let (bytes, file): (std::borrow::Cow<[u8]>, Option<PathBuf>) = match source {
        ImageSource::Data(d) => (d.into(), None),
        ImageSource::File(f) => {
            let bytes = input::read(&f, Cap::TEXTURE).map_err(|e| e.to_string())?;
            (bytes.into(), Some(f))
        }
        ImageSource::View(view) => {
            let data = buffers
                .get(view.buffer().index())
                .ok_or("buffer view points to a missing buffer")?;
            let end = view.offset().checked_add(view.length());
            let bytes = end
                .and_then(|end| data.get(view.offset()..end))
                .ok_or_else(|| {
                    format!(
                        "bufferView {} (byteOffset {} + byteLength {}) lies outside its buffer ({} bytes)",
                        view.index(),
                        view.offset(),
                        view.length(),
                        data.len()
                    )
                })?;
            (bytes.into(), None)
        }
    };
    decode_bytes(&bytes, budget).map_err(|e| match &file {
        Some(f) => format!("{}: {e}", f.display()),
        None => e,
    })
}

/// PNG or JPEG bytes → RGBA8: the header first (size checks), then the pixels under
/// [`image::Limits`].
fn decode_bytes(bytes: &[u8], budget: u64) -> Result<Decoded, String> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot read: {e}"))
    };
    let (w, h) = reader()?
        .into_dimensions()
        .map_err(|e| format!("cannot decode: {e}"))?;
    if w == 0 || h == 0 {
        return Err("zero-sized image".into());
    }
    if w > MAX_TEXTURE_SIDE || h > MAX_TEXTURE_SIDE {
        return Err(format!(
            "{w}×{h} texels is larger than the {MAX_TEXTURE_SIDE}×{MAX_TEXTURE_SIDE} a texture may be"
        ));
    }
    if u64::from(w) * u64::from(h) > budget {
        return Err(format!(
            "{w}×{h} texels would bring the scene's textures past {MAX_SCENE_TEXELS} texels"
        ));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIDE);
    limits.max_image_height = Some(MAX_TEXTURE_SIDE);
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    let mut r = reader()?;
    r.limits(limits);
    let rgba = r
        .decode()
        .map_err(|e| format!("cannot decode: {e}"))?
        .to_rgba8();
    let (w, h) = rgba.dimensions();
    if w == 0 || h == 0 {
        return Err("zero-sized image".into());
    }
    let texels = rgba.pixels().map(|p| p.0).collect();
    Ok(Arc::new((w, h, texels)))
}
