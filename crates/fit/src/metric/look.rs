//! The look: how a model differs from its data on a sphere under one point light, in
//! CIEDE2000, as `facet report` shows it — the figure by which the fit decides whether a coat
//! helps (the grid's metric weighs each (ωi, ωo) bin alike; the eye weighs what a sphere shows).
//!
//! The scene is the report's: the unit sphere seen from (0, 0, 3) with a 45° vertical field of
//! view, a point light at (−1.6, 1.8, 3) of intensity 40; a pixel shows L = f cos θi I / r²
//! as 1 − e^−L, read as linear sRGB. Rendered here directly (no path tracer): one sample at
//! each pixel's centre, the pixels whose ray passes within 0.98 of the centre.

use crate::model::brdf::Brdf;
use crate::model::merl_grid::MerlTable;
use crate::model::rgb::Rgb;
use glam::DVec3;
use palette::color_difference::Ciede2000;
use palette::{FromColor, Lab, LinSrgb};

/// A sphere under a point light, seen by a pinhole camera on +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereScene {
    /// The camera's distance from the unit sphere's centre.
    pub camera_z: f64,
    /// The vertical field of view, degrees.
    pub yfov_deg: f64,
    /// The point light's position.
    pub light: DVec3,
    /// Its radiant intensity.
    pub intensity: f64,
    /// The image's side, pixels.
    pub side: usize,
}

impl SphereScene {
    /// The report's point-light scene (`facet report`) at 64² pixels.
    pub const REPORT: SphereScene = SphereScene {
        camera_z: 3.0,
        yfov_deg: 45.0,
        light: DVec3::new(-1.6, 1.8, 3.0),
        intensity: 40.0,
        side: 64,
    };

    /// Mean CIEDE2000 over the sphere's pixels of `model` against `data` (each f(ωi, ωo) in
    /// the sphere's local frame, `None` read as black).
    pub fn delta_e(&self, data: &dyn Brdf, model: &dyn Brdf) -> f64 {
        self.mean_delta_e(|wi, wo| data.eval(wi, wo), model)
    }

    /// [`SphereScene::delta_e`] against a MERL-grid table (interpolated, as a MERL file is).
    pub fn delta_e_to_table(&self, table: &MerlTable, model: &dyn Brdf) -> f64 {
        self.mean_delta_e(|wi, wo| table.lookup_interpolated(wi, wo), model)
    }

    fn mean_delta_e(&self, data: impl Fn(DVec3, DVec3) -> Option<Rgb>, model: &dyn Brdf) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for (wi, wo, irradiance) in self.pixels() {
            let e = wi.z * irradiance;
            let (d, m) = (shown(data(wi, wo), e), shown(model.eval(wi, wo), e));
            sum += f64::from(d.difference(m));
            n += 1;
        }
        sum / n.max(1) as f64
    }

    /// Each pixel on the sphere: (ωi, ωo) in the local frame, and the irradiance I / r² at
    /// normal incidence.
    pub fn pixels(&self) -> impl Iterator<Item = (DVec3, DVec3, f64)> + '_ {
        let tan = (self.yfov_deg.to_radians() / 2.0).tan();
        let camera = DVec3::new(0.0, 0.0, self.camera_z);
        let ndc = move |p: usize| (2.0 * (p as f64 + 0.5) / self.side as f64 - 1.0) * tan;
        let pixels = (0..self.side).flat_map(move |py| (0..self.side).map(move |px| (px, py)));
        pixels.filter_map(move |(px, py)| {
            let dir = DVec3::new(ndc(px), -ndc(py), -1.0).normalize();
            // The ray's closest approach to the centre: within 0.98 of the radius.
            let t_mid = -camera.dot(dir);
            let closest = (camera + t_mid * dir).length();
            if closest > 0.98 {
                return None;
            }
            let p = camera + (t_mid - (1.0 - closest * closest).sqrt()) * dir;
            let n = p.normalize();
            let tangent = DVec3::Y.cross(n).normalize();
            let bitangent = n.cross(tangent);
            let local = |w: DVec3| DVec3::new(w.dot(tangent), w.dot(bitangent), w.dot(n));
            let to_light = self.light - p;
            let (wi, wo) = (local(to_light.normalize()), local(-dir));
            Some((wi, wo, self.intensity / to_light.length_squared()))
        })
    }
}

/// A pixel's colour: L = f E (E = I cos θi / r², 0 below the horizon) shown as 1 − e^−L.
fn shown(f: Option<Rgb>, e: f64) -> Lab {
    let f = f.filter(|_| e > 0.0).unwrap_or([0.0; 3]);
    let d = f.map(|f| (1.0 - (-(f * e).max(0.0)).exp()) as f32);
    Lab::from_color(LinSrgb::new(d[0], d[1], d[2]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::brdf::Brdf;

    /// A Lambertian of albedo ρ (f = ρ/π).
    struct Lambert(f64);

    impl Brdf for Lambert {
        fn name(&self) -> &str {
            "lambert"
        }
        fn eval(&self, _: DVec3, _: DVec3) -> Option<Rgb> {
            Some([self.0 / std::f64::consts::PI; 3])
        }
    }

    /// A model against itself differs by 0; two greys differ by what CIEDE2000 says of two
    /// neutral colours, |ΔL*| (ΔC = ΔH = 0, S_L = 1 at L* = 50): the mean over the sphere of
    /// their L* difference, computed here independently per pixel from the CIE L* formula.
    #[test]
    fn two_greys_differ_by_their_lightness() {
        let scene = SphereScene::REPORT;
        assert_eq!(scene.delta_e(&Lambert(0.5), &Lambert(0.5)), 0.0);
        let lightness = |y: f64| match y > (6.0f64 / 29.0).powi(3) {
            true => 116.0 * y.cbrt() - 16.0,
            false => y * (29.0f64 / 3.0).powi(3),
        };
        let (mut want, mut n) = (0.0, 0);
        for (wi, _, e) in scene.pixels() {
            let y = |rho: f64| 1.0 - (-(rho / std::f64::consts::PI * wi.z.max(0.0) * e)).exp();
            let (a, b) = (lightness(y(0.5)), lightness(y(0.3)));
            // CIEDE2000's S_L = 1 + 0.015 (L̄ − 50)² / √(20 + (L̄ − 50)²)
            let l_bar = (a + b) / 2.0 - 50.0;
            want += (a - b).abs() / (1.0 + 0.015 * l_bar * l_bar / (20.0 + l_bar * l_bar).sqrt());
            n += 1;
        }
        let got = scene.delta_e(&Lambert(0.5), &Lambert(0.3));
        want /= n as f64;
        // f32 Lab: relative 1e-4.
        assert!((got - want).abs() < 1e-4 * want, "{got} against {want}");
        // The rays within 0.98 of the centre: a cone of half-angle asin(0.98 / 3), a disc of
        // radius 32 tan(that) / tan(22.5°) pixels; its area to 1 % (the pixels on its edge).
        let r = 32.0 * (0.98f64 / 3.0).asin().tan() / 22.5f64.to_radians().tan();
        let disc = std::f64::consts::PI * r * r;
        assert!(
            (n as f64 - disc).abs() < 0.01 * disc,
            "{n} pixels, a disc of {disc}"
        );
    }
}
