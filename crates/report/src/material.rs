//! One material's part of the report: its spheres (the measurement and each model, under the
//! point light and the environment), the ΔE images of each model against the reference (the
//! measurement, or the tabulated model when there is none), the noise floor (the reference
//! rendered again at another seed, against itself), and the plots of its NDF and F.

use crate::delta_e::{DePair, DeltaE, delta_e_image};
use crate::error::{ReportError, Result};
use crate::scenes::{
    FLOOR_SEED, Lighting, N_MODELS, SEED, SphereRenderer, Variant, material, on_sphere,
};
use crate::subject::Subject;
use crate::{IMG, false_colour, plots};
use facet_fit::model::material::ModelChoice;
use facet_render::Image;
use facet_render::scene::Material;
use std::path::Path;

/// What the page says of one material.
pub struct MaterialReport {
    /// The fit's name.
    pub name: String,
    /// The input as given.
    pub input: String,
    /// The file stem of its images (unique in the report).
    pub stem: String,
    /// Whether the reference is the measurement (else the fit's own model, [`reference()`]).
    pub measured: bool,
    /// Whether the fit kept a coat (its coated model is then shown too).
    pub coated: bool,
    /// The fit's record (errors, times).
    pub record: facet_fit::model::material::FitRecord,
    /// The fit's wall time here (or as recorded in a fit JSON), ms.
    pub fit_ms: f64,
    /// The renders' wall time, ms.
    pub render_ms: f64,
    /// Mean ΔE2000 and ΔE_ITP per lighting ([`Lighting::ALL`] order) and model
    /// ([`Variant::MODELS`] order); `None` for the reference itself and for a model not shown.
    pub mean_de: [[Option<DePair<f64>>; N_MODELS]; 2],
    /// The noise floor per lighting: the mean ΔE2000 and ΔE_ITP of the reference rendered at
    /// [`FLOOR_SEED`] against its render at [`SEED`], the difference the renders' noise alone
    /// gives.
    pub floor: [DePair<f64>; 2],
    /// The ΔE images in the same order (kept for the database means).
    pub de: [[Option<DeltaE>; N_MODELS]; 2],
}

/// The page-relative path of one render.
pub fn render_file(stem: &str, lighting: Lighting, variant: Variant) -> String {
    format!("{IMG}/{stem}-{}-{}.png", lighting.key(), variant.key())
}

/// The page-relative path of the image of the noise floor under one lighting.
pub fn floor_file(stem: &str, lighting: Lighting) -> String {
    format!("{IMG}/{stem}-{}-de-noise.png", lighting.key())
}

/// The page-relative path of one ΔE image.
pub fn de_file(stem: &str, lighting: Lighting, model: Variant) -> String {
    format!("{IMG}/{stem}-{}-de-{}.png", lighting.key(), model.key())
}

/// The variants rendered for a subject: the measurement when there is one, every single-layer
/// model, and the coated model when the fit kept a coat.
pub fn variants(measured: bool, coated: bool) -> Vec<Variant> {
    let models = Variant::MODELS
        .into_iter()
        .filter(move |&m| m != Variant::Coated || coated);
    measured
        .then_some(Variant::Measured)
        .into_iter()
        .chain(models)
        .collect()
}

/// The variant ΔE is measured against: the measurement, else the model a fit JSON stands for
/// as a source (its coated tabulated model when it kept a coat, else its tabulated model).
pub fn reference(measured: bool, coated: bool) -> Variant {
    match (measured, coated) {
        (true, _) => Variant::Measured,
        (false, true) => Variant::Coated,
        (false, false) => Variant::Model(ModelChoice::Tabulated),
    }
}

/// Renders, compares and plots `subject` into `out`, its files named after `stem`.
pub fn report_material(
    renderer: &mut SphereRenderer,
    subject: &Subject,
    stem: &str,
    out: &Path,
) -> Result<MaterialReport> {
    let t = std::time::Instant::now();
    let source = &subject.fit.record.source;
    let measured = subject.measurement.is_some();
    let coated = subject.fit.coated.is_some();
    // Each material once, cloned per lighting.
    let materials = variants(measured, coated)
        .into_iter()
        .map(|v| {
            Ok((
                v,
                material(v, source, &subject.fit, subject.measurement.as_ref())?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    let reference_variant = reference(measured, coated);
    let mut mean_de = [[None; N_MODELS]; 2];
    let mut de: [[Option<DeltaE>; N_MODELS]; 2] = Default::default();
    let mut floor = [DePair::default(); 2];
    for (li, &lighting) in Lighting::ALL.iter().enumerate() {
        let images = render_variants(renderer, subject, &materials, lighting, stem, out)?;
        let reference = &images
            .iter()
            .find(|(v, _)| *v == reference_variant)
            .expect("the reference is rendered")
            .1;
        let again = materials
            .iter()
            .find(|(v, _)| *v == reference_variant)
            .expect("the reference has a material");
        floor[li] = noise_floor(renderer, subject, again, reference, lighting, stem, out)?;
        for (mi, &model) in Variant::MODELS.iter().enumerate() {
            if model == reference_variant {
                continue;
            }
            // A model not shown (the coated one of a fit without a coat) has no image.
            let Some((_, image)) = images.iter().find(|(v, _)| *v == model) else {
                continue;
            };
            let d = delta_e_image(reference, image, &mask(renderer.side()));
            false_colour::write_png(&d, &out.join(de_file(stem, lighting, model)))?;
            mean_de[li][mi] = Some(d.mean());
            de[li][mi] = Some(d);
        }
    }
    let render_ms = t.elapsed().as_secs_f64() * 1e3;
    plots::write_ndf_plot(&subject.fit, &out.join(plots::ndf_file(stem)))?;
    plots::write_fresnel_plot(&subject.fit, &out.join(plots::fresnel_file(stem)))?;
    Ok(MaterialReport {
        name: subject.fit.record.name.clone(),
        input: subject.input.clone(),
        stem: stem.to_owned(),
        measured,
        coated,
        record: subject.fit.record.clone(),
        fit_ms: subject.fit_ms,
        render_ms,
        mean_de,
        floor,
        de,
    })
}

/// The pixels compared in a `side`² image: those that see the sphere.
fn mask(side: u32) -> impl Fn(u32, u32) -> bool {
    move |x, y| on_sphere(side, x, y)
}

/// Every variant of `materials` rendered under `lighting` at [`SEED`], each written as a PNG.
fn render_variants(
    renderer: &mut SphereRenderer,
    subject: &Subject,
    materials: &[(Variant, Material)],
    lighting: Lighting,
    stem: &str,
    out: &Path,
) -> Result<Vec<(Variant, Image)>> {
    let mut images = Vec::new();
    for (variant, m) in materials {
        let image = renderer
            .render(m.clone(), lighting, SEED)
            .map_err(|source| ReportError::Rendering {
                what: format!("{}: rendering {}", subject.input, variant.key()),
                source: Box::new(source),
            })?;
        let path = out.join(render_file(stem, lighting, *variant));
        image.write_png(&path, 0.0).map_err(|e| ReportError::Png {
            path: path.clone(),
            source: Box::new(e),
        })?;
        images.push((*variant, image));
    }
    Ok(images)
}

/// The noise floor under `lighting`: the reference (`again`, whose render at [`SEED`] is
/// `reference`) rendered once more at [`FLOOR_SEED`] and compared with that render — the ΔE of
/// the renders' noise alone; its image written beside the models' ΔE images.
fn noise_floor(
    renderer: &mut SphereRenderer,
    subject: &Subject,
    again: &(Variant, Material),
    reference: &Image,
    lighting: Lighting,
    stem: &str,
    out: &Path,
) -> Result<DePair<f64>> {
    let image = renderer
        .render(again.1.clone(), lighting, FLOOR_SEED)
        .map_err(|source| ReportError::Rendering {
            what: format!("{}: rendering {} again", subject.input, again.0.key()),
            source: Box::new(source),
        })?;
    let d = delta_e_image(reference, &image, &mask(renderer.side()));
    false_colour::write_png(&d, &out.join(floor_file(stem, lighting)))?;
    Ok(d.mean())
}
