//! The one interface every BRDF source and every fitted model implements.

use crate::model::merl_grid::MerlTable;
use crate::model::rgb::Rgb;
use glam::DVec3;
use std::borrow::Cow;

/// A BRDF: measured, neural, analytic or fitted.
///
/// `eval` returns f_r without the cosine, or `None` where the source has no sample (a
/// missing MERL bin, a direction below the horizon). A missing sample is never a number.
pub trait Brdf: Sync {
    /// Short name used in file names and reports.
    fn name(&self) -> &str;

    /// f_r(wi, wo) per channel; both directions in the shading frame, z up.
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb>;

    /// Whether f_r is invariant under rotation about the normal (a MERL file is).
    fn is_isotropic(&self) -> bool {
        true
    }

    /// The backscattering value f(o, o) for o at polar angle `theta`, azimuth `phi`.
    /// Sources with a faster or better-sampled slice (MERL: the θd = 0 column, averaged over
    /// φd and interpolated) override it.
    fn backscatter(&self, theta: f64, phi: f64) -> Option<Rgb> {
        let o = crate::model::geometry::spherical(theta, phi);
        self.eval(o, o)
    }

    /// The source sampled on the standard MERL grid (bin lower edges), for the Fresnel average
    /// and the error metric. A MERL file returns its own samples.
    fn merl_table(&self) -> Cow<'_, MerlTable> {
        Cow::Owned(MerlTable::sample(self))
    }
}

impl MerlTable {
    /// Samples any BRDF at the bin lower edges; below the horizon and where the source has no
    /// value the sample is marked missing (−1).
    pub fn sample<B: Brdf + ?Sized>(brdf: &B) -> Self {
        MerlTable::from_fn(|wi, wo| brdf.eval(wi, wo))
    }
}
