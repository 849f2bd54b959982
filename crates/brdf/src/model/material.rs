//! A fitted material: the tabulated NDF with its Fresnel table, the GGX and Beckmann fits, and
//! the record written as `<name>.json`. Each model is itself a [`Brdf`].

use crate::error::BrdfError;
use crate::model::brdf::Brdf;
use crate::model::coat::{Coat, CoatLayer, Coated};
use crate::model::fresnel::{Fresnel, FresnelTable};
use crate::model::fresnel_curves::FresnelFits;
use crate::model::metric::Metric;
use crate::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use crate::model::rgb::Rgb;
use crate::model::tabulated::{NdfTables, Stretch, TabulatedNdf};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Arc;

/// α and rotation of a parametric fit, with its error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// α along the NDF's rotated x axis.
    pub alpha_x: f64,
    /// α along the NDF's rotated y axis (equal to `alpha_x` in an isotropic fit).
    pub alpha_y: f64,
    /// Radians.
    pub rotation: f64,
    /// The error metric of this model against the source.
    pub error: f64,
}

/// A GGX or Beckmann fit: by least squares in the metric's space (the model used, with a
/// Fresnel table averaged for its own D and G), and beside it the paper's estimate (α by first
/// absolute slope moments, with the extraction's Fresnel) and its error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamRecord {
    /// α along the rotated x axis, by least squares.
    pub alpha_x: f64,
    /// α along the rotated y axis, by least squares.
    pub alpha_y: f64,
    /// Rotation of the α axes, radians.
    pub rotation: f64,
    /// The error metric of the least-squares model with its own Fresnel table (and ρd); a
    /// physical Fresnel's error is in `fresnel_fits`.
    pub error: f64,
    /// How `alpha_x`, `alpha_y` and `rotation` were found (`"least_squares"`).
    pub method: String,
    /// The paper's estimate by slope moments, with its error: with a diffuse lobe on a quarter
    /// of the grid's rows, as the physical curves' errors (within 0.6 % of the full grid's on
    /// the 100 MERL proxies, median 0.04 %).
    pub moments: Params,
    /// F(θd) for this model's own D and G: averaged (the paper), or with a diffuse lobe solved
    /// together with `diffuse` and kept in [0, 1].
    pub fresnel: FresnelTable,
    /// The Lambertian albedo ρd (f = ρd/π) fitted with this model; zero without a diffuse lobe.
    #[serde(default)]
    pub diffuse: Rgb,
    /// Conductor, dielectric and Schlick curves fitted to `fresnel`, and which one the renderer
    /// uses (absent: the table; fits without a diffuse lobe have none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fresnel_fits: Option<FresnelFits>,
}

/// The extracted (tabulated) model of a fit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TabulatedRecord {
    /// Error metric of the tabulated model; absent when it was not asked for.
    pub error: Option<f64>,
    /// The stretch applied to the tables (identity as extracted; edited in the viewer).
    pub stretch: Stretch,
    /// The extracted D and G1 tables.
    pub tables: NdfTables,
    /// The Lambertian albedo ρd (f = ρd/π) of the tabulated model; zero without a diffuse lobe.
    #[serde(default)]
    pub diffuse: Rgb,
    /// Where the tables come from: `power_iteration` (the extraction, refined when the fit
    /// refines), or `ggx` / `beckmann` when that fit's NDF, tabulated and refined, fitted
    /// better than every extraction.
    #[serde(default = "power_iteration")]
    pub origin: String,
}

fn power_iteration() -> String {
    "power_iteration".into()
}

/// Wall-clock times of a fit's phases, milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Timings {
    /// Reading the source (0 when the caller did not time it).
    pub load: f64,
    /// The first power iteration and its D / G1 tables.
    pub extract: f64,
    /// The grid samples and the tabulated model's F (and ρd): with a diffuse lobe, its
    /// separation (more extractions), refinement and physical Fresnel fits included.
    pub fresnel: f64,
    /// The GGX / Beckmann fits with their errors (and physical Fresnel fits).
    pub fit: f64,
    /// The coat's search and its base's fit (0 without one).
    #[serde(default)]
    pub coat: f64,
    /// The whole fit.
    pub total: f64,
}

/// The fit JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// The source's name.
    pub name: String,
    /// Where the source came from, as the caller described it (a path, `nbrdf:NAME`, ...).
    pub source: String,
    /// What ran the extraction: `cpu`, the adapter's description, or a CPU fallback notice.
    pub backend: String,
    /// The GPU's error when a GPU fit fell back to the CPU (`backend` then says so in words).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
    /// θ samples of the extraction.
    pub resolution: usize,
    /// φ samples of the extraction (1 when isotropic).
    pub phi_resolution: usize,
    /// Whether αx, αy and a rotation were fitted.
    pub anisotropic: bool,
    /// The quadrature of the power iteration.
    pub quadrature: crate::numerics::quadrature::Quadrature,
    /// Power iterations run.
    pub iterations: usize,
    /// Residual of the power iteration when it stopped.
    pub residual: f64,
    /// λ of the power iteration: F(0) of the backscattering slice, mean of RGB.
    pub eigenvalue: f64,
    /// The extracted model.
    pub tabulated: TabulatedRecord,
    /// The GGX fit, when asked for.
    pub ggx: Option<ParamRecord>,
    /// The Beckmann fit, when asked for.
    pub beckmann: Option<ParamRecord>,
    /// F(θd) of the tabulated model.
    pub fresnel: FresnelTable,
    /// Physical curves fitted to `fresnel` and the one the renderer uses (see
    /// [`ParamRecord::fresnel_fits`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fresnel_fits: Option<FresnelFits>,
    /// Whether the models carry a fitted diffuse lobe (`--no-diffuse` and anisotropic fits:
    /// false, the paper's single lobe).
    #[serde(default)]
    pub diffuse_lobe: bool,
    /// Extractions run to separate the diffuse lobe from the tabulated NDF (1 without one).
    #[serde(default)]
    pub separation_rounds: usize,
    /// Rounds of the refinement of the tabulated NDF in the metric's space (0: none).
    #[serde(default)]
    pub refine_rounds: usize,
    /// A clear coat over a base, where it fits the source better than the single layer above
    /// (absent: none was searched, or none fitted better). The single layer's models stay
    /// what they are; this is a second, coated model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coat: Option<CoatRecord>,
    /// The objective the fit minimised: every `error` above is in it (`log` in records
    /// written before it was recorded, the paper's metric).
    #[serde(default = "paper_metric")]
    pub metric: Metric,
    /// The metric's ε: its errors are |ln(1 + x_model/ε) − ln(1 + x_data/ε)| (1 for `log`).
    #[serde(default = "one")]
    pub metric_floor: f64,
    /// The same models' errors in the other metric (absent in older records).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other_metric: Option<MetricErrors>,
    /// How the tabulated model looks beside the source: the sphere under the report's point
    /// light (absent for anisotropic sources and in older records).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub look: Option<LookRecord>,
    /// How long each phase took.
    pub timings_ms: Timings,
}

fn paper_metric() -> Metric {
    Metric::Log
}

fn one() -> f64 {
    1.0
}

/// A fit's models' errors in one metric.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MetricErrors {
    /// The metric.
    pub metric: Metric,
    /// The tabulated model's error.
    pub tabulated: Option<f64>,
    /// The GGX model's, where fitted.
    pub ggx: Option<f64>,
    /// The Beckmann model's, where fitted.
    pub beckmann: Option<f64>,
    /// The coated tabulated model's, where the fit kept a coat.
    pub coated: Option<f64>,
}

/// The mean CIEDE2000 between a model and its source on a sphere under the report's point
/// light (facet-fit's `metric::look::SphereScene::REPORT`, the source read from its MERL-grid
/// table): below 1 the eye sees no difference.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LookRecord {
    /// The single layer's tabulated model's ΔE2000.
    pub tabulated: f64,
    /// The coated tabulated model's, where a coat was searched (kept or not).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coated: Option<f64>,
}

/// A coat kept by the fit ([`crate::model::coat`]): its parameters, the coated models' errors
/// against the source, and the base under it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoatRecord {
    /// η, α and weight of the coat.
    #[serde(flatten)]
    pub coat: Coat,
    /// The coated tabulated model's error against the source (compare with
    /// `tabulated.error`, the single layer's).
    pub error: f64,
    /// The coated GGX model's error, when GGX was fitted.
    #[serde(default)]
    pub ggx_error: Option<f64>,
    /// The coated Beckmann model's error, when Beckmann was fitted.
    #[serde(default)]
    pub beckmann_error: Option<f64>,
    /// The base: the fit of the data as seen from inside the coat, its models evaluated at the
    /// refracted directions (its own errors are against those data).
    pub base: Box<FitRecord>,
}

/// The coated models of a fit: the coat and the base's models under it.
#[derive(Clone, Debug)]
pub struct CoatedModels {
    /// The coat.
    pub layer: CoatLayer,
    /// The base's models.
    pub base: FittedMaterial,
}

impl CoatedModels {
    /// One of the base's models under the coat, if it was fitted.
    pub fn model(&self, choice: ModelChoice) -> Option<Coated<MicrofacetBrdf>> {
        self.base.model(choice).map(|m| Coated {
            layer: self.layer.clone(),
            base: m.clone(),
        })
    }
}

/// Which model of a fit to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelChoice {
    /// The extracted NDF and G1 tables.
    Tabulated,
    /// The GGX fit.
    Ggx,
    /// The Beckmann fit.
    Beckmann,
}

impl ModelChoice {
    /// `tabulated`, `ggx` or `beckmann`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "tabulated" => Some(ModelChoice::Tabulated),
            "ggx" => Some(ModelChoice::Ggx),
            "beckmann" => Some(ModelChoice::Beckmann),
            _ => None,
        }
    }
}

/// A fit record with its models built.
#[derive(Clone, Debug)]
pub struct FittedMaterial {
    /// What is saved as JSON.
    pub record: FitRecord,
    /// The tabulated model (with the record's stretch).
    pub tabulated: MicrofacetBrdf,
    /// The GGX model, when fitted.
    pub ggx: Option<MicrofacetBrdf>,
    /// The Beckmann model, when fitted.
    pub beckmann: Option<MicrofacetBrdf>,
    /// The coated models, when the fit kept a coat (`record.coat`).
    pub coated: Option<Box<CoatedModels>>,
}

impl FittedMaterial {
    /// Builds the models of a record, checking its tables and parameters.
    pub fn from_record(record: FitRecord) -> Result<Self, String> {
        record.fresnel.validate()?;
        let st = record.tabulated.stretch;
        check_alpha("tabulated.stretch", st.alpha_x, st.alpha_y, st.rotation)?;
        let ndf = TabulatedNdf::new(record.tabulated.tables.clone(), record.tabulated.stretch)
            .map_err(|e| format!("tabulated.tables: {e}"))?;
        Self::with_ndf(record, Arc::new(ndf))
    }

    /// [`FittedMaterial::from_record`] for a record whose tabulated NDF is built already (a
    /// fit's own): its sampler is not built a second time. `ndf` must be the record's
    /// tables with the record's stretch.
    pub fn from_parts(record: FitRecord, ndf: Arc<TabulatedNdf>) -> Result<Self, String> {
        debug_assert!(
            ndf.tables() == &record.tabulated.tables && ndf.stretch == record.tabulated.stretch,
            "from_parts: the NDF is not the record's"
        );
        record.fresnel.validate()?;
        let st = record.tabulated.stretch;
        check_alpha("tabulated.stretch", st.alpha_x, st.alpha_y, st.rotation)?;
        Self::with_ndf(record, ndf)
    }

    /// The models of a record whose Fresnel table and stretch are checked, with its NDF.
    fn with_ndf(record: FitRecord, ndf: Arc<TabulatedNdf>) -> Result<Self, String> {
        check_normalised(&ndf)?;
        check_figures(&record)?;
        check_albedo("tabulated.diffuse", record.tabulated.diffuse)?;
        let tabulated = MicrofacetBrdf {
            name: format!("{}-tabulated", record.name),
            ndf: Ndf::Tabulated(ndf),
            fresnel: used_fresnel("fresnel_fits", &record.fresnel_fits, &record.fresnel)?,
            diffuse: record.tabulated.diffuse,
        };
        let param =
            |kind: NdfKind, p: &Option<ParamRecord>| -> Result<Option<MicrofacetBrdf>, String> {
                let Some(p) = p else { return Ok(None) };
                p.fresnel.validate()?;
                check_alpha(
                    &format!("{}.alpha", kind.name()),
                    p.alpha_x,
                    p.alpha_y,
                    p.rotation,
                )?;
                check_albedo(&format!("{}.diffuse", kind.name()), p.diffuse)?;
                Ok(Some(MicrofacetBrdf {
                    name: format!("{}-{}", record.name, kind.name()),
                    ndf: Ndf::Analytic(AnalyticNdf {
                        kind,
                        alpha_x: p.alpha_x,
                        alpha_y: p.alpha_y,
                        rotation: p.rotation,
                    }),
                    fresnel: used_fresnel(
                        &format!("{}.fresnel_fits", kind.name()),
                        &p.fresnel_fits,
                        &p.fresnel,
                    )?,
                    diffuse: p.diffuse,
                }))
            };
        let ggx = param(NdfKind::Ggx, &record.ggx)?;
        let beckmann = param(NdfKind::Beckmann, &record.beckmann)?;
        let coated = record.coat.as_ref().map(coated_models).transpose()?;
        Ok(FittedMaterial {
            record,
            tabulated,
            ggx,
            beckmann,
            coated,
        })
    }

    /// Reads a fit JSON written by [`FittedMaterial::save`].
    pub fn load(path: &Path) -> Result<Self, BrdfError> {
        Self::parse(
            path,
            &crate::io::input::read_to_string(path, crate::io::input::Cap::FIT_JSON)?,
        )
    }

    /// A fit from the text of its JSON; `path` names it in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Self, BrdfError> {
        let bad = |problem: String| BrdfError::Material {
            path: path.to_owned(),
            problem,
        };
        let record: FitRecord = serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        Self::from_record(record).map_err(bad)
    }

    /// Writes the record as pretty JSON, through a temporary file renamed into place.
    pub fn save(&self, path: &Path) -> Result<(), BrdfError> {
        let text =
            serde_json::to_string_pretty(&self.record).expect("a fit record always serialises");
        crate::io::output::write_bytes_atomically(path, text).map_err(|e| BrdfError::io(path, e))
    }

    /// One of the fitted models, if it was fitted.
    pub fn model(&self, choice: ModelChoice) -> Option<&MicrofacetBrdf> {
        match choice {
            ModelChoice::Tabulated => Some(&self.tabulated),
            ModelChoice::Ggx => self.ggx.as_ref(),
            ModelChoice::Beckmann => self.beckmann.as_ref(),
        }
    }

    /// The tabulated model with its NDF stretched: `P(x~/αx, y~/αy) sec⁴θ / (αx αy)`.
    pub fn stretched(&self, stretch: Stretch) -> MicrofacetBrdf {
        let Ndf::Tabulated(t) = &self.tabulated.ndf else {
            unreachable!("the tabulated model has a tabulated NDF")
        };
        MicrofacetBrdf {
            ndf: Ndf::Tabulated(Arc::new(t.with_stretch(stretch))),
            ..self.tabulated.clone()
        }
    }
}

/// α in [`ALPHA_RANGE`](crate::model::analytic::ALPHA_RANGE) and a finite rotation, or an error naming
/// the field and the values.
fn check_alpha(field: &str, alpha_x: f64, alpha_y: f64, rotation: f64) -> Result<(), String> {
    let range = crate::model::analytic::ALPHA_RANGE;
    if range.contains(&alpha_x) && range.contains(&alpha_y) && rotation.is_finite() {
        return Ok(());
    }
    Err(format!(
        "{field}: α = ({alpha_x}, {alpha_y}), rotation {rotation} (α must lie in [{:e}, {}], the rotation be finite)",
        range.start(),
        range.end()
    ))
}

/// The longest a recorded phase of a fit may have taken, ms: a week (a fit takes seconds).
const MAX_PHASE_MS: f64 = 7.0 * 24.0 * 3600e3;
/// The largest ΔE2000 a look may record (two colours of CIELAB differ by at most about 200).
const MAX_DELTA_E: f64 = 1000.0;

/// The figures a record reports rather than renders with: each phase's time in
/// [0, [`MAX_PHASE_MS`]], each look in [0, [`MAX_DELTA_E`]], the metric's ε positive and
/// finite; an error naming the field and its value (a summary of fits sums the times: 1.7e308
/// of them made "inf s in all").
fn check_figures(r: &FitRecord) -> Result<(), String> {
    let in_range = |field: &str, v: f64, max: f64, unit: &str| match (0.0..=max).contains(&v) {
        true => Ok(()),
        false => Err(format!("{field}: {v}{unit} (between 0 and {max}{unit})")),
    };
    let t = &r.timings_ms;
    for (field, v) in [
        ("load", t.load),
        ("extract", t.extract),
        ("fresnel", t.fresnel),
        ("fit", t.fit),
        ("coat", t.coat),
        ("total", t.total),
    ] {
        in_range(&format!("timings_ms.{field}"), v, MAX_PHASE_MS, " ms")?;
    }
    if let Some(look) = r.look {
        in_range("look.tabulated", look.tabulated, MAX_DELTA_E, "")?;
        if let Some(c) = look.coated {
            in_range("look.coated", c, MAX_DELTA_E, "")?;
        }
    }
    if !(r.metric_floor > 0.0 && r.metric_floor.is_finite()) {
        return Err(format!(
            "metric_floor: {} (the metric's ε is positive and finite)",
            r.metric_floor
        ));
    }
    Ok(())
}

/// The widest factor by which a read NDF table's ∫ D cos θ dω may miss 1: 45 % is the table
/// quadrature's own error at worst (a Beckmann NDF of α = 10⁻⁴ on 256 nodes; a constant D on
/// two nodes: 41 %). A table off by more is no distribution but a scaled one: D = 10³⁸ gave
/// one flake a DPF of P = 10³⁶, D = 10³⁰⁰ overflowed the DPF's f32 table to P = NaN.
const NORMALISATION_SLACK: f64 = 10.0;

/// The tabulated NDF of a fit read from a file is a distribution: ∫ D cos θ dω = 1 within
/// [`NORMALISATION_SLACK`], or an error with the integral.
fn check_normalised(ndf: &TabulatedNdf) -> Result<(), String> {
    let area = ndf.projected_area();
    if (1.0 / NORMALISATION_SLACK..=NORMALISATION_SLACK).contains(&area) {
        return Ok(());
    }
    Err(format!(
        "tabulated.tables: the NDF integrates to ∫ D cos θ dω = {area:e}, not 1 (a normal \
         distribution; at most a factor of {NORMALISATION_SLACK} off is read)"
    ))
}

/// The coated models of a record's coat, or an error naming the field.
fn coated_models(c: &CoatRecord) -> Result<Box<CoatedModels>, String> {
    if c.base.coat.is_some() {
        return Err("coat.base: a base under a coat holds a coat itself".into());
    }
    let layer = CoatLayer::new(c.coat)?;
    let base =
        FittedMaterial::from_record((*c.base).clone()).map_err(|e| format!("coat.base: {e}"))?;
    Ok(Box::new(CoatedModels { layer, base }))
}

/// The Fresnel a model renders with: its table, or the fit that `fits.used` names.
fn used_fresnel(
    field: &str,
    fits: &Option<FresnelFits>,
    table: &FresnelTable,
) -> Result<Fresnel, String> {
    match fits {
        None => Ok(Fresnel::Table(table.clone())),
        Some(f) => {
            f.validate(field)?;
            Ok(f.fresnel(f.used, table))
        }
    }
}

/// An albedo in [0, 1] per channel, or an error naming the field and the values.
fn check_albedo(field: &str, albedo: Rgb) -> Result<(), String> {
    if albedo.iter().all(|a| (0.0..=1.0).contains(a)) {
        return Ok(());
    }
    Err(format!(
        "{field}: ρd = {albedo:?} (each channel must lie in [0, 1])"
    ))
}

/// A fit as a source (`facet convert fit.json …`, `facet fit fit.json`, a measured material's
/// `source`): its tabulated model, under its coat when it kept one, the fit's closest model of
/// the data.
impl Brdf for FittedMaterial {
    fn name(&self) -> &str {
        &self.record.name
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        match &self.coated {
            Some(c) => c.layer.over(&c.base.tabulated, wi, wo),
            None => self.tabulated.eval(wi, wo),
        }
    }

    fn is_isotropic(&self) -> bool {
        self.tabulated.is_isotropic()
    }
}
