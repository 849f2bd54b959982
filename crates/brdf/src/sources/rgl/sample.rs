//! Importance sampling of an RGL `.bsdf` as Mitsuba 3's `measured` plugin does it
//! (`sample()` of `src/bsdfs/measured.cpp`): the luminance warp takes the uniform sample to the
//! sample space, the VNDF warp takes that to u(m), and ωo is ωi reflected about m. The density
//! is the product of the two warps' densities over the Jacobian from u(m) to ωo, the same
//! expression [`RglBsdf::pdf`] evaluates, so that `sample` and `pdf` agree.

use super::{RglBsdf, elevation, fold_like, u2phi, u2theta};
use glam::DVec3;
use std::f64::consts::PI;

impl RglBsdf {
    /// Samples ωo for the parameter direction `wi` (Mitsuba's `si.wi`, the camera side) from
    /// the uniform `u`: ωo and its solid-angle density, equal to [`RglBsdf::pdf`]`(wi, ωo)`.
    /// `None` when `wi` or the sampled ωo is at or below the horizon.
    ///
    /// The steps of measured.cpp: s = luminance.sample((u₁, u₀) | φi, θi) (the plugin swaps
    /// the components), u_m = vndf.sample(s | φi, θi), θm = u2theta, φm = u2phi (+ φi when
    /// isotropic), ωo = 2 ⟨ωi, m⟩ m − ωi; an anisotropic file folded by symmetry samples in
    /// the folded frame and unfolds ωo with ωi's signs.
    pub fn sample(&self, wi: DVec3, u: [f64; 2]) -> Option<(DVec3, f64)> {
        if wi.z <= 0.0 {
            return None;
        }
        let wf = fold_like(wi, wi, self.reduction);
        let (theta_i, phi_i) = (elevation(wf), wf.y.atan2(wf.x));
        let params = [phi_i, theta_i];
        let (s, lum_pdf) = self.luminance.sample([u[1], u[0]], &params);
        let (u_m, vndf_pdf) = self.vndf.sample(s, &params);
        let theta_m = u2theta(u_m[0]);
        let phi_m = u2phi(u_m[1]) + if self.isotropic { phi_i } else { 0.0 };
        let (sin_t, cos_t) = theta_m.sin_cos();
        let (sin_p, cos_p) = phi_m.sin_cos();
        let m = DVec3::new(cos_p * sin_t, sin_p * sin_t, cos_t);
        // dω/du(m) = 2π² u sin θm, times 4 ⟨ωi, m⟩ from m to the reflected ωo.
        let jacobian = (2.0 * PI * PI * u_m[0] * sin_t).max(1e-6) * 4.0 * wf.dot(m);
        let wo = fold_like(2.0 * wf.dot(m) * m - wf, wi, self.reduction);
        (wo.z > 0.0).then_some((wo, vndf_pdf * lum_pdf / jacobian))
    }
}
