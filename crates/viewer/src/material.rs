//! The edited material: a fit record, the model shown, and the edits applied on top of it.

use facet_fit::model::coat::Coat;
use facet_fit::model::material::{FitRecord, FittedMaterial, ModelChoice};
use facet_render::scene::{FacetMaterial, GlintParams, Material, MeasuredMaterial, Measurement};
use std::path::PathBuf;
use std::sync::Arc;

/// What the preview shows on the sphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// The measurement itself (a MERL-grid table or an RGL file, on the GPU), sampled by the
    /// unedited fit; only when the input was a measurement.
    Measured,
    /// The tabulated fit with the edited stretch.
    Tabulated,
    /// The GGX fit with its edited α.
    Ggx,
    /// The Beckmann fit with its edited α.
    Beckmann,
    /// The GGX model with glints.
    Glint,
}

impl Shown {
    /// Every choice, in the order of the selector.
    pub const ALL: [Shown; 5] = [
        Shown::Measured,
        Shown::Tabulated,
        Shown::Ggx,
        Shown::Beckmann,
        Shown::Glint,
    ];

    /// The selector's label.
    pub fn label(self) -> &'static str {
        match self {
            Shown::Measured => "measured data",
            Shown::Tabulated => "tabulated fit",
            Shown::Ggx => "GGX",
            Shown::Beckmann => "Beckmann",
            Shown::Glint => "glint",
        }
    }
}

/// Glint settings of the edit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlintEdit {
    /// Flakes per unit UV area.
    pub density: f32,
    /// Cone half-angle γ, degrees.
    pub gamma_deg: f32,
    /// Expected count above which the count is replaced by its mean.
    pub threshold: f32,
    /// Flakes drawn from the fit's tabulated NDF instead of its GGX model.
    pub tabulated: bool,
}

impl Default for GlintEdit {
    fn default() -> Self {
        GlintEdit {
            density: 2.0e5,
            gamma_deg: 1.0,
            threshold: 64.0,
            tabulated: false,
        }
    }
}

/// The loaded fit and the edits on it. `record` holds the edited α, rotation and diffuse
/// albedo ρd of every model, the single layer's and (in `record.coat.base`) those of the base
/// under the fit's coat; `tint` multiplies the Fresnel tables of the layer shown when the record
/// is written out. While the coat is shown ([`EditedMaterial::coat_shown`]) the α, ρd and tint
/// edits go to the base under it, else to the single layer.
#[derive(Clone, Debug)]
pub struct EditedMaterial {
    /// The fit as loaded or fitted (the "data's fit" of the plots).
    pub base: Arc<FittedMaterial>,
    /// Where it came from (file path or source spec).
    pub source: String,
    /// The record with edited α, rotation and ρd.
    pub record: FitRecord,
    /// Which model the preview shows.
    pub shown: Shown,
    /// RGB multiplier of every Fresnel table.
    pub tint: [f64; 3],
    /// Glint settings.
    pub glint: GlintEdit,
    /// αx and αy move together (their ratio kept).
    pub lock: bool,
    /// The measurement the fit was made from (`None` for a fit JSON).
    pub measurement: Option<Arc<Measurement>>,
    /// The fit's coat as edited (η, α, weight); `None`: the fit has none, or it is switched
    /// off.
    pub coat: Option<Coat>,
}

impl EditedMaterial {
    /// The edit of `base` (from `source`) before any change: GGX shown when fitted, else the tabulated fit.
    pub fn new(base: FittedMaterial, source: String) -> Self {
        let record = base.record.clone();
        let shown = if record.ggx.is_some() {
            Shown::Ggx
        } else {
            Shown::Tabulated
        };
        EditedMaterial {
            base: Arc::new(base),
            source,
            shown,
            tint: [1.0; 3],
            glint: GlintEdit::default(),
            lock: true,
            measurement: None,
            coat: record.coat.as_ref().map(|c| c.coat),
            record,
        }
    }

    /// The edit of `base`, fitted from `measurement` (which "measured data" renders).
    pub fn with_measurement(
        base: FittedMaterial,
        source: String,
        measurement: Measurement,
    ) -> Self {
        EditedMaterial {
            measurement: Some(Arc::new(measurement)),
            ..Self::new(base, source)
        }
    }

    /// The model the shown choice renders with.
    pub fn model(&self) -> ModelChoice {
        match self.lobe() {
            Shown::Measured | Shown::Tabulated => ModelChoice::Tabulated,
            Shown::Ggx | Shown::Glint => ModelChoice::Ggx,
            Shown::Beckmann => ModelChoice::Beckmann,
        }
    }

    /// Whether the fit's coat is shown (the fit kept one and it is switched on): the α, ρd and
    /// tint edits then go to the base under it.
    pub fn coat_shown(&self) -> bool {
        self.coat.is_some() && self.record.coat.is_some()
    }

    /// The layer the α and ρd edits go to: the base under the coat while it is shown, else the
    /// single layer.
    fn layer(&self) -> &FitRecord {
        match &self.record.coat {
            Some(c) if self.coat.is_some() => &c.base,
            _ => &self.record,
        }
    }

    /// See [`Self::layer`].
    fn layer_mut(&mut self) -> &mut FitRecord {
        if self.coat_shown() {
            let c = self
                .record
                .coat
                .as_mut()
                .expect("coat_shown: the fit has a coat");
            &mut c.base
        } else {
            &mut self.record
        }
    }

    /// The layer of the fit as loaded that [`Self::layer`] edits.
    fn fitted_layer(&self) -> &FitRecord {
        match &self.base.record.coat {
            Some(c) if self.coat.is_some() => &c.base,
            _ => &self.base.record,
        }
    }

    /// The smooth model whose NDF the shown material uses: glints take the tabulated NDF when
    /// asked to (or when the fit has no GGX model), else GGX.
    pub fn lobe(&self) -> Shown {
        match self.shown {
            Shown::Glint if self.glint.tabulated || self.layer().ggx.is_none() => Shown::Tabulated,
            Shown::Glint => Shown::Ggx,
            s => s,
        }
    }

    /// Whether the shown model exists in the fit (GGX/Beckmann may be absent).
    pub fn available(&self, shown: Shown) -> bool {
        match shown {
            Shown::Measured => self.measurement.is_some(),
            Shown::Tabulated | Shown::Glint => true,
            Shown::Ggx => self.layer().ggx.is_some(),
            Shown::Beckmann => self.layer().beckmann.is_some(),
        }
    }

    /// (αx, αy, rotation) of the shown model, in the layer edited ([`Self::coat_shown`]): the
    /// tabulated stretch or the analytic α.
    pub fn alpha(&self) -> Option<(f64, f64, f64)> {
        let r = self.layer();
        match self.lobe() {
            Shown::Measured => None,
            Shown::Tabulated => {
                let s = r.tabulated.stretch;
                Some((s.alpha_x, s.alpha_y, s.rotation))
            }
            Shown::Ggx | Shown::Glint => r.ggx.as_ref().map(|p| (p.alpha_x, p.alpha_y, p.rotation)),
            Shown::Beckmann => r
                .beckmann
                .as_ref()
                .map(|p| (p.alpha_x, p.alpha_y, p.rotation)),
        }
    }

    /// Sets (αx, αy, rotation) of the shown model (the edited layer's); α clamped to [1e-3, 4].
    pub fn set_alpha(&mut self, ax: f64, ay: f64, rotation: f64) {
        let (ax, ay) = (ax.clamp(1e-3, 4.0), ay.clamp(1e-3, 4.0));
        let lobe = self.lobe();
        let r = self.layer_mut();
        match lobe {
            Shown::Measured => {}
            Shown::Tabulated => {
                r.tabulated.stretch.alpha_x = ax;
                r.tabulated.stretch.alpha_y = ay;
                r.tabulated.stretch.rotation = rotation;
            }
            Shown::Ggx | Shown::Glint | Shown::Beckmann => {
                let p = if lobe == Shown::Beckmann {
                    r.beckmann.as_mut()
                } else {
                    r.ggx.as_mut()
                };
                if let Some(p) = p {
                    p.alpha_x = ax;
                    p.alpha_y = ay;
                    p.rotation = rotation;
                }
            }
        }
    }

    /// The diffuse albedo ρd of the shown model (the edited layer's; `None` for the measured
    /// data).
    pub fn diffuse(&self) -> Option<[f64; 3]> {
        let r = self.layer();
        match self.lobe() {
            Shown::Measured => None,
            Shown::Tabulated => Some(r.tabulated.diffuse),
            Shown::Ggx | Shown::Glint => r.ggx.as_ref().map(|p| p.diffuse),
            Shown::Beckmann => r.beckmann.as_ref().map(|p| p.diffuse),
        }
    }

    /// Sets ρd of the shown model, each channel clamped to [0, 1].
    pub fn set_diffuse(&mut self, albedo: [f64; 3]) {
        let albedo = albedo.map(|a| a.clamp(0.0, 1.0));
        let lobe = self.lobe();
        let r = self.layer_mut();
        match lobe {
            Shown::Measured => {}
            Shown::Tabulated => r.tabulated.diffuse = albedo,
            Shown::Ggx | Shown::Glint => r.ggx.iter_mut().for_each(|p| p.diffuse = albedo),
            Shown::Beckmann => r.beckmann.iter_mut().for_each(|p| p.diffuse = albedo),
        }
    }

    /// ρd of the shown model as fitted (what "reset" restores).
    pub fn fitted_diffuse(&self) -> Option<[f64; 3]> {
        let r = self.fitted_layer();
        match self.lobe() {
            Shown::Measured => None,
            Shown::Tabulated => Some(r.tabulated.diffuse),
            Shown::Ggx | Shown::Glint => r.ggx.as_ref().map(|p| p.diffuse),
            Shown::Beckmann => r.beckmann.as_ref().map(|p| p.diffuse),
        }
    }

    /// Whether α, rotation, ρd (of either layer) or the tint was edited.
    pub fn is_edited(&self) -> bool {
        self.record != self.base.record || self.tint != [1.0; 3]
    }

    /// Whether the fit kept a coat (which [`Self::coat`] edits).
    pub fn has_coat(&self) -> bool {
        self.base.record.coat.is_some()
    }

    /// The edited record as saved: both layers' edited α and ρd, the coat's edited η, α and
    /// weight (no coat while it is switched off), the Fresnel tables of the layer shown times
    /// the tint. (The coat's recorded errors are the fitted coat's.)
    pub fn edited_record(&self) -> FitRecord {
        let mut r = self.record.clone();
        r.coat = match (r.coat.take(), self.coat) {
            (Some(c), Some(coat)) => Some(facet_fit::model::material::CoatRecord { coat, ..c }),
            _ => None,
        };
        if self.tint != [1.0; 3] {
            match r.coat.as_mut() {
                Some(c) => tint_tables(&mut c.base, self.tint),
                None => tint_tables(&mut r, self.tint),
            }
        }
        r
    }

    /// The fitted material the renderer gets (the unedited base for "measured data").
    pub fn fitted(&self) -> Result<Arc<FittedMaterial>, String> {
        if self.shown == Shown::Measured {
            return Ok(self.base.clone());
        }
        FittedMaterial::from_record(self.edited_record()).map(Arc::new)
    }

    /// The measurement as a scene material, sampled by the unedited fit (`None` without one).
    pub fn measured_material(&self) -> Option<Material> {
        let data = self.measurement.clone()?;
        Some(Material {
            name: "measured".into(),
            measured: Some(MeasuredMaterial {
                source: self.source.clone(),
                path: None,
                data,
                fit: Some(self.base.clone()),
                unfitted: None,
            }),
            ..Material::default()
        })
    }

    /// The scene material of the sphere.
    pub fn render_material(&self) -> Result<Material, String> {
        if self.shown == Shown::Measured {
            return self
                .measured_material()
                .ok_or_else(|| format!("{} is a fit, not a measurement", self.source));
        }
        let fit = self.fitted()?;
        let glint = (self.shown == Shown::Glint).then_some(GlintParams {
            density: self.glint.density,
            gamma_deg: self.glint.gamma_deg,
            threshold: self.glint.threshold,
        });
        Ok(Material {
            name: "facet".into(),
            facet: Some(FacetMaterial {
                source: PathBuf::from(&self.source),
                fit,
                model: self.model(),
                glint,
            }),
            ..Material::default()
        })
    }

    /// What the renderer's material depends on, for change detection (cheap to compare).
    pub fn key(&self) -> MaterialKey {
        let p = |p: &Option<facet_fit::model::material::ParamRecord>| {
            p.as_ref().map(|p| {
                [
                    p.alpha_x,
                    p.alpha_y,
                    p.rotation,
                    p.diffuse[0],
                    p.diffuse[1],
                    p.diffuse[2],
                ]
            })
        };
        let layer = self.layer();
        let s = layer.tabulated.stretch;
        MaterialKey {
            base: Arc::as_ptr(&self.base) as usize,
            measurement: self.measurement.as_ref().map(|m| Arc::as_ptr(m) as usize),
            shown: self.shown,
            stretch: [s.alpha_x, s.alpha_y, s.rotation],
            tabulated_diffuse: layer.tabulated.diffuse,
            ggx: p(&layer.ggx),
            beckmann: p(&layer.beckmann),
            tint: self.tint,
            glint: (self.shown == Shown::Glint).then_some(self.glint),
            coat: self
                .coat
                .filter(|_| self.coat_shown())
                .map(|c| [c.eta, c.alpha, c.weight]),
        }
    }
}

/// Every Fresnel table of `r`'s models times `tint`, per channel.
fn tint_tables(r: &mut FitRecord, tint: [f64; 3]) {
    let times = |t: &mut facet_fit::model::fresnel::FresnelTable| {
        for v in &mut t.rgb {
            for (x, k) in v.iter_mut().zip(tint) {
                *x *= k;
            }
        }
    };
    times(&mut r.fresnel);
    if let Some(p) = r.ggx.as_mut() {
        times(&mut p.fresnel);
    }
    if let Some(p) = r.beckmann.as_mut() {
        times(&mut p.fresnel);
    }
}

/// See [`EditedMaterial::key`].
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialKey {
    /// Address of the base fit (a new fit is a new key).
    pub base: usize,
    /// Address of the measurement.
    pub measurement: Option<usize>,
    /// The model shown.
    pub shown: Shown,
    /// αx, αy, rotation of the tabulated stretch (of the layer edited: the base under a coat
    /// shown, else the single layer).
    pub stretch: [f64; 3],
    /// ρd of the tabulated model (of the layer edited).
    pub tabulated_diffuse: [f64; 3],
    /// αx, αy, rotation and ρd of GGX (of the layer edited).
    pub ggx: Option<[f64; 6]>,
    /// αx, αy, rotation and ρd of Beckmann (of the layer edited).
    pub beckmann: Option<[f64; 6]>,
    /// The Fresnel tint.
    pub tint: [f64; 3],
    /// Glint settings, when glints are shown.
    pub glint: Option<GlintEdit>,
    /// The coat's η, α and weight, when one is shown.
    pub coat: Option<[f64; 3]>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use facet_fit::model::material::CoatRecord;

    /// The demo's fit with a coat attached, as the fit attaches one.
    fn coated_fit() -> FittedMaterial {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../assets/demo/default_fit.json");
        let fit = FittedMaterial::load(&path).unwrap();
        let mut record = fit.record.clone();
        record.coat = Some(CoatRecord {
            coat: Coat::new(1.5, 0.05, 1.0),
            error: 0.0,
            ggx_error: None,
            beckmann_error: None,
            base: Box::new(fit.record.clone()),
        });
        FittedMaterial::from_record(record).unwrap()
    }

    /// The GGX α of a fitted material (the shown model).
    fn ggx_alpha(fit: &FittedMaterial) -> f64 {
        fit.record.ggx.as_ref().unwrap().alpha_x
    }

    /// With the coat shown, α, ρd and tint edits go to the base under it: the coated model
    /// rendered and saved has the edited base and the single layer is untouched. With the coat
    /// off they go to the single layer, and the base keeps its own edits for when it is back.
    #[test]
    fn edits_go_to_the_layer_shown() {
        let mut m = EditedMaterial::new(coated_fit(), "coated.json".into());
        assert!(m.coat_shown() && !m.is_edited());
        let a0 = ggx_alpha(&m.base);
        let (ax, ay, rot) = m.alpha().unwrap();
        let before = m.key();
        m.set_alpha(ax * 1.5, ay * 1.5, rot);
        m.set_diffuse([0.25, 0.5, 0.125]);
        m.tint = [1.0, 0.5, 1.0];
        assert!(m.is_edited() && m.key() != before);
        let fit = m.fitted().unwrap();
        let coated = fit.coated.as_ref().expect("the coat stays");
        assert_eq!(ggx_alpha(&coated.base), 1.5 * a0);
        assert_eq!(
            coated.base.record.ggx.as_ref().unwrap().diffuse,
            [0.25, 0.5, 0.125]
        );
        assert_eq!(ggx_alpha(&fit), a0, "the single layer is untouched");
        let (f0, f1) = (
            &m.base.record.fresnel.rgb[10],
            &coated.base.record.fresnel.rgb[10],
        );
        assert_eq!((f1[0], f1[1]), (f0[0], 0.5 * f0[1]), "the base's F tinted");
        assert_eq!(
            fit.record.fresnel.rgb[10], *f0,
            "the single layer's F untinted"
        );

        m.coat = None;
        assert!(!m.coat_shown() && m.alpha().unwrap().0 == ax);
        m.set_alpha(ax * 2.0, ay * 2.0, rot);
        let fit = m.fitted().unwrap();
        assert!(fit.coated.is_none() && ggx_alpha(&fit) == 2.0 * a0);
        m.coat = m.base.record.coat.as_ref().map(|c| c.coat);
        assert_eq!(m.alpha().unwrap().0, 1.5 * ax, "the base's edit is kept");
        assert_eq!(
            m.fitted_diffuse(),
            m.base.record.ggx.as_ref().map(|p| p.diffuse)
        );
    }

    /// The coat's own edits reach the rendered model; switched off, the single layer shows.
    #[test]
    fn coat_edits_reach_the_rendered_model() {
        let mut m = EditedMaterial::new(coated_fit(), "coated.json".into());
        let before = m.key();
        m.coat = Some(Coat::new(1.7, 0.2, 0.5));
        assert_ne!(m.key(), before);
        let fit = m.fitted().unwrap();
        assert_eq!(
            fit.coated.as_ref().unwrap().layer.coat,
            Coat::new(1.7, 0.2, 0.5)
        );
        m.coat = None;
        assert!(m.fitted().unwrap().coated.is_none());
    }
}
