//! The physical Fresnel curves recorded with a fit (Schlick, dielectric, conductor), their
//! qualities and which one the renderer uses. Fitting them to a table is
//! facet-fit's `fitting::fresnel_fit`'s.

use crate::model::fresnel::{Fresnel, FresnelTable};
use crate::model::rgb::Rgb;
use serde::{Deserialize, Serialize};

/// Which Fresnel the renderer uses for a model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FresnelChoice {
    /// The table F(θd) solved with the model (the default: the closest to the data).
    #[default]
    Table,
    /// The conductor fit.
    Conductor,
    /// The dielectric fit.
    Dielectric,
    /// The Schlick fit.
    Schlick,
}

impl FresnelChoice {
    /// `table`, `conductor`, `dielectric` or `schlick`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "table" => Some(Self::Table),
            "conductor" => Some(Self::Conductor),
            "dielectric" => Some(Self::Dielectric),
            "schlick" => Some(Self::Schlick),
            _ => None,
        }
    }
}

/// How close a fitted curve is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FitQuality {
    /// RMS of F_fit − F_table over the fitted bins and channels.
    pub rms: f64,
    /// Facet's error metric of the model with this Fresnel in place of its table.
    pub error: f64,
}

/// The physical Fresnel fits of one model's table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FresnelFits {
    /// F0 per channel of F = F0 + (1 − F0)(1 − cos θd)⁵.
    pub schlick_f0: Rgb,
    /// The Schlick fit's quality.
    pub schlick: FitQuality,
    /// The dielectric's relative index.
    pub dielectric_eta: f64,
    /// The dielectric fit's quality.
    pub dielectric: FitQuality,
    /// The conductor's η per channel.
    pub conductor_eta: Rgb,
    /// The conductor's k per channel.
    pub conductor_k: Rgb,
    /// The conductor fit's quality.
    pub conductor: FitQuality,
    /// The Fresnel the renderer uses.
    pub used: FresnelChoice,
}

impl FresnelFits {
    /// The Fresnel of `choice`: `table` itself or one of the fits.
    pub fn fresnel(&self, choice: FresnelChoice, table: &FresnelTable) -> Fresnel {
        match choice {
            FresnelChoice::Table => Fresnel::Table(table.clone()),
            FresnelChoice::Schlick => Fresnel::Schlick {
                f0: self.schlick_f0,
            },
            FresnelChoice::Dielectric => Fresnel::Dielectric {
                eta: self.dielectric_eta,
            },
            FresnelChoice::Conductor => Fresnel::Conductor {
                eta: self.conductor_eta,
                k: self.conductor_k,
            },
        }
    }

    /// Checks the fitted values (a JSON may have been edited); `Err` names the field.
    pub fn validate(&self, field: &str) -> Result<(), String> {
        let ok = self.schlick_f0.iter().all(|f| (0.0..=1.0).contains(f))
            && self.dielectric_eta.is_finite()
            && self.dielectric_eta > 0.0
            && self.conductor_eta.iter().all(|e| e.is_finite() && *e > 0.0)
            && self.conductor_k.iter().all(|k| k.is_finite() && *k >= 0.0);
        if ok {
            return Ok(());
        }
        Err(format!(
            "{field}: Schlick F0 must lie in [0, 1], η be positive and k non-negative (F0 {:?}, dielectric η {}, conductor η {:?}, k {:?})",
            self.schlick_f0, self.dielectric_eta, self.conductor_eta, self.conductor_k
        ))
    }
}
