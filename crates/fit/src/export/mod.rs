//! A fit's analytic model written for another renderer: a Mitsuba 3 `<bsdf>`, a pbrt-v4
//! `MakeNamedMaterial`, or a glTF 2.0 material, with what it approximates.
//!
//! Each export takes one analytic fit (GGX by default; Beckmann on request, where the target
//! has it), its α (αx, αy along the fit's rotated axes), its Lambertian albedo ρd and one of
//! the physical Fresnel curves fitted to its table ([`crate::fitting::fresnel_fit`]), and states in the
//! file what it approximates: the Fresnel curve used with its recorded error in Facet's metric
//! ([`FitQuality::error`], the model with that curve in place of its table), the error of the
//! model with its table for comparison, and what the target cannot represent ([`Report`]).
//!
//! The material is exported as a **conductor** or a **plastic** (a diffuse base under a
//! dielectric interface). [`KindRequest::Auto`] takes a conductor when
//!
//! - the Schlick F0 of the fit, averaged over the channels, is at least [`CONDUCTOR_MIN_F0`]
//!   (every common dielectric lies below 0.2, η ≈ 2.6, every metal above 0.5), or
//! - ρd is at most [`CONDUCTOR_MAX_ALBEDO`] in every channel (a plastic would keep nothing but
//!   its Fresnel) and the conductor curve's error is below [`CONDUCTOR_MARGIN`] × the
//!   dielectric's (recorded errors, else the RMS distances to the table): a coloured F that one
//!   η cannot make, as a metallic paint's.
//!
//! The error comparison alone decides nothing: the conductor curve (η and k per channel)
//! contains the dielectric one (k = 0), so its error is never much above the dielectric's, and
//! a colourless table fits both alike.
//!
//! A fit that kept a clear coat ([`crate::model::coat`]) is exported coated unless
//! [`ExportOptions::coat`] is false (then the single layer, and the statement says so): for
//! pbrt-v4 as `coatedconductor` / `coateddiffuse` and for glTF as `KHR_materials_clearcoat`,
//! the base's analytic fit under the coat with the coated model's recorded error; for Mitsuba 3,
//! which has no coated conductor, the coated model itself (the coat over the base's analytic
//! fit with its F table) tabulated into an RGL `.bsdf` ([`TableFile`]) for its `measured`
//! plugin, with the table's error against that model beside the model's recorded one.
//!
//! Each target's writer is in its own module: [`mitsuba`], `pbrt` and [`gltf`]; [`rgl`] writes
//! a fit's model as an RGL `.bsdf` file.

pub mod gltf;
pub mod mitsuba;
mod pbrt;
pub mod rgl;

use crate::error::FitError;
use crate::fitting::fresnel_fit::FitFresnelCurves;
use crate::model::fresnel_curves::{FitQuality, FresnelChoice, FresnelFits};
use crate::model::material::{FitRecord, FittedMaterial, ModelChoice, ParamRecord};
use crate::model::microfacet::NdfKind;
use crate::model::rgb::Rgb;
use serde::Serialize;
use std::path::Path;

/// The mean Schlick F0 from which [`KindRequest::Auto`] exports a conductor.
pub const CONDUCTOR_MIN_F0: f64 = 0.2;

/// The largest ρd (every channel) with which [`KindRequest::Auto`] weighs the Fresnel errors.
pub const CONDUCTOR_MAX_ALBEDO: f64 = 0.01;

/// How much lower than the dielectric's the conductor curve's error must be for
/// [`KindRequest::Auto`] to take a conductor below [`CONDUCTOR_MIN_F0`].
pub const CONDUCTOR_MARGIN: f64 = 0.9;

/// The renderer an export is written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// Mitsuba 3: a `<bsdf>` element (`roughconductor` or `roughplastic`; `measured` with a
    /// [`TableFile`] for a coat) as the root of an XML file, loadable by `mi.load_file` or an
    /// `<include>`.
    Mitsuba,
    /// pbrt-v4: a `MakeNamedMaterial` statement (`conductor` or `coateddiffuse`).
    Pbrt,
    /// glTF 2.0: a `.gltf` holding one metallic-roughness material.
    Gltf,
}

impl Target {
    /// The file extension of the target's files: `xml`, `pbrt` or `gltf`.
    pub fn extension(self) -> &'static str {
        match self {
            Target::Mitsuba => "xml",
            Target::Pbrt => "pbrt",
            Target::Gltf => "gltf",
        }
    }

    /// `mitsuba`, `pbrt` or `gltf`.
    pub fn name(self) -> &'static str {
        match self {
            Target::Mitsuba => "mitsuba",
            Target::Pbrt => "pbrt",
            Target::Gltf => "gltf",
        }
    }

    /// Whether the target has a Beckmann distribution (Mitsuba only).
    pub fn has_beckmann(self) -> bool {
        self == Target::Mitsuba
    }
}

/// Which analytic fit to export.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ModelRequest {
    /// The GGX fit (the default: every target has GGX).
    #[default]
    Ggx,
    /// The Beckmann fit; a target without Beckmann (pbrt, glTF) takes the GGX fit instead and
    /// says so.
    Beckmann,
    /// Whichever fit the target can represent has the lower error (GGX for pbrt and glTF).
    Best,
}

/// How to export the material.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KindRequest {
    /// A conductor when the mean Schlick F0 is at least [`CONDUCTOR_MIN_F0`], or when ρd is
    /// at most [`CONDUCTOR_MAX_ALBEDO`] and the conductor curve fits clearly better than the
    /// dielectric ([`CONDUCTOR_MARGIN`]); else a plastic.
    #[default]
    Auto,
    /// A conductor (η, k per channel; ρd dropped).
    Conductor,
    /// A diffuse base ρd under a dielectric interface of one η.
    Plastic,
}

/// What an export represents the material as.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A conductor.
    Conductor,
    /// A diffuse base under a dielectric interface.
    Plastic,
}

/// What to export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExportOptions {
    /// The renderer.
    pub target: Target,
    /// The analytic fit.
    pub model: ModelRequest,
    /// Conductor, plastic, or chosen by F0.
    pub kind: KindRequest,
    /// Export the fit's clear coat where it has one and the target can write one; false:
    /// the single layer.
    pub coat: bool,
}

/// The clear coat of an export: the fit's, over the base written.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CoatExport {
    /// The coat's index of refraction.
    pub eta: f64,
    /// Its GGX α.
    pub alpha: f64,
    /// The weight of its reflection.
    pub weight: f64,
}

/// What an export approximates, written into it (a comment, or the glTF material's `extras`)
/// and summed up by [`Report::summary`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// `mitsuba`, `pbrt` or `gltf`.
    pub target: &'static str,
    /// The fit file.
    pub source_fit: String,
    /// The fitted material's name.
    pub material: String,
    /// The fit the values come from: `ggx` or `beckmann`.
    pub fit_model: &'static str,
    /// The distribution written: `ggx` or `beckmann`.
    pub distribution: &'static str,
    /// Conductor or plastic.
    pub kind: Kind,
    /// α along the fit's rotated x axis.
    pub alpha_x: f64,
    /// α along the fit's rotated y axis.
    pub alpha_y: f64,
    /// The rotation of the α axes, degrees counter-clockwise from the tangent.
    pub rotation_deg: f64,
    /// ρd of the fit.
    pub diffuse: Rgb,
    /// The Fresnel curve the export stands for: `conductor`, `dielectric` or `schlick`.
    pub fresnel: &'static str,
    /// Facet's error metric of the model with that curve in place of its table, as the fit
    /// recorded it; `None` when the fit recorded no Fresnel fits (the curve was fitted here).
    pub fresnel_error: Option<f64>,
    /// RMS distance of that curve to the model's F table over θd ≤ 80°.
    pub fresnel_rms: f64,
    /// Facet's error metric of the model with its own F table, for comparison.
    pub table_error: f64,
    /// Whether the fit recorded its Fresnel fits (else they were fitted here to its table).
    pub fresnel_fits_recorded: bool,
    /// What the target cannot represent, and what stands in for it.
    pub notes: Vec<String>,
    /// The clear coat written over the material, if any (the model and its values are then
    /// the base's, and `table_error` the coated model's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coat: Option<CoatExport>,
    /// The coated model tabulated into a `.bsdf` (Mitsuba 3), if it was.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tabulated: Option<TableExport>,
}

/// The coated model as the `.bsdf` file of an export ([`TableFile`]) holds it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TableExport {
    /// The file's name, beside the exported file.
    pub file: String,
    /// The file's error against the coated model in Facet's metric, on the MERL grid.
    pub error: f64,
    /// The NDF its sample space was built on ([`rgl::sampling_ndfs`]).
    pub sample_space: &'static str,
}

impl Report {
    /// One line: the target, the material, the model and α, the Fresnel and its error.
    pub fn summary(&self) -> String {
        let error = match (self.fresnel_error, self.coat, &self.tabulated) {
            (_, _, Some(t)) => format!(
                "the F table: error {:.3e}; tabulated in {}, {:.3e} against the coated model",
                self.table_error, t.file, t.error
            ),
            (Some(e), _, _) => format!(
                "{} Fresnel error {e:.3e} (with the F table {:.3e})",
                self.fresnel, self.table_error
            ),
            (None, Some(_), _) => format!(
                "{} Fresnel error unknown (under the coat; with the F table {:.3e})",
                self.fresnel, self.table_error
            ),
            (None, None, _) => format!(
                "{} Fresnel error unknown (fitted at export; with the F table {:.3e})",
                self.fresnel, self.table_error
            ),
        };
        let coat = self.coat.map_or(String::new(), |c| {
            format!(
                " under a clear coat (η {}, α {:.4}, weight {:.3})",
                c.eta, c.alpha, c.weight
            )
        });
        let alpha = if self.alpha_x == self.alpha_y {
            format!("α {:.4}", self.alpha_x)
        } else {
            format!(
                "α {:.4}/{:.4} at {:.1}°",
                self.alpha_x, self.alpha_y, self.rotation_deg
            )
        };
        format!(
            "{}: {} as {} ({} fit, {alpha}){coat}, {error}; {} approximation(s) noted in the file",
            self.target,
            self.material,
            self.written_as(),
            self.fit_model,
            self.notes.len()
        )
    }

    /// What the model is written as: `a ggx conductor`, or the base of a tabulated coat.
    fn written_as(&self) -> String {
        match self.tabulated {
            Some(_) => format!("a {} base", self.distribution),
            None => format!(
                "a {} {}",
                self.distribution,
                match self.kind {
                    Kind::Conductor => "conductor",
                    Kind::Plastic => "plastic",
                }
            ),
        }
    }

    /// The statement as lines of text (for the XML and pbrt comments).
    fn lines(&self) -> Vec<String> {
        let mut v = vec![
            format!(
                "Exported by facet from the fit {} (material {}).",
                self.source_fit, self.material
            ),
            format!(
                "Model: the {} fit, written as {}; alpha_x {}, alpha_y {}, rotation {} deg; rho_d {:?}.",
                self.fit_model,
                self.written_as(),
                self.alpha_x,
                self.alpha_y,
                self.rotation_deg,
                self.diffuse
            ),
            match (self.fresnel_error, self.coat, &self.tabulated) {
                (_, Some(c), Some(t)) => format!(
                    "Coat: a clear dielectric of eta {}, GGX alpha {}, weight {} over the model above, whose values are the base's fitted under it (seen through the coat), with its own F table; this coated model is tabulated in {} (sample space on the {} NDF). Facet's error metric of the coated model: {:e}; of the table against the coated model: {:e}.",
                    c.eta, c.alpha, c.weight, t.file, t.sample_space, self.table_error, t.error
                ),
                (Some(e), _, _) => format!(
                    "Fresnel: the {} fit; Facet's error metric of the model with it: {e:e} (with the fit's F table: {:e}; RMS to the table {:.2e}).",
                    self.fresnel, self.table_error, self.fresnel_rms
                ),
                (None, Some(c), _) => format!(
                    "Coat: a clear dielectric of eta {}, GGX alpha {}, weight {} over the model above, whose values are the base's fitted under it (seen through the coat). Fresnel: the base's {} fit (RMS {:.2e} to its table); Facet's error metric of the coated model with the tables: {:e}, with the curve: unknown.",
                    c.eta, c.alpha, c.weight, self.fresnel, self.fresnel_rms, self.table_error
                ),
                (None, None, _) => format!(
                    "Fresnel: the {} curve fitted at export to the model's F table (RMS {:.2e}); its error in Facet's metric is unknown (the fit recorded none; with the F table: {:e}).",
                    self.fresnel, self.fresnel_rms, self.table_error
                ),
            },
        ];
        v.extend(self.notes.iter().map(|n| format!("Approximation: {n}")));
        v
    }
}

/// A written export: the file's text and what it approximates.
#[derive(Clone, Debug, PartialEq)]
pub struct Exported {
    /// The whole file.
    pub text: String,
    /// What it approximates (also written inside `text`).
    pub report: Report,
    /// A second file the first names, to be written beside it.
    pub table: Option<TableFile>,
}

/// The `.bsdf` file a Mitsuba 3 export of a coat names: the coated model tabulated for the
/// `measured` plugin ([`rgl::rgl_bytes`] at [`rgl::BsdfResolution::standard`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TableFile {
    /// Its file name (`NAME.coated.bsdf`), which the exported file refers to; it goes in the
    /// same folder.
    pub name: String,
    /// Its contents.
    pub bytes: Vec<u8>,
}

/// One of the Fresnel curves with its quality.
struct Curve {
    name: &'static str,
    quality: FitQuality,
}

impl Curve {
    /// The curve the target's BSDF evaluates for `kind`.
    fn of(target: Target, kind: Kind, fits: &FresnelFits) -> Self {
        // The curve each target's BSDF evaluates: glTF's is always Schlick (a conductor's F0 is
        // its base colour; a dielectric's F0 comes from `ior` and `KHR_materials_specular`).
        let choice = match (target, kind) {
            (Target::Gltf, _) => FresnelChoice::Schlick,
            (_, Kind::Conductor) => FresnelChoice::Conductor,
            (_, Kind::Plastic) => FresnelChoice::Dielectric,
        };
        let quality = match choice {
            FresnelChoice::Conductor => fits.conductor,
            FresnelChoice::Dielectric => fits.dielectric,
            _ => fits.schlick,
        };
        Curve {
            name: match choice {
                FresnelChoice::Conductor => "conductor",
                FresnelChoice::Dielectric => "dielectric",
                _ => "schlick",
            },
            quality,
        }
    }
}

/// Writes the analytic model of `fit` for `options.target`; `path` names the fit in the
/// statement and in errors (a fit without the asked model is an error naming it).
pub fn export(
    fit: &FittedMaterial,
    path: &Path,
    options: &ExportOptions,
) -> Result<Exported, FitError> {
    let bad = |problem: String| FitError::Material {
        path: path.to_owned(),
        problem,
    };
    let r = &fit.record;
    let target = options.target;
    let mut notes = Vec::new();
    // A coat written: the base's fit under it is the model exported.
    let coat = r.coat.as_ref().filter(|_| options.coat);
    // Mitsuba 3 gets the coated model as a table: no curve stands in for the F table.
    let tabulate = target == Target::Mitsuba && coat.is_some();
    let rec = coat.map_or(r, |c| &*c.base);
    let (fit_kind, p) = choose(rec, options, &mut notes).map_err(bad)?;
    let mut curve_notes = Vec::new();
    let (fits, recorded) = fresnel_fits(rec, p, &mut curve_notes);
    let kind = choose_kind(options.kind, p, &fits, recorded);
    let curve = Curve::of(target, kind, &fits);
    if !tabulate {
        notes.append(&mut curve_notes);
        note_approximations(&mut notes, target, kind, p, &fits, recorded);
    }
    note_coat(&mut notes, r, coat.is_some(), target);
    let coated_error = |c: &crate::model::material::CoatRecord| match fit_kind {
        NdfKind::Ggx => c.ggx_error,
        NdfKind::Beckmann => c.beckmann_error,
    };
    let mut report = Report {
        target: target.name(),
        source_fit: path.display().to_string(),
        material: r.name.clone(),
        fit_model: fit_kind.name(),
        distribution: if target.has_beckmann() {
            fit_kind.name()
        } else {
            "ggx"
        },
        kind,
        alpha_x: p.alpha_x,
        alpha_y: p.alpha_y,
        rotation_deg: p.rotation.to_degrees(),
        diffuse: p.diffuse,
        fresnel: if tabulate { "table" } else { curve.name },
        // A base's curve was measured against the data under the coat, not the source.
        fresnel_error: known_error(recorded, curve.quality).filter(|_| coat.is_none()),
        fresnel_rms: if tabulate { 0.0 } else { curve.quality.rms },
        table_error: coat.map_or(p.error, |c| coated_error(c).unwrap_or(c.error)),
        fresnel_fits_recorded: recorded,
        notes,
        coat: coat.map(|c| CoatExport {
            eta: c.coat.eta,
            alpha: c.coat.alpha,
            weight: c.coat.weight,
        }),
        tabulated: None,
    };
    let id = crate::io::input::safe_file_stem(&r.name);
    let (text, table) = match target {
        Target::Mitsuba if tabulate => {
            let table = tabulate_coat(fit, fit_kind, &id, &mut report).map_err(bad)?;
            (
                mitsuba::write_measured(&id, &table.name, &report),
                Some(table),
            )
        }
        Target::Mitsuba => (mitsuba::write(&id, p, &fits, &mut report), None),
        Target::Pbrt => (pbrt::write(&id, p, &fits, &mut report), None),
        Target::Gltf => (gltf::write(&r.name, p, &fits, &mut report), None),
    };
    Ok(Exported {
        text,
        report,
        table,
    })
}

/// The coated model of `fit` with the base's `kind` fit, tabulated into `ID.coated.bsdf`
/// (recorded in `report.tabulated`).
fn tabulate_coat(
    fit: &FittedMaterial,
    kind: NdfKind,
    id: &str,
    report: &mut Report,
) -> Result<TableFile, String> {
    let choice = match kind {
        NdfKind::Ggx => ModelChoice::Ggx,
        NdfKind::Beckmann => ModelChoice::Beckmann,
    };
    let model = fit
        .coated
        .as_ref()
        .and_then(|c| c.model(choice))
        .ok_or_else(|| format!("the coat's base has no {} fit", kind.name()))?;
    let name = format!("{id}.coated.bsdf");
    let description = format!(
        "{} under its clear coat, tabulated by facet {} from the fit {}",
        report.material,
        env!("CARGO_PKG_VERSION"),
        report.source_fit
    );
    let res = rgl::BsdfResolution::standard();
    let (bytes, written) = rgl::rgl_bytes(&model, res, &description)
        .map_err(|e| format!("tabulating the coated model: {e}"))?;
    report.notes.push(format!(
        "Mitsuba 3 has no coated conductor: the coated model is tabulated for its measured plugin ({} θi slices of {}² samples; anything finer than that grid, as a coat's sharp peak, is smoothed: the table's error against the model is {:.3e})",
        res.theta_i, res.sample, written.error
    ));
    report.tabulated = Some(TableExport {
        file: name.clone(),
        error: written.error,
        sample_space: written.sample_space,
    });
    Ok(TableFile { name, bytes })
}

/// The Fresnel fits recorded with `p`, or (said in `notes`) fitted here to its F table, and
/// whether they were recorded.
fn fresnel_fits(r: &FitRecord, p: &ParamRecord, notes: &mut Vec<String>) -> (FresnelFits, bool) {
    let (fits, recorded) = match &p.fresnel_fits {
        Some(f) => (f.clone(), true),
        None => (FresnelFits::of(&p.fresnel, |_| [f64::NAN; 3]), false),
    };
    if !recorded {
        notes.push(if r.diffuse_lobe {
            "the fit recorded no Fresnel fits: they were fitted here to the model's F table, with no error in Facet's metric".into()
        } else {
            "a single-lobe fit (facet fit's no-diffuse or aniso options): no Fresnel fits were recorded, they were fitted here to the model's F table, which also holds the light of any diffuse term (ρd = 0); their error in Facet's metric is unknown".into()
        });
    }
    (fits, recorded)
}

/// A curve's error in Facet's metric where the fit recorded it (and it is finite).
fn known_error(recorded: bool, q: FitQuality) -> Option<f64> {
    recorded.then_some(q.error).filter(|e| e.is_finite())
}

/// The Schlick fit's F0, averaged over the channels.
fn mean_f0(fits: &FresnelFits) -> f64 {
    fits.schlick_f0.iter().sum::<f64>() / 3.0
}

/// Whether the conductor curve fits clearly better than the dielectric one
/// ([`CONDUCTOR_MARGIN`]): by their recorded errors where both are known, else by their RMS
/// distances to the table.
fn conductor_fits_better(fits: &FresnelFits, recorded: bool) -> bool {
    let (c, d) = (fits.conductor, fits.dielectric);
    match (known_error(recorded, c), known_error(recorded, d)) {
        (Some(c), Some(d)) => c < CONDUCTOR_MARGIN * d,
        _ => c.rms < CONDUCTOR_MARGIN * d.rms,
    }
}

/// The kind asked for, or [`KindRequest::Auto`]'s choice (the module's doc gives the rule).
fn choose_kind(request: KindRequest, p: &ParamRecord, fits: &FresnelFits, recorded: bool) -> Kind {
    let no_diffuse = p.diffuse.iter().all(|&a| a <= CONDUCTOR_MAX_ALBEDO);
    match request {
        KindRequest::Conductor => Kind::Conductor,
        KindRequest::Plastic => Kind::Plastic,
        KindRequest::Auto if mean_f0(fits) >= CONDUCTOR_MIN_F0 => Kind::Conductor,
        KindRequest::Auto if no_diffuse && conductor_fits_better(fits, recorded) => Kind::Conductor,
        KindRequest::Auto => Kind::Plastic,
    }
}

/// What every writer of `target` leaves out, added to `notes`: ρd under a conductor, the
/// conductor's coloured Fresnel under a plastic, a dielectric η whose F0 is not the table's,
/// rotated α axes, and the target's Smith G.
fn note_approximations(
    notes: &mut Vec<String>,
    target: Target,
    kind: Kind,
    p: &ParamRecord,
    fits: &FresnelFits,
    recorded: bool,
) {
    let (ax, ay, rot) = (p.alpha_x, p.alpha_y, p.rotation);
    let max_kd = p.diffuse.iter().cloned().fold(0.0, f64::max);
    if kind == Kind::Conductor && max_kd > 0.0 {
        notes.push(format!(
            "ρd = {:?} is dropped: the conductor has no diffuse lobe",
            p.diffuse
        ));
    }
    let c = fits.conductor;
    if kind == Kind::Plastic && conductor_fits_better(fits, recorded) {
        notes.push(format!(
            "a dielectric's Fresnel is one colourless curve: the conductor fit (η {:?}, k {:?}) is closer (error {}, RMS {:.2e}); exported with the conductor kind it is kept, without ρd",
            fits.conductor_eta,
            fits.conductor_k,
            fmt_error(known_error(recorded, c)),
            c.rms
        ));
    }
    if kind == Kind::Plastic && target != Target::Gltf {
        let (f0_eta, f0) = (dielectric_f0(fits.dielectric_eta), mean_f0(fits));
        if (f0_eta / f0 - 1.0).abs() > 0.05 {
            notes.push(format!(
                "the dielectric fit's η {} has F0 {f0_eta:.4}, the table's (Schlick fit's) F0 is {f0:.4}: one exact dielectric curve cannot follow this table at both normal and grazing incidence; η {:.4} would match F0 (its error in Facet's metric is not recorded)",
                fits.dielectric_eta,
                schlick_ior(f0)
            ));
        }
    }
    if ax != ay && rot != 0.0 && target != Target::Gltf {
        notes.push(format!(
            "the α axes are rotated by {:.3}° from the tangent: {} cannot rotate the distribution (alpha_u lies along dp/du); rotate the surface's tangent frame by that angle",
            rot.to_degrees(),
            target.name()
        ));
    }
    let g_note = match target {
        Target::Mitsuba => {
            "Mitsuba's Smith G is separable (G1(ωi) G1(ωo)); Facet's is height-direction correlated"
        }
        Target::Pbrt => {
            "pbrt-v4's Smith G is height correlated (1/(1 + Λi + Λo)); Facet's is height-direction correlated"
        }
        Target::Gltf => {
            "glTF's visibility term is height-correlated Smith G (GGX); Facet's is height-direction correlated"
        }
    };
    notes.push(g_note.into());
}

/// What becomes of the fit's coat (`written`, or the single layer exported), added to `notes`.
fn note_coat(notes: &mut Vec<String>, r: &FitRecord, written: bool, target: Target) {
    let Some(c) = &r.coat else { return };
    let (eta, alpha, w) = (c.coat.eta, c.coat.alpha, c.coat.weight);
    if !written {
        notes.push(format!(
            "the fit's clear coat (η {eta}, α {alpha:.4}, weight {w:.3}; coated tabulated error {:.3e} against the single layer's {}) is not exported (not asked for): this is the single layer",
            c.error,
            fmt_error(r.tabulated.error)
        ));
        return;
    }
    notes.push(format!(
        "the base's values are those fitted under the coat (the data seen through it); the single layer's tabulated error is {}, the coated one's {:.3e}",
        fmt_error(r.tabulated.error),
        c.error
    ));
    match target {
        Target::Pbrt => {
            notes.push("pbrt-v4's coated BSDFs are evaluated stochastically (a random walk between the interface and the base, thickness 0.01, no medium): light scatters between the layers, where Facet's coat takes one crossing each way".into());
            if w < 0.99 {
                notes.push(format!("pbrt-v4's interface reflects its whole Fresnel: the coat's weight {w:.3} is written as 1"));
            }
        }
        Target::Gltf => {
            notes.push(format!(
                "KHR_materials_clearcoat does not refract: the base is lit and seen along the outside directions and weighted by 1 − c F_schlick(0.04) (Facet: refracted, T(θi) T(θo) / η²), with ior 1.5 (the fit's η {eta})"
            ));
        }
        Target::Mitsuba => {}
    }
}

fn fmt_error(e: Option<f64>) -> String {
    e.map_or("unknown".into(), |e| format!("{e:.3e}"))
}

/// The fit to export (its kind and record), with a note when the target stands GGX in for
/// Beckmann; `Err` says what is missing.
fn choose<'a>(
    r: &'a FitRecord,
    options: &ExportOptions,
    notes: &mut Vec<String>,
) -> Result<(NdfKind, &'a ParamRecord), String> {
    let target = options.target;
    let missing = |name: &str| {
        format!(
            "the fit has no {name} model (it was fitted with another --model); refit it with --model {} or all",
            name.to_lowercase()
        )
    };
    match options.model {
        ModelRequest::Ggx => r
            .ggx
            .as_ref()
            .map(|p| (NdfKind::Ggx, p))
            .ok_or_else(|| missing("GGX")),
        ModelRequest::Beckmann if target.has_beckmann() => r
            .beckmann
            .as_ref()
            .map(|p| (NdfKind::Beckmann, p))
            .ok_or_else(|| missing("Beckmann")),
        ModelRequest::Beckmann => {
            let g = r.ggx.as_ref().ok_or_else(|| {
                format!(
                    "{} has only the GGX (Trowbridge–Reitz) distribution, and the fit has no GGX model to stand in for the Beckmann one",
                    target.name()
                )
            })?;
            notes.push(match &r.beckmann {
                Some(b) => format!(
                    "{} has no Beckmann distribution: the GGX fit (α {:.4}/{:.4}, error {:.3e}) stands in for the Beckmann fit (α {:.4}/{:.4}, error {:.3e})",
                    target.name(),
                    g.alpha_x,
                    g.alpha_y,
                    g.error,
                    b.alpha_x,
                    b.alpha_y,
                    b.error
                ),
                None => format!(
                    "{} has no Beckmann distribution (nor has the fit a Beckmann model): the GGX fit is exported",
                    target.name()
                ),
            });
            Ok((NdfKind::Ggx, g))
        }
        ModelRequest::Best => {
            let mut best: Option<(NdfKind, &ParamRecord)> =
                r.ggx.as_ref().map(|p| (NdfKind::Ggx, p));
            if let Some(b) = &r.beckmann {
                if target.has_beckmann() {
                    if best.is_none_or(|(_, g)| b.error < g.error) {
                        best = Some((NdfKind::Beckmann, b));
                    }
                } else if best.is_some_and(|(_, g)| b.error < g.error) {
                    notes.push(format!(
                        "the Beckmann fit has the lower error ({:.3e}), but {} has only GGX: the GGX fit is exported",
                        b.error,
                        target.name()
                    ));
                }
            }
            best.ok_or_else(|| {
                if target.has_beckmann() {
                    "the fit has no analytic (GGX or Beckmann) model; refit it with --model all"
                        .into()
                } else {
                    missing("GGX")
                }
            })
        }
    }
}

/// F0 = ((η − 1)/(η + 1))² of a dielectric of relative index η.
pub fn dielectric_f0(eta: f64) -> f64 {
    ((eta - 1.0) / (eta + 1.0)).powi(2)
}

/// The η of a dielectric of normal-incidence reflectance F0: (1 + √F0)/(1 − √F0) (F0 below 1).
pub fn schlick_ior(f0: f64) -> f64 {
    let r = f0.clamp(0.0, 0.999_999).sqrt();
    (1.0 + r) / (1.0 - r)
}

/// A number list: `a, b, c` (Mitsuba) or `a b c` (pbrt), in the shortest form that reads back
/// to the same f64.
fn list(v: &[f64], sep: &str) -> String {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(sep)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::gltf::gltf_alphas;
    use crate::model::fresnel::{Fresnel, FresnelTable};
    use crate::model::material::{Params, TabulatedRecord};

    fn table_of(f: &Fresnel) -> FresnelTable {
        FresnelTable::on_merl_bins(
            (0..90)
                .map(|j| f.eval((j as f64).to_radians().cos()))
                .collect(),
        )
    }

    /// A parameter record of α, a Fresnel curve and ρd, with fits recorded (errors made up,
    /// distinct so that a test can tell them apart) or not.
    pub(super) fn param(
        ax: f64,
        ay: f64,
        rot: f64,
        f: &Fresnel,
        kd: Rgb,
        recorded: bool,
    ) -> ParamRecord {
        let table = table_of(f);
        let fits = recorded.then(|| {
            let mut fits = FresnelFits::of(&table, |_| [0.0; 3]);
            fits.conductor.error = 0.011;
            fits.dielectric.error = 0.022;
            fits.schlick.error = 0.033;
            fits
        });
        ParamRecord {
            alpha_x: ax,
            alpha_y: ay,
            rotation: rot,
            error: 0.005,
            method: "least_squares".into(),
            moments: Params {
                alpha_x: ax,
                alpha_y: ay,
                rotation: rot,
                error: 0.1,
            },
            fresnel: table,
            diffuse: kd,
            fresnel_fits: fits,
        }
    }

    fn record(ggx: Option<ParamRecord>, beckmann: Option<ParamRecord>) -> FitRecord {
        let p = ggx.as_ref().or(beckmann.as_ref()).unwrap().clone();
        let tables = crate::fitting::refine::tabulate(
            crate::model::microfacet::AnalyticNdf::isotropic(NdfKind::Ggx, 0.3),
            32,
            32,
        )
        .unwrap()
        .tables()
        .clone();
        FitRecord {
            name: "test material".into(),
            source: "analytic:test".into(),
            backend: "cpu".into(),
            fallback: None,
            resolution: 16,
            phi_resolution: 1,
            anisotropic: p.alpha_x != p.alpha_y,
            quadrature: crate::numerics::quadrature::Quadrature::GaussLegendreSqrt,
            iterations: 1,
            residual: 0.0,
            eigenvalue: 1.0,
            tabulated: TabulatedRecord {
                error: None,
                stretch: crate::model::tabulated::Stretch::IDENTITY,
                tables,
                diffuse: p.diffuse,
                origin: "power_iteration".into(),
            },
            fresnel: p.fresnel.clone(),
            fresnel_fits: p.fresnel_fits.clone(),
            ggx,
            beckmann,
            diffuse_lobe: p.fresnel_fits.is_some(),
            separation_rounds: 1,
            refine_rounds: 0,
            coat: None,
            metric: crate::metric::Metric::Log,
            metric_floor: 1.0,
            other_metric: None,
            look: None,
            timings_ms: Default::default(),
        }
    }

    pub(super) fn material(
        ggx: Option<ParamRecord>,
        beckmann: Option<ParamRecord>,
    ) -> FittedMaterial {
        FittedMaterial::from_record(record(ggx, beckmann)).unwrap()
    }

    pub(super) fn run(
        m: &FittedMaterial,
        target: Target,
        model: ModelRequest,
    ) -> Result<Exported, FitError> {
        export(
            m,
            Path::new("fits/test.json"),
            &ExportOptions {
                target,
                model,
                kind: KindRequest::Auto,
                coat: true,
            },
        )
    }

    /// A GGX gold fit of α 0.3 that kept a coat (η 1.5, α 0.04, weight 0.8; recorded errors 0.01,
    /// GGX 0.012) over a base of α 0.2.
    fn coated_gold() -> FittedMaterial {
        use crate::model::coat::Coat;
        use crate::model::material::CoatRecord;
        let gold = |a| Some(param(a, a, 0.0, &Fresnel::GOLD, [0.0; 3], true));
        let mut r = record(gold(0.3), None);
        r.coat = Some(CoatRecord {
            coat: Coat::new(1.5, 0.04, 0.8),
            error: 0.01,
            ggx_error: Some(0.012),
            beckmann_error: None,
            base: Box::new(record(gold(0.2), None)),
        });
        FittedMaterial::from_record(r).unwrap()
    }

    /// A fit that kept a coat exports the coat over its base's GGX fit: pbrt-v4's
    /// coatedconductor with the coat as the interface and the base as the conductor, glTF's
    /// clearcoat (factor w, roughness √α); the coated model's recorded error; Mitsuba, or
    /// `coat: false`, the single layer, saying so.
    #[test]
    fn a_coat_is_exported_over_its_base() {
        let m = coated_gold();
        let pbrt = run(&m, Target::Pbrt, ModelRequest::Ggx).unwrap();
        for line in [
            r#""string type" [ "coatedconductor" ]"#,
            r#""float interface.eta" [ 1.5 ]"#,
            r#""float interface.uroughness" [ 0.04 ]"#,
            r#""float conductor.uroughness" [ 0.2 ]"#,
        ] {
            assert!(pbrt.text.contains(line), "{line}:\n{}", pbrt.text);
        }
        let rep = &pbrt.report;
        assert_eq!((rep.table_error, rep.fresnel_error), (0.012, None));
        assert!(
            rep.notes.iter().any(|n| n.contains("written as 1")),
            "{:?}",
            rep.notes
        );
        assert!(
            rep.summary()
                .contains("under a clear coat (η 1.5, α 0.0400, weight 0.800)")
        );

        let gltf = run(&m, Target::Gltf, ModelRequest::Ggx).unwrap();
        let doc: serde_json::Value = serde_json::from_str(&gltf.text).unwrap();
        let mat = &doc["materials"][0];
        let cc = &mat["extensions"]["KHR_materials_clearcoat"];
        assert_eq!(cc["clearcoatFactor"], 0.8);
        assert!((cc["clearcoatRoughnessFactor"].as_f64().unwrap() - 0.2).abs() < 1e-12);
        let rough = mat["pbrMetallicRoughness"]["roughnessFactor"]
            .as_f64()
            .unwrap();
        assert!((rough - 0.2f64.sqrt()).abs() < 1e-12, "the base's α 0.2");
        assert!(
            doc["extensionsUsed"]
                .to_string()
                .contains("KHR_materials_clearcoat")
        );

        let single = export(
            &m,
            Path::new("fits/test.json"),
            &ExportOptions {
                target: Target::Pbrt,
                model: ModelRequest::Ggx,
                kind: KindRequest::Auto,
                coat: false,
            },
        )
        .unwrap();
        assert!(single.text.contains(r#""string type" [ "conductor" ]"#));
        assert!(
            single
                .report
                .notes
                .iter()
                .any(|n| n.contains("not asked for"))
        );
    }

    /// Mitsuba 3 gets the coated model tabulated: a `measured` `<bsdf>` naming
    /// `NAME.coated.bsdf`, the table's bytes, its error against the coated model stated. The
    /// table holds the coat: its error against the coated model is under a tenth of the single
    /// layer's distance to that model (the base at α 0.2 under a sharp coat against one lobe of
    /// α 0.3).
    #[test]
    fn mitsuba_gets_the_coat_tabulated() {
        use crate::metric::grid::{GridSamples, error_metric};
        use crate::sources::rgl::RglBsdf;
        let m = coated_gold();
        let x = run(&m, Target::Mitsuba, ModelRequest::Ggx).unwrap();
        assert!(
            x.text
                .contains(r#"<bsdf type="measured" id="test_material""#),
            "{}",
            x.text
        );
        assert!(
            x.text
                .contains(r#"<string name="filename" value="test_material.coated.bsdf"/>"#),
            "{}",
            x.text
        );
        let table = x.table.as_ref().expect("a table");
        assert_eq!(table.name, "test_material.coated.bsdf");
        let t = x.report.tabulated.as_ref().unwrap();
        assert!(x.report.summary().contains("test_material.coated.bsdf"));
        assert_eq!(x.report.table_error, 0.012);
        let file = RglBsdf::parse("t", table.bytes.clone()).unwrap();
        let coated = m.coated.as_ref().unwrap().model(ModelChoice::Ggx).unwrap();
        let set = GridSamples::new(&coated);
        let single = error_metric(m.model(ModelChoice::Ggx).unwrap(), &set);
        let tabulated = error_metric(&file, &set);
        assert!(
            (tabulated - t.error).abs() <= 1e-12 * t.error.max(1e-300),
            "{tabulated} {}",
            t.error
        );
        assert!(
            tabulated < 0.1 * single,
            "table {tabulated}, single layer {single}"
        );
        // Without the coat, the single layer as before.
        let single = export(
            &m,
            Path::new("fits/test.json"),
            &ExportOptions {
                target: Target::Mitsuba,
                model: ModelRequest::Ggx,
                kind: KindRequest::Auto,
                coat: false,
            },
        )
        .unwrap();
        assert!(single.text.contains(r#"<float name="alpha" value="0.3"/>"#));
        assert!(single.table.is_none() && single.report.tabulated.is_none());
    }

    /// A GGX gold fit exports the fit's conductor η and k exactly, α as is, the conductor's
    /// recorded error and the table error beside it.
    #[test]
    fn gold_exports_the_conductor_fit() {
        let m = material(
            Some(param(0.2, 0.2, 0.0, &Fresnel::GOLD, [0.0; 3], true)),
            None,
        );
        let fits = m.record.ggx.as_ref().unwrap().fresnel_fits.clone().unwrap();
        let x = run(&m, Target::Mitsuba, ModelRequest::Ggx).unwrap();
        assert_eq!(x.report.kind, Kind::Conductor);
        assert!(
            x.text
                .contains(r#"<bsdf type="roughconductor" id="test_material" version="3.0.0">"#),
            "{}",
            x.text
        );
        assert!(x.text.contains(r#"<float name="alpha" value="0.2"/>"#));
        assert!(x.text.contains(&format!(
            r#"<rgb name="eta" value="{}, {}, {}"/>"#,
            fits.conductor_eta[0], fits.conductor_eta[1], fits.conductor_eta[2]
        )));
        assert!(x.text.contains(&format!(
            r#"<rgb name="k" value="{}, {}, {}"/>"#,
            fits.conductor_k[0], fits.conductor_k[1], fits.conductor_k[2]
        )));
        assert_eq!(x.report.fresnel_error, Some(0.011));
        assert!(
            x.text.contains("1.1e-2") && x.text.contains("5e-3"),
            "{}",
            x.text
        );
        let pbrt = run(&m, Target::Pbrt, ModelRequest::Ggx).unwrap();
        assert!(pbrt.text.contains(&format!(
            "\"rgb eta\" [ {} {} {} ]",
            fits.conductor_eta[0], fits.conductor_eta[1], fits.conductor_eta[2]
        )));
        assert!(pbrt.text.contains("\"float uroughness\" [ 0.2 ]"));
        assert!(pbrt.text.contains("\"bool remaproughness\" [ false ]"));
        let g = run(&m, Target::Gltf, ModelRequest::Ggx).unwrap();
        assert_eq!(g.report.fresnel, "schlick");
        assert_eq!(g.report.fresnel_error, Some(0.033));
        let v: serde_json::Value = serde_json::from_str(&g.text).unwrap();
        let pbr = &v["materials"][0]["pbrMetallicRoughness"];
        assert_eq!(pbr["metallicFactor"], 1.0);
        assert_eq!(pbr["roughnessFactor"].as_f64().unwrap(), 0.2f64.sqrt());
        for c in 0..3 {
            assert_eq!(
                pbr["baseColorFactor"][c].as_f64().unwrap(),
                fits.schlick_f0[c]
            );
        }
    }

    /// A plastic: η and ρd written as the fit has them; anisotropy in Mitsuba is √(αx αy).
    #[test]
    fn plastic_exports_the_dielectric_fit() {
        let kd = [0.3, 0.1, 0.05];
        let m = material(
            Some(param(
                0.3,
                0.1,
                0.5,
                &Fresnel::Dielectric { eta: 1.5 },
                kd,
                true,
            )),
            None,
        );
        let fits = m.record.ggx.as_ref().unwrap().fresnel_fits.clone().unwrap();
        assert!((fits.dielectric_eta - 1.5).abs() < 1e-3);
        let x = run(&m, Target::Mitsuba, ModelRequest::Ggx).unwrap();
        assert_eq!(x.report.kind, Kind::Plastic);
        assert_eq!(x.report.fresnel_error, Some(0.022));
        assert!(x.text.contains(r#"type="roughplastic""#));
        assert!(x.text.contains(&format!(
            r#"<float name="alpha" value="{}"/>"#,
            (0.3f64 * 0.1).sqrt()
        )));
        assert!(x.text.contains(&format!(
            r#"<float name="int_ior" value="{}"/>"#,
            fits.dielectric_eta
        )));
        assert!(
            x.text
                .contains(r#"<rgb name="diffuse_reflectance" value="0.3, 0.1, 0.05"/>"#)
        );
        assert!(x.text.contains("cannot rotate"), "{}", x.text);
        assert!(
            !x.text[x.text.find("<!--").unwrap() + 4..x.text.find("-->").unwrap()].contains("--")
        );
        let p = run(&m, Target::Pbrt, ModelRequest::Ggx).unwrap();
        assert!(p.text.contains("\"string type\" [ \"coateddiffuse\" ]"));
        assert!(p.text.contains("\"rgb reflectance\" [ 0.3 0.1 0.05 ]"));
        assert!(
            p.text.contains("\"float uroughness\" [ 0.3 ]")
                && p.text.contains("\"float vroughness\" [ 0.1 ]")
        );
        let g = run(&m, Target::Gltf, ModelRequest::Ggx).unwrap();
        let v: serde_json::Value = serde_json::from_str(&g.text).unwrap();
        let mat = &v["materials"][0];
        assert_eq!(mat["pbrMetallicRoughness"]["metallicFactor"], 0.0);
        assert_eq!(
            mat["pbrMetallicRoughness"]["roughnessFactor"]
                .as_f64()
                .unwrap(),
            0.1f64.sqrt()
        );
        // glTF's Fresnel is Schlick's: the ior is the Schlick fit's F0 (achromatic here, so no
        // KHR_materials_specular).
        let f0 = fits.schlick_f0.iter().sum::<f64>() / 3.0;
        let ior = mat["extensions"]["KHR_materials_ior"]["ior"]
            .as_f64()
            .unwrap();
        assert_eq!(ior, schlick_ior(f0));
        assert!((dielectric_f0(ior) / f0 - 1.0).abs() < 1e-12);
        assert!(mat["extensions"]["KHR_materials_specular"].is_null());
        assert_eq!(g.report.fresnel_error, Some(0.033));
        let an = &mat["extensions"]["KHR_materials_anisotropy"];
        let (along, across) = gltf_alphas(
            mat["pbrMetallicRoughness"]["roughnessFactor"]
                .as_f64()
                .unwrap(),
            an["anisotropyStrength"].as_f64().unwrap(),
        );
        assert!((along - 0.3).abs() < 1e-12 && (across - 0.1).abs() < 1e-12);
        assert_eq!(an["anisotropyRotation"].as_f64().unwrap(), 0.5);
        let used: Vec<&str> = v["extensionsUsed"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_str().unwrap())
            .collect();
        assert!(used.contains(&"KHR_materials_ior") && used.contains(&"KHR_materials_anisotropy"));
    }

    /// Beckmann: Mitsuba writes it; pbrt and glTF take the GGX fit and say so; a fit without
    /// the asked model is an error naming the file.
    #[test]
    fn beckmann_and_missing_models() {
        let gold = |a| param(a, a, 0.0, &Fresnel::GOLD, [0.0; 3], true);
        let m = material(Some(gold(0.2)), Some(gold(0.25)));
        let x = run(&m, Target::Mitsuba, ModelRequest::Beckmann).unwrap();
        assert!(x.text.contains(r#"value="beckmann""#) && x.text.contains(r#"value="0.25""#));
        let p = run(&m, Target::Pbrt, ModelRequest::Beckmann).unwrap();
        assert_eq!((p.report.fit_model, p.report.distribution), ("ggx", "ggx"));
        assert!(p.text.contains("[ 0.2 ]") && p.text.contains("no Beckmann distribution"));
        let only_ggx = material(Some(gold(0.2)), None);
        let e = run(&only_ggx, Target::Mitsuba, ModelRequest::Beckmann)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("fits/test.json") && e.contains("no Beckmann model"),
            "{e}"
        );
        let only_beckmann = material(None, Some(gold(0.2)));
        let e = run(&only_beckmann, Target::Gltf, ModelRequest::Beckmann)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("fits/test.json") && e.contains("only the GGX"),
            "{e}"
        );
        let e = run(&only_beckmann, Target::Pbrt, ModelRequest::Ggx)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no GGX model"), "{e}");
        // Best: the lower error the target can represent.
        let best = run(&only_beckmann, Target::Mitsuba, ModelRequest::Best).unwrap();
        assert_eq!(best.report.fit_model, "beckmann");
    }

    /// Without recorded Fresnel fits the curve is fitted here and its error is unknown.
    #[test]
    fn unrecorded_fresnel_fits_are_fitted_with_unknown_error() {
        let m = material(
            Some(param(0.2, 0.2, 0.0, &Fresnel::GOLD, [0.0; 3], false)),
            None,
        );
        let x = run(&m, Target::Pbrt, ModelRequest::Ggx).unwrap();
        assert_eq!(x.report.fresnel_error, None);
        assert!(!x.report.fresnel_fits_recorded);
        assert!(x.text.contains("unknown"));
        assert!(x.report.summary().contains("error unknown"));
        // Gold's η comes back from its own table (fresnel_fit's tolerance).
        let Fresnel::Conductor { eta, .. } = Fresnel::GOLD else {
            unreachable!()
        };
        let fits = FresnelFits::of(&m.record.ggx.as_ref().unwrap().fresnel, |_| [0.0; 3]);
        assert!((fits.conductor_eta[0] / eta[0] - 1.0).abs() < 0.02);
        assert!(x.text.contains(&format!("{}", fits.conductor_eta[0])));
    }

    /// The automatic kind: F0 ≥ 0.2 is a conductor whatever ρd; below, a conductor only with
    /// no diffuse lobe and a conductor curve clearly better than the dielectric.
    #[test]
    fn auto_kind_rule() {
        let kind = |f: &Fresnel, kd: Rgb, tie: bool| {
            let mut p = param(0.2, 0.2, 0.0, f, kd, true);
            if tie {
                let fits = p.fresnel_fits.as_mut().unwrap();
                fits.conductor.error = fits.dielectric.error;
            }
            run(&material(Some(p), None), Target::Mitsuba, ModelRequest::Ggx)
                .unwrap()
                .report
        };
        // Gold with a diffuse lobe: a conductor, ρd dropped and said so.
        let r = kind(&Fresnel::GOLD, [0.1; 3], false);
        assert_eq!(r.kind, Kind::Conductor);
        assert!(
            r.notes.iter().any(|n| n.contains("dropped")),
            "{:?}",
            r.notes
        );
        // A colourless black dielectric: the curves tie, a plastic.
        let glass = Fresnel::Dielectric { eta: 1.5 };
        assert_eq!(kind(&glass, [0.0; 3], true).kind, Kind::Plastic);
        // A coloured F of low F0 and no diffuse lobe (a metallic paint): the conductor fits
        // better (the made-up errors: 0.011 against 0.022), a conductor; with ρd, a plastic.
        let paint = Fresnel::Conductor {
            eta: [2.75, 2.2, 1.07],
            k: [0.0; 3],
        };
        assert_eq!(kind(&paint, [0.0; 3], false).kind, Kind::Conductor);
        assert_eq!(kind(&paint, [0.05; 3], false).kind, Kind::Plastic);
    }
}
