//! The objective a fit minimises, named in its record: the error metric's space
//! (the passes over the grid that compute it are in facet-fit's `metric`).

use serde::{Deserialize, Serialize};

/// The objective a fit minimises: the mean over the MERL grid's valid samples and channels of
/// |ln(1 + x_model/ε) − ln(1 + x_data/ε)|, x = f_r cos θi. Above ε it is a relative error
/// (|ln(x_model / x_data)|), below it an absolute one (|x_model − x_data| / ε).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// ε = 1: the paper's (Dupuy et al. 2015). Where x ≪ 1, the dark half of most materials,
    /// it is an absolute error, blind to what the eye sees there.
    Log,
    /// ε 0.3 times the material's median x ([`Metric::RELATIVE_FLOOR`], at least
    /// [`Metric::MIN_FLOOR`]): relative down to well below the material's typical brightness,
    /// as lightness (L* ∝ Y^⅓) is, so that a dark metal's colour and a dark plastic's diffuse
    /// count as a highlight does. Chosen by the sphere's ΔE2000 against the measurement on the
    /// MERL-100 and the RGL-51 (`docs/log/fitting.md`, 2026-12-06).
    #[default]
    Perceptual,
}

impl Metric {
    /// [`Metric::Perceptual`]'s ε: this fraction of the material's median x over the MERL
    /// grid (its typical brightness away from the highlight), ...
    pub const RELATIVE_FLOOR: f64 = 0.3;
    /// ... and no less than this: under the reference light of `facet report` (a white
    /// Lambertian shown at 0.78, Y ≈ 4.8 x), x = 0.002 is Y ≈ 0.0096, where lightness stops
    /// being a cube root (L* is linear in Y below 0.008856).
    pub const MIN_FLOOR: f64 = 0.002;

    /// ε of the metric on a source whose median x over the grid `median_x` gives (asked only
    /// where the metric needs it).
    pub fn floor(self, median_x: impl FnOnce() -> f64) -> f32 {
        match self {
            Metric::Log => 1.0,
            Metric::Perceptual => (Self::RELATIVE_FLOOR * median_x()).max(Self::MIN_FLOOR) as f32,
        }
    }

    /// The other metric: the one a record's `other_metric` errors are in.
    pub const fn other(self) -> Metric {
        match self {
            Metric::Log => Metric::Perceptual,
            Metric::Perceptual => Metric::Log,
        }
    }

    /// `log` or `perceptual`.
    pub fn parse(s: &str) -> Option<Metric> {
        match s {
            "log" => Some(Metric::Log),
            "perceptual" => Some(Metric::Perceptual),
            _ => None,
        }
    }

    /// The name the JSON and the command line use.
    pub const fn name(self) -> &'static str {
        match self {
            Metric::Log => "log",
            Metric::Perceptual => "perceptual",
        }
    }
}
