//! Measured materials on the GPU against their CPU twins: the MERL-grid lookup of
//! `shaders/render/materials/merl.inc.wgsl` against `MerlTable::lookup_interpolated` on the same filled
//! table, at 10⁵ random direction pairs, grazing ones included.

use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::geometry::to_half_diff;
use facet_fit::model::merl_grid::{
    MerlTable, PHI_D_RES, THETA_D_RES, THETA_H_RES, index as merl_index,
};
use facet_fit::sources::nbrdf::NbrdfLibrary;
use facet_fit::{Brdf, Rgb};
use facet_gpu::{Gpu, buffer, dispatch, gpu_for_tests, shader};
use facet_render::bvh::procedural::Rng;
use facet_render::materials::merl::merl_block;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// A direction above the horizon: cos θ uniform, or (one in four) grazing, θ in [80°, 89.5°].
fn direction(rng: &mut Rng) -> DVec3 {
    let phi = 2.0 * PI * rng.f32() as f64;
    let theta = if rng.f32() < 0.25 {
        (80.0 + 9.5 * rng.f32() as f64).to_radians()
    } else {
        (rng.f32() as f64).acos()
    };
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// The pairs as the GPU reads them (f32) and as the CPU reads the same f32 values.
fn pairs(n: usize, seed: u64) -> (Vec<[f32; 8]>, Vec<(DVec3, DVec3)>) {
    let mut rng = Rng::new(seed);
    let f32s: Vec<[f32; 8]> = (0..n)
        .map(|_| {
            let (a, b) = (direction(&mut rng).as_vec3(), direction(&mut rng).as_vec3());
            [a.x, a.y, a.z, 0.0, b.x, b.y, b.z, 0.0]
        })
        .collect();
    let f64s = f32s
        .iter()
        .map(|p| {
            let v = |i: usize| DVec3::new(p[i] as f64, p[i + 1] as f64, p[i + 2] as f64);
            (v(0), v(4))
        })
        .collect();
    (f32s, f64s)
}

/// merl_eval on the GPU at every pair.
fn gpu_lookup(gpu: &Gpu, table: &MerlTable, pairs: &[[f32; 8]]) -> Vec<[f32; 4]> {
    let (d, q) = (&gpu.device, &gpu.queue);
    let constants = [
        ("MERL_THETA_H", THETA_H_RES as f64),
        ("MERL_THETA_D", THETA_D_RES as f64),
        ("MERL_PHI_D", PHI_D_RES as f64),
    ];
    let pipeline = shader::compute_pipeline(d, "tests/render/merl_probe.wgsl", "probe", &constants)
        .unwrap_or_else(|e| panic!("{e}"));
    let tables = buffer::storage(d, "merl table", &merl_block(table));
    let input = buffer::storage(d, "pairs", pairs);
    let results = buffer::storage_zeroed(d, "results", pairs.len() as u64 * 16);
    dispatch::run(
        d,
        q,
        &pipeline,
        "merl probe",
        &[
            tables.as_entire_binding(),
            input.as_entire_binding(),
            results.as_entire_binding(),
        ],
        pairs.len() as u32,
        64,
    );
    buffer::read(d, q, &results, pairs.len()).unwrap()
}

/// The largest |value| among the valid samples a lookup of (wi, wo) blends, over the sum of
/// their weights: the scale of what a shift of the bin coordinates by f32 rounding can change
/// (the blend renormalises by that sum where corners are missing, which magnifies the shift).
fn corner_scale(table: &MerlTable, wi: DVec3, wo: DVec3) -> f64 {
    let c = to_half_diff(wi, wo);
    let x = [
        (c.theta_h.max(0.0) / FRAC_PI_2).sqrt() * THETA_H_RES as f64,
        c.theta_d.max(0.0) / FRAC_PI_2 * THETA_D_RES as f64,
        c.phi_d.rem_euclid(PI) / PI * PHI_D_RES as f64,
    ];
    let axis = |v: f64, n: usize| {
        let v = v.clamp(0.0, (n - 1) as f64);
        let i = (v as usize).min(n - 2);
        [(i, 1.0 - (v - i as f64)), (i + 1, v - i as f64)]
    };
    let p = (x[2] as usize).min(PHI_D_RES - 1);
    let tp = x[2] - p as f64;
    let (mut m, mut wsum) = (0.0f64, 0.0);
    for (i, wi) in axis(x[0], THETA_H_RES) {
        for (j, wj) in axis(x[1], THETA_D_RES) {
            for (k, wk) in [(p, 1.0 - tp), ((p + 1) % PHI_D_RES, tp)] {
                if let Some(v) = table.value(i, j, k) {
                    m = v.iter().fold(m, |m, x| m.max(x.abs()));
                    wsum += wi * wj * wk;
                }
            }
        }
    }
    m / wsum.max(1e-3)
}

/// Asserts the GPU lookup equals the CPU's at every pair: |GPU − CPU| ≤ 1e-5 |CPU| (f32
/// rounding of the blend) + 2e-4 · the largest corner (the bin coordinates, in f32, are off by
/// up to ~10⁻⁴ bins near the 180-bin φd axis's end after the atan2s and the fold, and the blend
/// moves by that fraction of the corners' spread, over the valid corners' weight) + 1e-30. Returns the worst ratio to that
/// allowance.
fn assert_gpu_matches_cpu(what: &str, gpu: &Gpu, table: &MerlTable, n: usize, seed: u64) -> f64 {
    let (f32s, f64s) = pairs(n, seed);
    let out = gpu_lookup(gpu, table, &f32s);
    let mut worst = 0.0f64;
    let mut nonzero = 0;
    for ((wi, wo), g) in f64s.iter().zip(&out) {
        let cpu: Rgb = table.lookup_interpolated(*wi, *wo).unwrap_or([0.0; 3]);
        let scale = corner_scale(table, *wi, *wo);
        for c in 0..3 {
            let allowed = 1e-5 * cpu[c].abs() + 2e-4 * scale + 1e-30;
            let r = (g[c] as f64 - cpu[c]).abs() / allowed;
            worst = worst.max(r);
            assert!(
                r <= 1.0,
                "{what}: wi {wi} wo {wo} channel {c}: GPU {} CPU {} (corners up to {scale})",
                g[c],
                cpu[c]
            );
        }
        nonzero += (cpu[1] > 0.0) as usize;
    }
    assert!(nonzero > n / 2, "{what}: {nonzero} of {n} pairs nonzero");
    println!("{what}: worst |GPU − CPU| / allowance {worst:.3} over {n} pairs");
    worst
}

/// A sharp GGX (α 0.05, its peak ~10³ times its tails) sampled on the grid, and a MERL-100
/// proxy sampled on the grid, each filled as the renderer fills them; and a table with whole
/// (θh, φd) lines missing, which stay missing after the fill, so that the renormalised blend
/// and the all-missing zero are exercised.
#[test]
fn gpu_merl_lookup_matches_the_cpu_at_1e5_pairs() {
    let Some(gpu) = gpu_for_tests("gpu_merl_lookup_matches_the_cpu_at_1e5_pairs") else {
        return;
    };
    let ggx = MerlTable::sample(&parse_analytic("ggx?alpha=0.05&f0=0.9").unwrap()).filled();
    assert_gpu_matches_cpu("GGX α 0.05", &gpu, &ggx, 100_000, 1);

    let library = NbrdfLibrary::embedded();
    let paint = library.get("gold-metallic-paint").unwrap();
    assert!(paint.is_isotropic());
    let paint = paint.merl_table().filled();
    assert_gpu_matches_cpu("gold-metallic-paint proxy", &gpu, &paint, 100_000, 2);

    let mut holes = MerlTable::sample(&parse_analytic("beckmann?alpha=0.3&f0=0.5").unwrap());
    for i in (0..THETA_H_RES).step_by(3) {
        for k in (0..PHI_D_RES).step_by(2) {
            (0..THETA_D_RES).for_each(|j| holes.mark_missing(merl_index(i, j, k)));
        }
    }
    let holes = holes.filled();
    assert!(holes.missing_count() > 0);
    assert_gpu_matches_cpu("lines missing", &gpu, &holes, 20_000, 3);
}
