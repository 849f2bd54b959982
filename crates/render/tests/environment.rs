//! Environment maps: the sampling density integrates to one, importance sampling estimates the
//! map's integral, sampled pixels follow their probabilities, bad files are named.

mod common;

use common::{demo, temp_dir};
use facet_render::scene::Environment;
use facet_render::scene::environment::{EnvironmentMap, direction_to_uv, luminance};
use glam::{Vec2, Vec3};
use std::f64::consts::PI;
use std::path::PathBuf;
use std::sync::Arc;

/// xorshift64*: deterministic uniform numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32) / (1u64 << 24) as f32
    }
    fn vec2(&mut self) -> Vec2 {
        Vec2::new(self.next(), self.next())
    }
}

/// A 64 × 32 test map: a colour gradient, a black row, a black column block and a hot spot.
fn test_map() -> EnvironmentMap {
    let (w, h) = (64usize, 32usize);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if y == 5 || (20..24).contains(&x) {
                Vec3::ZERO
            } else if (x, y) == (40, 12) {
                Vec3::new(300.0, 200.0, 100.0)
            } else {
                Vec3::new(0.2 + x as f32 / 64.0, 0.5, 1.0 - y as f32 / 40.0)
            }
        })
        .collect();
    EnvironmentMap::from_texels("test".into(), w as u32, h as u32, texels).unwrap()
}

/// Exact ∫ L dω: Σ L_xy ΔΩ_xy, ΔΩ = (2π / w)(cos θ_top − cos θ_bottom).
fn exact_integral(m: &EnvironmentMap) -> [f64; 3] {
    let (w, h) = (m.width as usize, m.height as usize);
    let mut sum = [0.0f64; 3];
    for (i, t) in m.texels.iter().enumerate() {
        let y = (i / w) as f64;
        let d_omega =
            2.0 * PI / w as f64 * ((PI * y / h as f64).cos() - (PI * (y + 1.0) / h as f64).cos());
        for c in 0..3 {
            sum[c] += f64::from(t[c]) * d_omega;
        }
    }
    sum
}

fn sky_map() -> EnvironmentMap {
    let (texels, _) = demo::sky_texels();
    EnvironmentMap::from_texels("sky".into(), 256, 128, texels).unwrap()
}

fn black_map() -> EnvironmentMap {
    EnvironmentMap::from_texels("black".into(), 16, 8, vec![Vec3::ZERO; 128]).unwrap()
}

#[test]
fn cdfs_have_the_documented_shape() {
    for m in [test_map(), sky_map(), black_map()] {
        let (w, h) = (m.width as usize, m.height as usize);
        assert_eq!(m.marginal_cdf.len(), h + 1);
        assert_eq!(m.conditional_cdf.len(), h * (w + 1));
        assert_eq!((m.marginal_cdf[0], m.marginal_cdf[h]), (0.0, 1.0));
        for y in 0..h {
            let row = &m.conditional_cdf[y * (w + 1)..(y + 1) * (w + 1)];
            assert_eq!((row[0], row[w]), (0.0, 1.0));
            assert!(row.windows(2).all(|p| p[0] <= p[1]));
        }
        assert!(m.total > 0.0);
    }
    // The black row of the test map is never chosen; the all-black map falls back to sin θ.
    let m = test_map();
    assert_eq!(m.marginal_cdf[5], m.marginal_cdf[6]);
    let b = black_map();
    assert!(
        (b.pixel_probability(3, 0) / b.pixel_probability(3, 3)
            - (PI / 16.0).sin() as f32 / (PI * 3.5 / 8.0).sin() as f32)
            .abs()
            < 1e-5
    );
}

#[test]
fn pdf_integrates_to_one_over_the_sphere() {
    for (name, m) in [
        ("test", test_map()),
        ("sky", sky_map()),
        ("black", black_map()),
    ] {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let n = 2_000_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            // Uniform direction: y = 1 − 2u, φ = 2πv; ∫ pdf dω = 4π E[pdf].
            let (u, v) = (rng.next(), rng.next());
            let y = 1.0 - 2.0 * u;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = 2.0 * std::f32::consts::PI * v;
            let x = f64::from(m.pdf(Vec3::new(r * phi.cos(), y, r * phi.sin()))) * 4.0 * PI;
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / n as f64;
        let sigma = ((sum2 / n as f64 - mean * mean) / n as f64).sqrt();
        println!("{name}: ∫ pdf dω = {mean:.5} ± {sigma:.5}");
        assert!(
            (mean - 1.0).abs() < 3.0 * sigma + 1e-3,
            "{name}: ∫ pdf = {mean} ± {sigma}"
        );
        // The same integral by an 8 × 8 midpoint rule inside every pixel, dω = 2π² sin θ du dv.
        let (w, h) = (m.width as usize, m.height as usize);
        let mut quad = 0.0f64;
        for j in 0..h * 8 {
            for i in 0..w * 8 {
                let uv = Vec2::new(
                    (i as f32 + 0.5) / (8 * w) as f32,
                    (j as f32 + 0.5) / (8 * h) as f32,
                );
                let d = facet_render::scene::environment::uv_to_direction(uv);
                let d_omega = 2.0 * PI * PI * (PI * f64::from(uv.y)).sin() / (64 * w * h) as f64;
                quad += f64::from(m.pdf(d)) * d_omega;
            }
        }
        assert!(
            (quad - 1.0).abs() < 1e-4,
            "{name}: midpoint ∫ pdf dω = {quad}"
        );
    }
}

#[test]
fn importance_samples_estimate_the_integral_and_match_pdf() {
    for (name, m) in [("test", test_map()), ("sky", sky_map())] {
        let mut rng = Rng(12345);
        let n = 200_000;
        let mut est = [0.0f64; 3];
        for _ in 0..n {
            let (d, pdf, l) = m.sample(rng.vec2());
            if pdf == 0.0 {
                continue;
            }
            assert!((d.length() - 1.0).abs() < 1e-5 && pdf.is_finite());
            // Exactly pdf() and lookup() of the direction, by contract.
            assert_eq!((m.pdf(d), m.lookup(d)), (pdf, l));
            for c in 0..3 {
                est[c] += f64::from(l[c] / pdf) / n as f64;
            }
        }
        let exact = exact_integral(&m);
        println!("{name}: E[L/pdf] = {est:?}, exact {exact:?}");
        for c in 0..3 {
            assert!(
                (est[c] / exact[c] - 1.0).abs() < 0.01,
                "{name} channel {c}: {} vs {}",
                est[c],
                exact[c]
            );
        }
    }
}

#[test]
fn sampled_pixels_follow_their_probabilities() {
    let m = test_map();
    let (w, h) = (m.width as usize, m.height as usize);
    let n = 500_000usize;
    let mut counts = vec![0usize; w * h];
    let mut rng = Rng(777);
    for _ in 0..n {
        let (d, _, _) = m.sample(rng.vec2());
        let uv = direction_to_uv(d);
        let (x, y) = (
            ((uv.x * w as f32) as usize).min(w - 1),
            ((uv.y * h as f32) as usize).min(h - 1),
        );
        counts[y * w + x] += 1;
    }
    let (mut chi2, mut dof) = (0.0f64, 0usize);
    for y in 0..h {
        for x in 0..w {
            let expected = f64::from(m.pixel_probability(x, y)) * n as f64;
            let got = counts[y * w + x] as f64;
            if expected == 0.0 {
                assert!(
                    got <= 1.0,
                    "pixel ({x}, {y}) has probability 0 but {got} samples"
                );
            } else {
                chi2 += (got - expected).powi(2) / expected;
                dof += 1;
            }
        }
    }
    let dof = (dof - 1) as f64;
    println!("χ² = {chi2:.1} for {dof} degrees of freedom");
    assert!(chi2 < dof + 5.0 * (2.0 * dof).sqrt(), "χ² = {chi2} ≫ {dof}");
    // The hot spot gets its share: p_xy = w_xy / Σ w.
    let spot = m.pixel_probability(40, 12);
    let w_spot =
        luminance(Vec3::new(300.0, 200.0, 100.0)) * (std::f32::consts::PI * 12.5 / 32.0).sin();
    assert!(
        (spot - w_spot / m.total).abs() < 1e-5,
        "{spot} vs {}",
        w_spot / m.total
    );
}

#[test]
fn environment_radiance_is_constant_or_the_nearest_texel() {
    let m = Arc::new(test_map());
    let d = Vec3::new(0.3, -0.2, 0.9).normalize();
    assert_eq!(Environment::Constant(Vec3::ONE).radiance(d), Vec3::ONE);
    let uv = direction_to_uv(d);
    let (x, y) = ((uv.x * 64.0) as usize, (uv.y * 32.0) as usize);
    assert_eq!(
        Environment::Map(m.clone()).radiance(d),
        m.texels[y * 64 + x]
    );
    // Row 0 is straight up.
    assert_eq!(m.pixel(Vec3::Y).1, 0);
    assert_eq!(m.pixel(Vec3::NEG_Y).1, 31);
}

#[test]
fn bad_exr_files_are_errors_naming_them() {
    let dir = temp_dir("exr");
    let missing = dir.join("absent.exr");
    let e = EnvironmentMap::load(&missing).unwrap_err().to_string();
    assert!(e.contains("absent.exr"), "{e}");
    std::fs::write(dir.join("text.exr"), "this is not an image").unwrap();
    let e = EnvironmentMap::load(&dir.join("text.exr"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("text.exr"), "{e}");
    let e = EnvironmentMap::from_texels(PathBuf::from("zero.exr"), 0, 4, vec![])
        .unwrap_err()
        .to_string();
    assert!(e.contains("zero.exr"), "{e}");
    let e = EnvironmentMap::from_texels("nan.exr".into(), 1, 1, vec![Vec3::NAN])
        .unwrap_err()
        .to_string();
    assert!(e.contains("nan.exr"), "{e}");
}

#[test]
fn non_finite_and_negative_texels_become_zero_with_a_warning() {
    let dir = temp_dir("exr-nan");
    let path = dir.join("nan.exr");
    exr::prelude::write_rgb_file(&path, 4, 2, |x, y| match (x, y) {
        (0, 0) => (f32::NAN, 1.0, 1.0),
        (1, 0) => (-1.0, 1.0, 1.0),
        (2, 1) => (f32::INFINITY, 0.0, 0.0),
        _ => (1.0, 2.0, 3.0),
    })
    .unwrap();
    let (m, warnings) = EnvironmentMap::load(&path).unwrap();
    assert_eq!((m.width, m.height), (4, 2));
    assert_eq!(
        &m.texels[..3],
        &[Vec3::ZERO, Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)]
    );
    assert_eq!(m.texels[6], Vec3::ZERO);
    assert!(
        warnings.len() == 1 && warnings[0].contains("nan.exr") && warnings[0].contains('3'),
        "{warnings:?}"
    );
}

#[test]
fn committed_sky_has_a_sun_three_times_the_sky() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/demo/sky.exr");
    let (m, warnings) = EnvironmentMap::load(&path).unwrap();
    assert!(warnings.is_empty());
    assert_eq!((m.width, m.height), (256, 128));
    // Same texels as the generator (f32 ZIP is lossless).
    assert_eq!(m.texels, demo::sky_texels().0);
    // The brightest pixel is the sun's.
    let brightest = (0..m.texels.len())
        .max_by(|&a, &b| luminance(m.texels[a]).total_cmp(&luminance(m.texels[b])))
        .unwrap();
    assert_eq!(brightest, {
        let (x, y) = m.pixel(demo::sun_direction());
        y * 256 + x
    });
    // Sun irradiance at normal incidence vs sky on a horizontal plane, split by a 5° cone.
    let (w, h) = (256usize, 128usize);
    let (mut sun, mut sky) = (0.0f64, 0.0f64);
    for (i, t) in m.texels.iter().enumerate() {
        let d = facet_render::scene::environment::uv_to_direction(Vec2::new(
            ((i % w) as f32 + 0.5) / w as f32,
            ((i / w) as f32 + 0.5) / h as f32,
        ));
        let d_omega = 2.0 * PI / w as f64 * PI / h as f64 * f64::from((1.0 - d.y * d.y).sqrt());
        let l = f64::from(luminance(*t));
        if d.dot(demo::sun_direction()) > 5f32.to_radians().cos() {
            sun += l * d_omega;
        } else if d.y > 0.0 {
            sky += l * d_omega * f64::from(d.y);
        }
    }
    println!("sun {sun:.3}, sky {sky:.3}, ratio {:.3}", sun / sky);
    assert!((sun / sky - 3.0).abs() < 0.3, "sun / sky = {}", sun / sky);
}
