//! The coat's sampling in WGSL (shaders/render/materials/coat.inc.wgsl, through coat_probe.wgsl, over a
//! GGX + Lambertian base): its histogram against the CPU's pdf of the same mixture (χ²), and
//! its pdf against the CPU's, for a sharp and a rough coat, from normal to grazing views. The
//! CPU's pdf is written here from the mixture's definition: the coat's visible normals with
//! probability p = w E_c(θo) / (w E_c(θo) + T(θo) max(a, 0.02)), else the base's sampling from the
//! refracted ωo folded into the cone that leaves the coat ([`Coat::fold_in`]): its pdf at ωi'
//! plus its pdf at the unfolded direction times [`Coat::fold_density`], times the refraction's
//! Jacobian cos θi / (η² cos θi'). No sample is lost past the critical angle.

mod common;

use facet_fit::model::coat::{Coat, CoatLayer};
use facet_fit::model::microfacet::{AnalyticNdf, NdfKind};
use facet_fit::numerics::chi2;
use facet_gpu::{buffer, gpu_for_tests, shader};
use facet_render::materials::coat::coat_block;
use glam::DVec3;
use std::f64::consts::PI;

/// The base of the probe: GGX α, the probability of its specular lobe, its albedo estimate.
const BASE: (f64, f64, f64) = (0.3, 0.6, 0.5);

/// The CPU's pdf of the coated mixture's ωi given ωo (0 below the horizon).
fn pdf(layer: &CoatLayer, wo: DVec3, wi: DVec3) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let c = layer.coat;
    let (alpha, p_spec, albedo) = BASE;
    let r = c.weight * layer.lobe_albedo(wo.z);
    let p = r / (r + layer.transmission(wo.z) * albedo.max(0.02));
    let coat_ndf = AnalyticNdf::isotropic(NdfKind::Ggx, c.alpha);
    let h = (wi + wo).normalize();
    let coat = coat_ndf.pdf_visible(wo, h) / (4.0 * wo.dot(h).abs());
    let (i, o) = (c.refract_in(wi), c.refract_in(wo));
    let base_ndf = AnalyticNdf::isotropic(NdfKind::Ggx, alpha);
    let base_pdf = |i: DVec3| {
        let hb = (i + o).normalize();
        p_spec * base_ndf.pdf_visible(o, hb) / (4.0 * o.dot(hb).abs()) + (1.0 - p_spec) * i.z / PI
    };
    let base = base_pdf(i) + base_pdf(c.unfold(i)) * c.fold_density(i);
    p * coat + (1.0 - p) * base * wi.z / (c.eta * c.eta * i.z)
}

#[test]
fn coat_sampling_matches_its_pdf() {
    let Some(gpu) = gpu_for_tests("coat_sampling_matches_its_pdf") else {
        return;
    };
    let file = "tests/render/coat_probe.wgsl";
    let pipeline = shader::compute_pipeline(&gpu.device, file, "coat_sample", &[]).unwrap();
    let wg = shader::workgroup_size(file, "coat_sample").unwrap();
    let n = 200_000u32;
    for coat in [Coat::new(1.5, 0.05, 1.0), Coat::new(1.5, 0.3, 0.5)] {
        let layer = CoatLayer::new(coat).unwrap();
        let tables = buffer::storage(&gpu.device, "coat", &coat_block(&layer));
        let (alpha, p_spec, albedo) = BASE;
        let bb = buffer::uniform(
            &gpu.device,
            "base",
            &[alpha as f32, p_spec as f32, albedo as f32, 0.0],
        );
        for theta_deg in [0.0f64, 40.0, 75.0] {
            let t = theta_deg.to_radians();
            let wo = DVec3::new(t.sin() * 0.6, t.sin() * 0.8, t.cos());
            let mut next = chi2::uniforms(theta_deg as u64 + 29);
            let inputs: Vec<[f32; 4]> = (0..n)
                .flat_map(|_| {
                    let u = [next() as f32, next() as f32, next() as f32];
                    let o = wo.as_vec3();
                    [[o.x, o.y, o.z, u[0]], [u[1], u[2], 0.0, 0.0]]
                })
                .collect();
            let ib = buffer::storage(&gpu.device, "inputs", &inputs);
            let out = common::probe(
                &gpu,
                &pipeline,
                "coat sample",
                &[
                    tables.as_entire_binding(),
                    bb.as_entire_binding(),
                    ib.as_entire_binding(),
                ],
                n,
                wg,
            );
            // The base's sampling loses what its specular lobe reflects below the surface (and
            // the coat's, below the horizon): the density of the rest integrates to what is
            // left, so the expected counts take every sample. None is lost past the critical
            // angle (the fold), which the CPU's pdf, integrated, confirms: its mass is the
            // fraction kept.
            let kept: Vec<(DVec3, f64)> = out
                .iter()
                .map(|g| {
                    let w = DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64);
                    (w, g[3] as f64)
                })
                .filter(|(w, _)| w.z > 0.0)
                .collect();
            let scale = f64::from(n) / kept.len() as f64;
            let dirs: Vec<DVec3> = kept.iter().map(|(w, _)| w.normalize()).collect();
            let r = chi2::chi2_hemisphere(&dirs, |wi| scale * pdf(&layer, wo, wi), 64);
            let off = kept
                .iter()
                .filter(|(w, p)| (p / pdf(&layer, wo, w.normalize()) - 1.0).abs() > 1e-2)
                .count();
            println!(
                "{coat:?} θo {theta_deg}°: {} of {n} kept, χ² {:.0} on {} dof, z {:.2}, ∫pdf {:.4}; {off} GPU pdfs off by > 1 %",
                kept.len(),
                r.chi2,
                r.dof,
                r.z,
                r.integral / scale
            );
            assert!(r.z < 5.0, "{coat:?} θo {theta_deg}°: χ² z = {}", r.z);
            // The fraction kept is the CPU pdf's mass over the hemisphere (binomial σ 5e-4, the
            // quadrature's error below that): the samples past the critical angle are folded in,
            // not lost (without the fold 58 % were kept at θo 0° against a mass of 95 %).
            let kept_fraction = kept.len() as f64 / f64::from(n);
            assert!(
                (r.integral / scale - kept_fraction).abs() < 3e-3,
                "{coat:?} θo {theta_deg}°: {kept_fraction} kept, the pdf's mass {}",
                r.integral / scale
            );
            assert!(
                off as f64 <= 1e-3 * f64::from(n),
                "{coat:?} θo {theta_deg}°: {off} GPU pdfs differ from the CPU's"
            );
        }
    }
}
