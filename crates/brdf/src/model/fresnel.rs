//! Fresnel reflectance: Schlick, exact conductor and dielectric, and tables F(θd) extracted
//! from measurements.

use crate::model::rgb::Rgb;
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

/// Reflectance as a function of cos θd = wi·h.
#[derive(Clone, Debug, PartialEq)]
pub enum Fresnel {
    /// F = F0 + (1 − F0)(1 − cos θd)^5 per channel.
    Schlick {
        /// F at normal incidence.
        f0: Rgb,
    },
    /// Exact unpolarised Fresnel of a conductor of complex index η + i k per channel.
    Conductor {
        /// Real part η of the index.
        eta: Rgb,
        /// Imaginary part k (extinction) of the index.
        k: Rgb,
    },
    /// Exact unpolarised Fresnel of a dielectric of relative index η (same for all channels).
    Dielectric {
        /// The relative index η.
        eta: f64,
    },
    /// A table over θd, as extracted from data.
    Table(FresnelTable),
}

impl Fresnel {
    /// Gold at the Rec.709 primaries (η, k), a common conductor preset.
    pub const GOLD: Fresnel = Fresnel::Conductor {
        eta: [0.143, 0.374, 1.442],
        k: [3.983, 2.385, 1.603],
    };

    /// F at cos θd, per channel.
    pub fn eval(&self, cos_d: f64) -> Rgb {
        let c = cos_d.clamp(0.0, 1.0);
        match self {
            Fresnel::Schlick { f0 } => f0.map(|f| f + (1.0 - f) * (1.0 - c).powi(5)),
            Fresnel::Conductor { eta, k } => std::array::from_fn(|i| conductor(c, eta[i], k[i])),
            Fresnel::Dielectric { eta } => [dielectric(c, *eta); 3],
            Fresnel::Table(t) => t.eval(c.acos()),
        }
    }
}

/// Unpolarised reflectance of a conductor: the mean of |r_s|² and |r_p|² with complex
/// cos θt = sqrt(1 − sin²θi / (η + ik)²) (pbrt-v4 `FrComplex`).
pub fn conductor(cos_i: f64, eta: f64, k: f64) -> f64 {
    type C = (f64, f64);
    let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let sqrt = |a: C| {
        let r = (a.0 * a.0 + a.1 * a.1).sqrt();
        let re = ((r + a.0) / 2.0).max(0.0).sqrt();
        let im = ((r - a.0) / 2.0).max(0.0).sqrt().copysign(a.1);
        (re, im)
    };
    let n = (eta, k);
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = div((sin2_i, 0.0), mul(n, n));
    let cos_t = sqrt((1.0 - sin2_t.0, -sin2_t.1));
    let ci = (cos_i, 0.0);
    let nci = mul(n, ci);
    let nct = mul(n, cos_t);
    let r_parl = div(
        (nci.0 - cos_t.0, nci.1 - cos_t.1),
        (nci.0 + cos_t.0, nci.1 + cos_t.1),
    );
    let r_perp = div((ci.0 - nct.0, -nct.1), (ci.0 + nct.0, nct.1));
    let norm = |a: C| a.0 * a.0 + a.1 * a.1;
    (norm(r_parl) + norm(r_perp)) / 2.0
}

/// Unpolarised reflectance of a dielectric interface seen from outside (relative index η).
pub fn dielectric(cos_i: f64, eta: f64) -> f64 {
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (r_parl * r_parl + r_perp * r_perp) / 2.0
}

/// The largest F a table may hold: the paper's averaged single lobe reaches 57 on the MERL
/// proxies (a diffuse fit keeps F in [0, 1]); far larger values are no fit's and make f overflow.
pub const MAX_FRESNEL: f64 = 1e6;

/// F(θd) per channel at θd_j = j · step, j = 0..n, linearly interpolated, clamped at the ends.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FresnelTable {
    /// θd of each entry, radians, increasing and evenly spaced from 0.
    pub theta_d: Vec<f64>,
    /// F per channel at each `theta_d`.
    pub rgb: Vec<Rgb>,
}

impl FresnelTable {
    /// Table on the MERL θd bins (lower edges, 1° apart).
    pub fn on_merl_bins(rgb: Vec<Rgb>) -> Self {
        let n = rgb.len();
        let theta_d = (0..n).map(|j| j as f64 / n as f64 * FRAC_PI_2).collect();
        FresnelTable { theta_d, rgb }
    }

    /// F at θd (radians), interpolated linearly and clamped to the table's ends.
    pub fn eval(&self, theta_d: f64) -> Rgb {
        let n = self.rgb.len();
        if n == 1 {
            return self.rgb[0];
        }
        let step = self.theta_d[1] - self.theta_d[0];
        let x = (theta_d / step).clamp(0.0, (n - 1) as f64);
        let j = (x as usize).min(n - 2);
        let t = x - j as f64;
        std::array::from_fn(|c| self.rgb[j][c] + t * (self.rgb[j + 1][c] - self.rgb[j][c]))
    }

    /// Checks the table read from a file: evenly spaced angles, finite non-negative values.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.theta_d.len();
        if n == 0 || n != self.rgb.len() {
            return Err(format!(
                "fresnel table has {} angles and {} values",
                n,
                self.rgb.len()
            ));
        }
        if self.theta_d[0] != 0.0 {
            return Err("fresnel theta_d must start at 0".into());
        }
        if n > 1 {
            let step = self.theta_d[1];
            if !(step > 0.0)
                || self
                    .theta_d
                    .iter()
                    .enumerate()
                    .any(|(j, &t)| (t - j as f64 * step).abs() > 1e-9)
            {
                return Err("fresnel theta_d must be evenly spaced and increasing".into());
            }
        }
        if let Some(v) = self
            .rgb
            .iter()
            .flatten()
            .find(|v| !(0.0..=MAX_FRESNEL).contains(*v))
        {
            return Err(format!(
                "fresnel rgb value {v} is not in [0, {MAX_FRESNEL}] (the paper's single lobe reaches 57 on the MERL proxies; larger is no fit's, and overflows f)"
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_matches_closed_forms() {
        // F(0) = ((η−1)² + k²) / ((η+1)² + k²) for a conductor; ((η−1)/(η+1))² for a dielectric.
        let (eta, k) = (0.2, 3.0);
        let f0 = ((eta - 1.0f64).powi(2) + k * k) / ((eta + 1.0f64).powi(2) + k * k);
        assert!((conductor(1.0, eta, k) - f0).abs() < 1e-12);
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < 1e-12);
        // A conductor with k = 0 is a dielectric.
        for c in [0.1, 0.5, 0.9] {
            assert!((conductor(c, 1.5, 0.0) - dielectric(c, 1.5)).abs() < 1e-12);
        }
        assert!((conductor(0.0, eta, k) - 1.0).abs() < 1e-12);
    }
}
