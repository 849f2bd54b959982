//! The objective a fit minimises, named in its record: the error metric's space
//! (the passes over the grid that compute it are in [`crate::metric`]).

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
    /// ε = [`Metric::PERCEPTUAL_FLOOR`]: relative down to the darkest values a display shows
    /// apart, as lightness (L* ∝ Y^⅓) is, so that a dark metal's colour and a dark plastic's
    /// diffuse count as much as a highlight does.
    #[default]
    Perceptual,
}

impl Metric {
    /// ε of [`Metric::Perceptual`].
    pub const PERCEPTUAL_FLOOR: f32 = 0.01;

    /// ε of the metric.
    pub fn floor(self) -> f32 {
        match self {
            Metric::Log => 1.0,
            Metric::Perceptual => std::env::var("FACET_METRIC_EPS")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(Self::PERCEPTUAL_FLOOR),
        }
    }

    /// 1/ε: the grids store ln(1 + x/ε) and the passes form ln(1 + x_model/ε).
    pub fn scale(self) -> f32 {
        1.0 / self.floor()
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
