//! An isotropic microfacet model reduced to tables over the MERL grid's bins: D per θh bin,
//! Λ cos θ per cos θ, F per θd bin and ρd/π. The passes over the grid read only these.

use crate::metric::lambda_table::{LAMBDA_TABLE, lambda_cos_table};
use crate::model::geometry::azimuth_between;
use crate::model::merl_grid::{THETA_D_RES, THETA_H_RES, bin_angles};
use crate::model::microfacet::{MicrofacetBrdf, Ndf, correlation, g2};
use crate::model::rgb::Rgb;
use crate::numerics::interp::fill_missing;
use glam::DVec3;
use std::f64::consts::PI;

pub use crate::model::merl_grid::MAX_X;

/// An isotropic microfacet model reduced to tables over the grid's bins.
#[derive(Clone)]
pub struct IsoTables {
    /// D at each θh bin, in f32 as the passes use it.
    pub(crate) d32: [f32; THETA_H_RES],
    /// Λ(θ) cos θ as a function of μ = cos θ on [0, 1], uniform in μ: finite at μ = 0 where Λ
    /// diverges (GGX: α/2), smooth in μ (GGX: (sqrt(μ² + α²(1 − μ²)) − μ) / 2), so it
    /// interpolates well, and a bin's table coordinate is its cosine times a constant: no acos.
    pub(crate) lambda_cos: Box<[f32; LAMBDA_TABLE]>,
    /// F at each θd bin.
    pub(crate) fresnel: [Rgb; THETA_D_RES],
    /// ρd/π.
    pub(crate) diffuse: Rgb,
}

impl IsoTables {
    /// Tables of an isotropic model; `None` for an anisotropic one (use the direct path).
    pub fn new(model: &MicrofacetBrdf) -> Option<Self> {
        if !model.ndf.is_isotropic()
            || matches!(model.ndf, Ndf::Analytic(a) if a.rotation != 0.0 && a.alpha_x != a.alpha_y)
        {
            return None;
        }
        let d32 = std::array::from_fn(|i| {
            model.ndf.d(crate::model::geometry::spherical(
                bin_angles(i, 0, 0).theta_h,
                0.0,
            )) as f32
        });
        let lambda_cos = lambda_cos_table(&model.ndf);
        Some(IsoTables {
            d32,
            lambda_cos,
            fresnel: fresnel_bins(model),
            diffuse: model.diffuse.map(|k| k / PI),
        })
    }

    /// D per θh bin.
    #[cfg(feature = "gpu")]
    pub(crate) fn d_table(&self) -> &[f32] {
        &self.d32
    }

    /// Λ cos θ, uniform in cos θ over [0, 1].
    #[cfg(feature = "gpu")]
    pub(crate) fn lambda_cos_table(&self) -> &[f32] {
        &self.lambda_cos[..]
    }

    /// These tables with the Fresnel and diffuse albedo of `model`, whose D and Λ are these
    /// tables' (the same F and ρd/π as [`IsoTables::new`] of `model`, without its D and Λ).
    pub fn with_model_fresnel(&self, model: &MicrofacetBrdf) -> Self {
        IsoTables {
            d32: self.d32,
            lambda_cos: self.lambda_cos.clone(),
            fresnel: fresnel_bins(model),
            diffuse: model.diffuse.map(|k| k / PI),
        }
    }

    /// The same model with another Fresnel table.
    pub fn set_fresnel(&mut self, f: &[Rgb]) {
        self.fresnel.copy_from_slice(&f[..THETA_D_RES]);
    }

    /// D G2 / (4 cos θo) at a sample of θh bin `i` given by its directions (the list path).
    pub(crate) fn x_ideal_at(&self, wi: DVec3, wo: DVec3, i: usize) -> f64 {
        let lambda = |mu: f64| {
            let x = (mu * (LAMBDA_TABLE - 1) as f64).clamp(0.0, (LAMBDA_TABLE - 1) as f64);
            let k = (x as usize).min(LAMBDA_TABLE - 2);
            let (a, b) = (self.lambda_cos[k] as f64, self.lambda_cos[k + 1] as f64);
            (a + (x - k as f64) * (b - a)) / mu
        };
        let g = g2(
            lambda(wi.z),
            lambda(wo.z),
            correlation(azimuth_between(wi, wo)),
        );
        self.d32[i] as f64 * g / (4.0 * wo.z)
    }
}

/// F of `model` at each θd bin.
fn fresnel_bins(model: &MicrofacetBrdf) -> [Rgb; THETA_D_RES] {
    std::array::from_fn(|j| model.fresnel.eval(bin_angles(0, j, 0).theta_d.cos()))
}

/// F per θd bin from the sums (Σ x_data per channel, Σ x_ideal); empty bins interpolated.
pub(crate) fn fresnel_from_sums(acc: &[([f64; 3], f64)]) -> Vec<Rgb> {
    let per_bin: Vec<Option<Rgb>> = acc
        .iter()
        .map(|(x, w)| (*w > 0.0).then(|| x.map(|v| v / w)))
        .collect();
    fill_missing(&per_bin).unwrap_or_else(|| vec![[1.0; 3]; THETA_D_RES])
}
