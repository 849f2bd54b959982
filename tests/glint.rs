//! The glint model's building blocks: TEA (CPU and WGSL) and the DPF.

mod common;

use facet_fit::microfacet::{AnalyticNdf, Ndf, NdfKind};
use facet_glint::dpf::{DpfConfig, DpfPyramid, DpfTable, cone_solid_angle, dpf, query_directions};
use facet_glint::tea::{pipeline_constants, tea, tea_unit};
use facet_gpu::{buffer, gpu_for_tests, shader};
use glam::DVec3;
use std::f64::consts::PI;

fn beckmann(alpha: f64) -> Ndf {
    Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Beckmann, alpha))
}

#[test]
fn dpf_matches_reference_values() {
    let ndf = beckmann(0.1);
    for (gamma, (to, ti, dphi), want) in [
        (1.0, (0.0, 0.0, 0.0), 7.587e-3),
        (1.0, (30.0, 30.0, 180.0), 8.755e-3),
        (6.0, (0.0, 0.0, 0.0), 0.2401),
    ] {
        let (wi, wo) = query_directions(
            f64::to_radians(to),
            f64::to_radians(ti),
            f64::to_radians(dphi),
        );
        let got = dpf(&ndf, wi, wo, f64::to_radians(gamma));
        println!("γ = {gamma}°, ({to}, {ti}, {dphi}): {got:.5e} (reference {want:.4e})");
        assert!((got / want - 1.0).abs() < 0.01, "{got} vs {want}");
    }
}

/// ∫ P(ωi, ωo, γ) dωo over the sphere = σ(γ) ∫_{ωi·m > 0} p(m) dm = σ(γ) for ωi not grazing.
#[test]
fn dpf_integrates_to_the_cone_solid_angle() {
    let ndf = beckmann(0.1);
    for (theta_i, gamma) in [(0.0, 1.0), (30.0, 10.0), (60.0, 45.0)] {
        let wi = DVec3::new(
            f64::to_radians(theta_i).sin(),
            0.0,
            f64::to_radians(theta_i).cos(),
        );
        let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
        let gamma = f64::to_radians(gamma);
        // Polar angle ψ about the mirror direction: P is concentrated within ~γ + 4α of it.
        let (t, b) = {
            let a = if mirror.x.abs() < 0.9 {
                DVec3::X
            } else {
                DVec3::Y
            };
            let t = a.cross(mirror).normalize();
            (t, mirror.cross(t))
        };
        let mut total = 0.0;
        let split = (gamma + 0.8).min(PI);
        for (lo, hi, n) in [(0.0, split, 64), (split, PI, 24)] {
            for (x, w) in facet_fit::quadrature::gauss_legendre(n) {
                let psi = lo + x * (hi - lo);
                let nchi = 96;
                for k in 0..nchi {
                    let chi = (k as f64 + 0.5) / nchi as f64 * 2.0 * PI;
                    let wo = psi.cos() * mirror + psi.sin() * (chi.cos() * t + chi.sin() * b);
                    total += w * (hi - lo) * psi.sin() * 2.0 * PI / nchi as f64
                        * dpf(&ndf, wi, wo, gamma);
                }
            }
        }
        let want = cone_solid_angle(gamma);
        println!(
            "θi = {theta_i}°, γ = {:.0}°: ∫P = {total:.5e}, σ(γ) = {want:.5e}",
            gamma.to_degrees()
        );
        assert!((total / want - 1.0).abs() < 0.02, "{total} vs {want}");
    }
}

#[test]
fn tables_hold_cell_centres_and_the_pyramid_interpolates_gamma() {
    let ndf = beckmann(0.2);
    let cfg = DpfConfig::preview();
    let pyramid = DpfPyramid::build(&ndf, cfg);
    let table = &pyramid.levels[2]; // γ = 5°
    // At a cell centre the lookup is the integral there (no half-cell shift).
    for (o, i, p) in [(0, 0, 0), (3, 5, 20), (7, 7, 23), (11, 2, 5)] {
        let (to, ti, dp) = DpfTable::cell_centre(cfg, o, i, p);
        let (wi, wo) = query_directions(to, ti, dp);
        let direct = dpf(&ndf, wi, wo, table.gamma);
        let looked = table.lookup(to, ti, dp);
        assert!(
            (looked - direct).abs() <= 1e-6 * direct.max(1e-6),
            "cell ({o},{i},{p}): {looked} vs {direct}"
        );
    }
    // Between levels: γ = 7° from the 5° and 10° levels, against the direct integral.
    let mut worst = 0.0f64;
    for (o, i, p) in [(1, 1, 23), (4, 4, 23), (6, 3, 20)] {
        let (to, ti, dp) = DpfTable::cell_centre(cfg, o, i, p);
        let (wi, wo) = query_directions(to, ti, dp);
        let direct = dpf(&ndf, wi, wo, 7f64.to_radians());
        let interp = pyramid.lookup(to, ti, dp, 7f64.to_radians());
        worst = worst.max((interp / direct - 1.0).abs());
    }
    println!("γ = 7° between levels: worst relative error {worst:.4}");
    assert!(worst < 0.02, "{worst}");
}

#[test]
fn tea_in_wgsl_matches_rust() {
    let Some(gpu) = gpu_for_tests("tea_in_wgsl_matches_rust") else {
        return;
    };
    let keys: Vec<[u32; 2]> = (0..10_000u32)
        .map(|k| [k.wrapping_mul(2_654_435_761), k ^ 0x5bd1_e995])
        .chain([[0, 0], [1, 2], [12345, 678]])
        .collect();
    let pipeline = shader::compute_pipeline(
        &gpu.device,
        "glint/tea_check.wgsl",
        "tea_check",
        &pipeline_constants(),
    )
    .unwrap();
    let kb = buffer::storage(&gpu.device, "keys", &keys);
    let hb = buffer::storage_zeroed(&gpu.device, "hashes", (keys.len() * 16) as u64);
    let bg = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: kb.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: hb.as_entire_binding(),
            },
        ],
    });
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups((keys.len() as u32).div_ceil(64), 1, 1);
    }
    gpu.queue.submit([enc.finish()]);
    let out: Vec<[u32; 4]> = buffer::read(&gpu.device, &gpu.queue, &hb, keys.len()).unwrap();
    for (k, h) in keys.iter().zip(&out) {
        let want = tea(k[0], k[1]);
        assert_eq!(((h[1] as u64) << 32) | h[0] as u64, want, "key {k:?}");
        assert_eq!(f32::from_bits(h[2]), tea_unit(k[0], k[1]));
    }
    let n = out.len();
    assert_eq!(
        ((out[n - 1][1] as u64) << 32) | out[n - 1][0] as u64,
        0x6955_6b69_8924_22ac
    );
}
