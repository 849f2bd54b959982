//! Statistics of flake counting against theory and against an explicit-flake reference.

use facet_fit::model::fresnel::Fresnel;
use facet_fit::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
use facet_glint::dpf::dpf;
use facet_glint::flakes::{Flake, FlakeField, Footprint, direction_cell};
use facet_glint::glint_brdf::{GlintConfig, glint_count, glint_eval};
use facet_glint::lit::LitKey;
use facet_glint::tea::tea_unit;
use glam::{DVec2, DVec3};
use std::f64::consts::PI;

const ALPHA: f64 = 0.2;

fn ndf() -> Ndf {
    Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Beckmann, ALPHA))
}

fn dir(theta_deg: f64, phi_deg: f64) -> DVec3 {
    facet_fit::model::geometry::spherical(theta_deg.to_radians(), phi_deg.to_radians())
}

/// Deterministic footprints: random centre, random orientation, semi-axes in [r/2, 3r/2].
fn footprint(k: u32, r: f64) -> Footprint {
    let u = |j: u32| tea_unit(k, 1000 + j) as f64;
    let t = 2.0 * PI * u(0);
    let (c, s) = (t.cos(), t.sin());
    Footprint {
        center: DVec2::new(u(1), u(2)),
        a: DVec2::new(c, s) * r * (0.5 + u(3)),
        b: DVec2::new(-s, c) * r * (0.5 + u(4)),
    }
}

/// The reference: each flake gets an explicit normal m from p(m) = D(m) cos θm (Beckmann:
/// tan²θ = −α² ln(1 − u), φ = 2πv), keyed on the flake, and is lit when ωi reflected about m
/// falls within γ of ωo.
fn explicit_lit(f: &Flake, wi: DVec3, wo: DVec3, gamma: f64) -> bool {
    let (u, v) = (
        tea_unit(f.id as u32, 77) as f64,
        tea_unit((f.id >> 32) as u32, 78) as f64,
    );
    let tan2 = -ALPHA * ALPHA * (1.0 - u).ln();
    let theta = tan2.sqrt().atan();
    let m = facet_fit::model::geometry::spherical(theta, 2.0 * PI * v);
    let r = 2.0 * wi.dot(m) * m - wi;
    wi.dot(m) > 0.0 && r.dot(wo) >= gamma.cos()
}

#[test]
fn counts_are_poisson_with_mean_n_a_p_like_explicit_flakes() {
    let field = FlakeField {
        density: 2.0e6,
        seed: 3,
    };
    let cfg = GlintConfig {
        gamma: 5f64.to_radians(),
        threshold: 16.0,
        filtered: false,
        blend: false,
    };
    let (wi, wo) = (dir(20.0, 0.0), dir(25.0, 170.0));
    let p = dpf(&ndf(), wi, wo, cfg.gamma);
    let cell = direction_cell(wi, wo, cfg.gamma);
    let (mut mean_sum, mut dev_model, mut dev_ref, mut sum_model, mut sum_ref) =
        (0.0, 0.0, 0.0, 0.0, 0.0);
    let n = 10_000;
    for k in 0..n {
        let fp = footprint(k, 0.006);
        let mu = field.density * fp.area() * p;
        let flakes = field.flakes_in(&fp);
        let model = field.lit_flakes_in(&fp, p, LitKey::of_cell(cell)).len() as f64;
        let reference = flakes
            .iter()
            .filter(|f| explicit_lit(f, wi, wo, cfg.gamma))
            .count() as f64;
        assert_eq!(model, glint_count(&field, &fp, wi, wo, p, &cfg));
        mean_sum += mu;
        sum_model += model;
        sum_ref += reference;
        dev_model += (model - mu).powi(2);
        dev_ref += (reference - mu).powi(2);
    }
    let sigma = mean_sum.sqrt(); // Poisson: the variance of the total is its mean
    println!(
        "P = {p:.4}; Σ N a P = {mean_sum:.0}; model Σ = {sum_model:.0}; explicit Σ = {sum_ref:.0}; 3σ = {:.0}",
        3.0 * sigma
    );
    println!(
        "variance / mean: model {:.3}, explicit {:.3}",
        dev_model / mean_sum,
        dev_ref / mean_sum
    );
    assert!((sum_model - mean_sum).abs() < 3.0 * sigma && (sum_ref - mean_sum).abs() < 3.0 * sigma);
    assert!((dev_model / mean_sum - 1.0).abs() < 0.2 && (dev_ref / mean_sum - 1.0).abs() < 0.2);
}

#[test]
fn nested_footprints_give_nested_counts() {
    let field = FlakeField {
        density: 1.0e6,
        seed: 9,
    };
    let cfg = GlintConfig {
        gamma: 2f64.to_radians(),
        threshold: 16.0,
        filtered: false,
        blend: true,
    };
    let mut violations = 0;
    for k in 0..10_000u32 {
        let wi = dir(10.0 + 60.0 * tea_unit(k, 1) as f64, 0.0);
        let wo = dir(
            10.0 + 60.0 * tea_unit(k, 2) as f64,
            360.0 * tea_unit(k, 3) as f64,
        );
        let p = 0.3 * tea_unit(k, 4) as f64;
        let small = footprint(k, 0.003);
        let big = small.scaled(1.0 + tea_unit(k, 5) as f64);
        if glint_count(&field, &small, wi, wo, p, &cfg) > glint_count(&field, &big, wi, wo, p, &cfg)
        {
            violations += 1;
        }
    }
    assert_eq!(violations, 0);
}

#[test]
fn filtered_value_is_the_unfiltered_mean() {
    let field = FlakeField {
        density: 4.0e6,
        seed: 5,
    };
    let (wi, wo) = (dir(35.0, 0.0), dir(30.0, 180.0));
    let gamma = 10f64.to_radians();
    let p = dpf(&ndf(), wi, wo, gamma);
    let on = GlintConfig {
        gamma,
        threshold: 16.0,
        filtered: true,
        blend: true,
    };
    let off = GlintConfig {
        filtered: false,
        ..on
    };
    let (mut filtered, mut counted) = (0.0, 0.0);
    for k in 0..2000 {
        let fp = footprint(k, 0.004);
        filtered += glint_count(&field, &fp, wi, wo, p, &on);
        counted += glint_count(&field, &fp, wi, wo, p, &off);
    }
    println!(
        "expected count per footprint {:.1}; filtered Σ {filtered:.0}, counted Σ {counted:.0}",
        filtered / 2000.0
    );
    assert!(
        filtered / 2000.0 > on.threshold,
        "the filter must have taken over"
    );
    assert!((counted - filtered).abs() < 3.0 * filtered.sqrt());
}

#[test]
fn large_footprints_converge_to_the_smooth_brdf() {
    // Without and with a diffuse lobe (which lies under the flakes in both models).
    for diffuse in [[0.0; 3], [0.3, 0.1, 0.05]] {
        large_footprint_limit(MicrofacetBrdf {
            name: "beckmann".into(),
            ndf: ndf(),
            fresnel: Fresnel::Schlick {
                f0: [0.04, 0.5, 0.9],
            },
            diffuse,
        });
    }
}

fn large_footprint_limit(model: MicrofacetBrdf) {
    let field = FlakeField {
        density: 1.0e9,
        seed: 1,
    };
    let cfg = GlintConfig::standard();
    let fp = Footprint {
        center: DVec2::splat(0.5),
        a: DVec2::new(0.05, 0.0),
        b: DVec2::new(0.0, 0.04),
    };
    for (wi, wo) in [
        (dir(0.0, 0.0), dir(10.0, 90.0)),
        (dir(30.0, 0.0), dir(30.0, 180.0)),
        (dir(60.0, 0.0), dir(45.0, 160.0)),
    ] {
        let p = dpf(&model.ndf, wi, wo, cfg.gamma);
        let glint = glint_eval(&model, &field, &fp, wi, wo, p, &cfg);
        let smooth = facet_fit::model::brdf::Brdf::eval(&model, wi, wo).unwrap();
        println!("glint {glint:.5?} smooth {smooth:.5?}");
        assert!((0..3).all(|c| (glint[c] / smooth[c] - 1.0).abs() < 0.01));
    }
}

#[test]
fn moving_the_light_changes_which_flakes_are_lit() {
    let field = FlakeField {
        density: 4.0e6,
        seed: 11,
    };
    let gamma = 2f64.to_radians();
    let p = 0.05; // a fixed threshold: what changes is which flakes draw λ < P
    let (mut kept_small, mut lit_small, mut overlap_big, mut chance_big) = (0.0, 0.0, 0.0, 0.0);
    for k in 0..300u32 {
        let fp = footprint(k, 0.004);
        let flakes = field.flakes_in(&fp);
        let wo = dir(30.0, 180.0);
        let wi = dir(
            20.0 + 20.0 * tea_unit(k, 1) as f64,
            360.0 * tea_unit(k, 2) as f64 * 0.1,
        );
        let lit = |w: DVec3| -> Vec<u64> {
            let cell = direction_cell(w, wo, gamma);
            field
                .lit_flakes_in(&fp, p, LitKey::of_cell(cell))
                .iter()
                .map(|f| f.id)
                .collect()
        };
        // Rotate the light about the view direction's plane: small (γ/5) and large (2.5γ).
        let turn = |deg: f64| {
            let axis = wi.cross(DVec3::Z).normalize();
            glam::DQuat::from_axis_angle(axis, deg.to_radians()) * wi
        };
        let a = lit(wi);
        let small = lit(turn(gamma.to_degrees() / 5.0));
        let big = lit(turn(2.5 * gamma.to_degrees()));
        kept_small += a.iter().filter(|id| small.contains(id)).count() as f64;
        lit_small += a.len() as f64;
        overlap_big += a.iter().filter(|id| big.contains(id)).count() as f64;
        chance_big += a.len() as f64 * big.len() as f64 / flakes.len().max(1) as f64;
    }
    println!(
        "small move keeps {:.2} of the lit flakes; large move overlap {overlap_big:.0} against {chance_big:.0} by chance",
        kept_small / lit_small
    );
    assert!(kept_small / lit_small > 0.6);
    assert!(overlap_big < chance_big + 3.0 * chance_big.sqrt());
}

/// Sampling from the smooth lobe is unbiased for the glint BRDF: the Monte Carlo estimate of
/// the directional albedo ∫ f cos θi dωi (filtered, huge density) equals the quadrature.
#[test]
fn sampling_estimates_the_albedo() {
    use facet_glint::glint_brdf::{glint_pdf, glint_sample};
    let model = MicrofacetBrdf {
        name: "ggx".into(),
        ndf: Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.3)),
        fresnel: Fresnel::Schlick { f0: [1.0; 3] },
        diffuse: [0.0; 3],
    };
    let field = FlakeField {
        density: 1.0e10,
        seed: 2,
    };
    let cfg = GlintConfig {
        gamma: 1f64.to_radians(),
        ..GlintConfig::standard()
    };
    let fp = Footprint {
        center: DVec2::splat(0.5),
        a: DVec2::new(0.05, 0.0),
        b: DVec2::new(0.0, 0.05),
    };
    let wo = dir(40.0, 0.0);
    let f = |wi: DVec3| {
        glint_eval(
            &model,
            &field,
            &fp,
            wi,
            wo,
            dpf(&model.ndf, wi, wo, cfg.gamma),
            &cfg,
        )[0] * wi.z
    };
    // Quadrature over the hemisphere of ωi.
    let (nt, np) = (120, 120);
    let mut quad = 0.0;
    for a in 0..nt {
        let t = (a as f64 + 0.5) / nt as f64 * PI / 2.0;
        for b in 0..np {
            let wi =
                facet_fit::model::geometry::spherical(t, (b as f64 + 0.5) / np as f64 * 2.0 * PI);
            quad += f(wi) * t.sin() * (PI / 2.0 / nt as f64) * (2.0 * PI / np as f64);
        }
    }
    // Monte Carlo with the lobe's samples; the pdf integrates to at most 1.
    let n = 4000;
    let (mut mc, mut sq) = (0.0, 0.0);
    for k in 0..n {
        if let Some((wi, pdf)) =
            glint_sample(&model, wo, [tea_unit(k, 1) as f64, tea_unit(k, 2) as f64])
        {
            assert!((pdf - glint_pdf(&model, wi, wo)).abs() <= 1e-12 * pdf);
            let x = f(wi) / pdf;
            mc += x;
            sq += x * x;
        }
    }
    let mean = mc / n as f64;
    let sigma = ((sq / n as f64 - mean * mean) / n as f64).sqrt();
    println!("albedo: quadrature {quad:.4}, sampled {mean:.4} ± {sigma:.4}");
    assert!((mean - quad).abs() < 4.0 * sigma + 0.01 * quad);
}

/// ≥ 10⁵ random queries, in pairs sharing a footprint as a shading point's light and BSDF
/// samples do, counted on the GPU (one walk per pair) and on the CPU (one per query), with and
/// without blending the direction cells. Lit counts are integers drawn from the same hashes;
/// f32 against f64 can still move a flake across the ellipse's edge or a uniform across a
/// CDF step (about 1e-7 apart): stated budget, at most 0.1 % of the queries may differ (by more
/// than 1e-4 relative), by at most 2 flakes per flake counted.
#[test]
fn gpu_counts_match_cpu_counts() {
    let Some(gpu) = facet_gpu::gpu_for_tests("gpu_counts_match_cpu_counts") else {
        return;
    };
    use facet_glint::flakes::direction_coords;
    use facet_glint::glint_brdf::glint_count_at;
    use facet_glint::gpu::{GlintCounter, GlintQuery};
    let counter = GlintCounter::new(&gpu.device).unwrap();
    let field = FlakeField {
        density: 3.0e5,
        seed: 21,
    };
    for blend in [true, false] {
        let cfg = GlintConfig {
            gamma: 2f64.to_radians(),
            threshold: 16.0,
            filtered: true,
            blend,
        };
        let pairs = 50_000u32;
        let mut qs = Vec::new();
        let (mut cpu, mut counted_flags) = (Vec::new(), Vec::new());
        for k in 0..pairs {
            let fp = footprint(k, 0.002 + 0.01 * tea_unit(k, 9) as f64);
            let wo = dir(
                70.0 * tea_unit(k, 11) as f64,
                360.0 * tea_unit(k, 12) as f64,
            );
            let mut p = [0.0; 2];
            let mut coords = [DVec2::ZERO; 2];
            for j in 0..2 {
                let wi = dir(70.0 * tea_unit(k, 10 + 10 * j) as f64, 0.0);
                // As the GPU sees them: f32.
                p[j as usize] = (0.2 * tea_unit(k, 13 + 10 * j) as f64) as f32 as f64;
                coords[j as usize] = direction_coords(wi, wo, cfg.gamma).as_vec2().as_dvec2();
                cpu.push(glint_count_at(
                    &field,
                    &fp,
                    coords[j as usize],
                    p[j as usize],
                    &cfg,
                ));
                counted_flags.push(field.density * fp.area() * p[j as usize] <= cfg.threshold);
            }
            qs.push(GlintQuery::pair(&fp, p, coords));
        }
        let g: Vec<f64> = counter
            .count(&gpu, &field, &cfg, &qs)
            .unwrap()
            .into_iter()
            .flatten()
            .collect();
        let n = g.len();
        let differ = g
            .iter()
            .zip(&cpu)
            .filter(|(a, b)| (*a - *b).abs() > 1e-4 * b.max(1.0))
            .count();
        let worst = g
            .iter()
            .zip(&cpu)
            .map(|(a, b)| (a - b).abs() / b.max(1.0))
            .fold(0.0, f64::max);
        let counted = counted_flags.iter().filter(|&&c| c).count();
        println!(
            "blend {blend}: {differ} of {n} queries differ ({counted} counted, the rest filtered); worst relative difference {worst}"
        );
        assert!(
            differ as f64 <= 0.001 * n as f64 && worst <= 2.0,
            "{differ} differ, worst {worst}"
        );
        assert!(
            counted > n / 2,
            "most queries must be counted, not filtered: {counted}"
        );
    }
}

/// The glint BRDF evaluated in WGSL (P from the pyramid's 3D textures) against the CPU on 10⁵
/// random queries, direction cells blended. f32 against f64: values agree to 1e-3 relative; a
/// flake can still cross the ellipse's edge, a uniform a CDF step (P differs by ~1e-6), or N·a·P
/// the filter's threshold, which changes a count: stated budget, at most 0.1 % of the queries
/// (33 of 10⁵ seen on lavapipe; 592 before the WGSL polar angle avoided the driver's atan2,
/// whose ~1e-4 error shifted the cells' bilinear weights).
#[test]
fn gpu_glint_brdf_matches_cpu() {
    let Some(gpu) = facet_gpu::gpu_for_tests("gpu_glint_brdf_matches_cpu") else {
        return;
    };
    use facet_fit::model::fresnel::FresnelTable;
    use facet_glint::dpf::{DpfConfig, DpfPyramid};
    use facet_glint::gpu::{GlintEvalQuery, GlintEvaluator, build_levels};
    let analytic = AnalyticNdf::isotropic(NdfKind::Beckmann, ALPHA);
    let schlick = Fresnel::Schlick {
        f0: [0.9, 0.6, 0.2],
    };
    let table = FresnelTable::on_merl_bins(
        (0..90)
            .map(|j| schlick.eval(f64::to_radians(j as f64).cos()))
            .collect(),
    );
    let model = MicrofacetBrdf {
        name: "beckmann".into(),
        ndf: Ndf::Analytic(analytic),
        fresnel: Fresnel::Table(table.clone()),
        diffuse: [0.0; 3],
    };
    let cfg = GlintConfig {
        gamma: 3f64.to_radians(),
        threshold: 16.0,
        filtered: true,
        blend: true,
    };
    let (levels, _) = DpfPyramid::levels_for(cfg.gamma);
    let dpf_levels = build_levels(&gpu, &model.ndf, DpfConfig::preview(), &levels).unwrap();
    let field = FlakeField {
        density: 2.0e5,
        seed: 8,
    };
    let n = 100_000u32;
    let mut queries = Vec::new();
    let mut cpu = Vec::new();
    for k in 0..n {
        let fp = footprint(k, 0.002 + 0.015 * tea_unit(k, 20) as f64);
        let wi = dir(
            80.0 * tea_unit(k, 21) as f64,
            360.0 * tea_unit(k, 22) as f64,
        );
        // ωo near the mirror direction half of the time, where glints are.
        let wo = if k % 2 == 0 {
            dir(
                80.0 * tea_unit(k, 23) as f64,
                360.0 * tea_unit(k, 24) as f64,
            )
        } else {
            let m = DVec3::new(-wi.x, -wi.y, wi.z);
            (m + 0.3
                * DVec3::new(
                    tea_unit(k, 25) as f64 - 0.5,
                    tea_unit(k, 26) as f64 - 0.5,
                    0.0,
                ))
            .normalize()
        };
        let (to, ti) = (wo.z.acos(), wi.z.acos());
        let dphi = wo.y.atan2(wo.x) - wi.y.atan2(wi.x);
        let p = dpf_levels.pyramid.lookup(to, ti, dphi, cfg.gamma);
        cpu.push(glint_eval(&model, &field, &fp, wi, wo, p, &cfg));
        queries.push(GlintEvalQuery::new(wi, wo, &fp));
    }
    let evaluator = GlintEvaluator::new(&gpu.device).unwrap();
    let g = evaluator
        .eval(&gpu, &field, &cfg, &analytic, &table, &dpf_levels, &queries)
        .unwrap();
    let (mut differ, mut nonzero) = (0, 0);
    for (a, b) in g.iter().zip(&cpu) {
        if b[1] > 0.0 {
            nonzero += 1;
        }
        if (0..3).any(|c| (a[c] - b[c]).abs() > 1e-3 * b[c].abs().max(1e-6)) {
            differ += 1;
        }
    }
    println!("{differ} of {n} queries differ by more than 1e-3 relative; {nonzero} non-zero");
    assert!(nonzero > 1000, "the queries must hit glints: {nonzero}");
    assert!(differ as f64 <= 0.001 * n as f64, "{differ} differ");
}

/// Sampling in WGSL against the Rust sampler on 10⁵ random (ωo, u): same ωi to 1e-4, same pdf
/// to 1e-3 relative (f32), the same samples rejected below the horizon.
#[test]
fn gpu_sampling_matches_cpu() {
    let Some(gpu) = facet_gpu::gpu_for_tests("gpu_sampling_matches_cpu") else {
        return;
    };
    use facet_glint::glint_brdf::glint_sample;
    use facet_gpu::{buffer, shader};
    for (kind, kind_id) in [(NdfKind::Ggx, 0u32), (NdfKind::Beckmann, 1u32)] {
        let analytic = AnalyticNdf {
            kind,
            alpha_x: 0.15,
            alpha_y: 0.4,
            rotation: 0.3,
        };
        let model = MicrofacetBrdf {
            name: "m".into(),
            ndf: Ndf::Analytic(analytic),
            fresnel: Fresnel::Schlick { f0: [1.0; 3] },
            diffuse: [0.0; 3],
        };
        let n = 100_000u32;
        let mut inputs: Vec<[f32; 4]> = Vec::new();
        let mut cpu = Vec::new();
        for k in 0..n {
            let wo = dir(
                85.0 * tea_unit(k, 31) as f64,
                360.0 * tea_unit(k, 32) as f64,
            );
            let u = [tea_unit(k, 33) as f64, tea_unit(k, 34) as f64];
            let wof = wo.as_vec3();
            // The GPU sees f32 inputs; the CPU reference takes the same rounded values.
            let (wo, u) = (wof.as_dvec3(), [u[0] as f32 as f64, u[1] as f32 as f64]);
            inputs.push([wof.x, wof.y, wof.z, u[0] as f32]);
            inputs.push([u[1] as f32, 0.0, 0.0, 0.0]);
            cpu.push(glint_sample(&model, wo, u));
        }
        let params: [u32; 4] = [
            kind_id,
            (0.15f32).to_bits(),
            (0.4f32).to_bits(),
            (0.3f32).to_bits(),
        ];
        let pipeline =
            shader::compute_pipeline(&gpu.device, "glint/glint_sample.wgsl", "glint_sample", &[])
                .unwrap();
        let ub = buffer::uniform(&gpu.device, "ndf", &params);
        let ib = buffer::storage(&gpu.device, "inputs", &inputs);
        let ob = buffer::storage_zeroed(&gpu.device, "samples", (n as u64) * 16);
        let wg =
            facet_gpu::shader::workgroup_size("glint/glint_sample.wgsl", "glint_sample").unwrap();
        facet_gpu::dispatch::run(
            &gpu.device,
            &gpu.queue,
            &pipeline,
            "sample",
            &[
                ub.as_entire_binding(),
                ib.as_entire_binding(),
                ob.as_entire_binding(),
            ],
            n,
            wg,
        );
        let out: Vec<[f32; 4]> = buffer::read(&gpu.device, &gpu.queue, &ob, n as usize).unwrap();
        let mut mismatched = 0;
        for (g, c) in out.iter().zip(&cpu) {
            let ok = match c {
                Some((wi, pdf)) => {
                    g[3] > 0.0
                        && (DVec3::new(g[0] as f64, g[1] as f64, g[2] as f64) - *wi).length() < 1e-4
                        && (g[3] as f64 / pdf - 1.0).abs() < 1e-3
                }
                None => g[3] == 0.0,
            };
            if !ok {
                mismatched += 1;
            }
        }
        println!("{kind:?}: {mismatched} of {n} samples differ");
        // Samples grazing the horizon can land on either side in f32.
        assert!(
            mismatched as f64 <= 1e-3 * n as f64,
            "{kind:?}: {mismatched}"
        );
    }
}

/// Counts are monotone in P for fixed keys: a light that brightens a direction only adds lit
/// flakes. Every draw is an inverse CDF at a fixed uniform, each non-decreasing in its count,
/// except where a draw switches from the exact CDF to its normal approximation (a mean crossing
/// 30, a split crossing 8 lit flakes), where the two can disagree by one: stated budget, 0.5 %
/// of random pairs (P1 < P2).
#[test]
fn counts_grow_with_p_for_fixed_keys() {
    use facet_glint::lit::LitKey;
    let field = FlakeField {
        density: 1.0e6,
        seed: 4,
    };
    let (mut violations, mut pairs, mut grew) = (0, 0, 0);
    for k in 0..5000u32 {
        let fp = footprint(k, 0.002 + 0.02 * tea_unit(k, 30) as f64);
        let key = LitKey(tea_unit(k, 31).to_bits(), k);
        let p1 = 0.05 * tea_unit(k, 32) as f64;
        let p2 = p1 * (1.0 + 0.2 * tea_unit(k, 33) as f64);
        let (c1, c2) = (field.lit_count(&fp, p1, key), field.lit_count(&fp, p2, key));
        pairs += 1;
        violations += (c1 > c2) as u32;
        grew += (c2 > c1) as u32;
    }
    println!("{violations} of {pairs} pairs decrease with P; {grew} grow");
    assert!(grew > pairs / 10, "P must matter: {grew}");
    assert!(violations as f64 <= 0.005 * pairs as f64, "{violations}");
}

/// No popping: the jump of a count over a small light move that takes the half vector across a
/// direction-cell edge. Without blending a crossing redraws every flake's state: the jump
/// (~√(2 N a P)) does not shrink with the move. Blended, the count fades across a band around
/// the edge, so the jump is proportional to the move, like a move inside a cell. Statistic: the
/// mean jump of crossing moves at δ/4 over that at δ (δ = γ/10 of light turn): 1 for a
/// discontinuity, ¼ for a continuous count; stated: > 0.6 unblended, < 0.45 blended.
#[test]
fn blended_counts_do_not_pop_at_cell_edges() {
    let field = FlakeField {
        density: 1.0e6,
        seed: 17,
    };
    let gamma = 2f64.to_radians();
    let mut ratios = Vec::new();
    for blend in [false, true] {
        let cfg = GlintConfig {
            gamma,
            threshold: 16.0,
            filtered: false,
            blend,
        };
        let mut crossing_jump = Vec::new();
        for (turn, moves) in [(gamma / 10.0, 4000u32), (gamma / 40.0, 16000)] {
            let (mut jc, mut nc) = (0.0, 0.0);
            for k in 0..moves {
                let wo = dir(30.0, 180.0);
                let wi = dir(
                    25.0 + 10.0 * tea_unit(k, 40) as f64,
                    20.0 * (tea_unit(k, 41) as f64 - 0.5),
                );
                let wi2 = {
                    let axis = DVec3::new(
                        tea_unit(k, 42) as f64 - 0.5,
                        tea_unit(k, 43) as f64 - 0.5,
                        0.0,
                    )
                    .normalize();
                    glam::DQuat::from_axis_angle(axis, turn) * wi
                };
                if direction_cell(wi, wo, gamma) == direction_cell(wi2, wo, gamma) {
                    continue;
                }
                let fp = footprint(k, 0.02);
                let count =
                    |w: DVec3| glint_count(&field, &fp, w, wo, dpf(&ndf(), w, wo, gamma), &cfg);
                jc += (count(wi) - count(wi2)).abs();
                nc += 1.0;
            }
            println!(
                "blend {blend}: light turn {:.3}°: mean jump {:.3} over {nc} moves crossing an edge",
                turn.to_degrees(),
                jc / nc
            );
            crossing_jump.push(jc / nc);
        }
        ratios.push(crossing_jump[1] / crossing_jump[0]);
    }
    println!(
        "jump at δ/4 over jump at δ: unblended {:.2}, blended {:.2}",
        ratios[0], ratios[1]
    );
    assert!(
        ratios[0] > 0.6,
        "the statistic must see unblended popping: {ratios:?}"
    );
    assert!(ratios[1] < 0.45, "blended counts pop: {ratios:?}");
}

/// The glint model of a fit's tabulated NDF (the demo fit: D, Λ and P from its tables) has the
/// smooth tabulated BRDF as its large-footprint limit, as the analytic one does.
#[test]
fn tabulated_glints_converge_to_the_smooth_tabulated_brdf() {
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/demo/default_fit.json");
    let fit = facet_fit::model::material::FittedMaterial::load(&path).unwrap();
    let model = fit.tabulated.clone();
    assert!(matches!(model.ndf, Ndf::Tabulated(_)));
    let field = FlakeField {
        density: 1.0e9,
        seed: 2,
    };
    let cfg = GlintConfig::standard();
    let fp = Footprint {
        center: DVec2::splat(0.5),
        a: DVec2::new(0.05, 0.0),
        b: DVec2::new(0.0, 0.04),
    };
    for (wi, wo) in [
        (dir(0.0, 0.0), dir(10.0, 90.0)),
        (dir(30.0, 0.0), dir(30.0, 180.0)),
        (dir(60.0, 0.0), dir(45.0, 160.0)),
    ] {
        let p = dpf(&model.ndf, wi, wo, cfg.gamma);
        let glint = glint_eval(&model, &field, &fp, wi, wo, p, &cfg);
        let smooth = facet_fit::model::brdf::Brdf::eval(&model, wi, wo).unwrap();
        println!("tabulated: glint {glint:.5?} smooth {smooth:.5?}");
        assert!((0..3).all(|c| (glint[c] / smooth[c] - 1.0).abs() < 0.01));
    }
}

/// Large footprints with the filter off, counted in WGSL against the CPU: up to 3 · 10⁵ flakes
/// and ~3000 lit ones a query. lavapipe (llvmpipe) caps the loop iterations of a shader
/// invocation at 65 535, so a walk that loops once a node and once a lit boundary flake comes
/// back short beyond some size there; these sizes stay below it. (Before leaves took their lit
/// flakes as a run, with 64-flake leaves scanned by selection sampling, 117 of 128 queries of
/// 10⁴ flakes at P = 0.05 came back short there, a third of the count.) A real GPU has no such
/// cap.
#[test]
fn gpu_counts_match_cpu_counts_on_large_unfiltered_footprints() {
    let Some(gpu) =
        facet_gpu::gpu_for_tests("gpu_counts_match_cpu_counts_on_large_unfiltered_footprints")
    else {
        return;
    };
    use facet_glint::flakes::direction_coords;
    use facet_glint::glint_brdf::glint_count_at;
    use facet_glint::gpu::{GlintCounter, GlintQuery};
    let counter = GlintCounter::new(&gpu.device).unwrap();
    let field = FlakeField {
        density: 3.0e5,
        seed: 21,
    };
    let cfg = GlintConfig {
        gamma: 2f64.to_radians(),
        threshold: 16.0,
        filtered: false,
        blend: true,
    };
    for (flakes, p) in [
        (1e3, 0.2),
        (1e4, 0.05),
        (3e4, 0.05),
        (1e5, 0.01),
        (3e5, 0.01),
    ] {
        let r = (flakes / field.density / PI).sqrt();
        let p = p as f32 as f64;
        let (mut qs, mut cpu) = (Vec::new(), Vec::new());
        for k in 0..64u32 {
            let fp = footprint(k, r);
            let wo = dir(40.0, 360.0 * tea_unit(k, 12) as f64);
            let wi = dir(30.0 + 0.3 * tea_unit(k, 10) as f64, 0.0);
            // Two direction cells a query, one near an edge (blended).
            let c = direction_coords(wi, wo, cfg.gamma).as_vec2().as_dvec2();
            let coords = [c, c + DVec2::new(0.37, 0.61)];
            for c in coords {
                cpu.push(glint_count_at(&field, &fp, c, p, &cfg));
            }
            qs.push(GlintQuery::pair(&fp, [p, p], coords));
        }
        let g: Vec<f64> = counter
            .count(&gpu, &field, &cfg, &qs)
            .unwrap()
            .into_iter()
            .flatten()
            .collect();
        // f32 against f64: a flake on the ellipse's edge may fall either side.
        let differ = g
            .iter()
            .zip(&cpu)
            .filter(|(a, b)| (*a - *b).abs() > 1e-3 * b.max(1.0))
            .count();
        let (sg, sc) = (g.iter().sum::<f64>(), cpu.iter().sum::<f64>());
        println!(
            "{flakes:e} flakes, P = {p:.3}: {differ} of {} queries differ; Σ GPU {sg:.0}, Σ CPU {sc:.0}",
            g.len()
        );
        assert!(differ <= 2, "{differ} of {} differ", g.len());
        assert!(
            (sg - sc).abs() <= 1e-3 * sc,
            "Σ GPU {sg} against Σ CPU {sc}"
        );
    }
}
