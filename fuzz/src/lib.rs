//! What the fuzz targets assert about a loader's answer. (The seeds in `corpus/<target>/seed-*`
//! are written by the root package's `tests/loader_mutation.rs`, see the README.)
//!
//! Every target: no panic; an error's message names the path given to the loader; an accepted
//! input gives a value the renderer and the fitter can use (finite values, indices in range,
//! BRDFs finite and non-negative where evaluated). A broken assertion panics, which libFuzzer
//! reports as a crash.

use facet_fit::Brdf;
use facet_render::scene::{EnvironmentMap, Light, Scene};
use glam::{DVec3, Vec2, Vec3};
use std::cell::RefCell;
use std::path::Path;

thread_local! {
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Runs one input. The loaders catch panics of their decoders and turn them into errors, which
/// is what a caller sees, so libFuzzer's hook (abort on any panic) is replaced the first time by
/// one that only records the panic; a panic that leaves `f` is then printed and aborts (a
/// crash). `FACET_FUZZ_CAUGHT_PANICS=1` keeps libFuzzer's hook: caught panics crash too.
pub fn run(f: impl FnOnce()) {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        if std::env::var_os("FACET_FUZZ_CAUGHT_PANICS").is_none() {
            std::panic::set_hook(Box::new(|info| {
                LAST_PANIC.with_borrow_mut(|s| *s = info.to_string());
            }));
        }
    });
    if std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).is_err() {
        eprintln!(
            "panic out of the loader or its checks: {}",
            LAST_PANIC.take()
        );
        std::process::abort();
    }
}

/// Panics unless the error's message names `path`.
pub fn assert_names(path: &Path, e: impl std::fmt::Display) {
    let message = e.to_string();
    assert!(
        message.contains(&path.display().to_string()),
        "the error does not name {}: {message}",
        path.display()
    );
}

/// Direction pairs (wi, wo) a BRDF is evaluated at: normal, mid, grazing, retro, forward.
pub fn direction_pairs() -> [(DVec3, DVec3); 6] {
    let d = |theta: f64, phi: f64| {
        DVec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    };
    [
        (d(0.0, 0.0), d(0.0, 0.0)),
        (d(0.3, 0.0), d(0.5, 3.1)),
        (d(1.2, 0.4), d(0.7, 2.0)),
        (d(1.56, 0.0), d(1.56, std::f64::consts::PI)),
        (d(0.8, 1.0), d(0.8, 1.0)),
        (d(1.5, -2.0), d(0.1, 3.0)),
    ]
}

/// Panics unless every value the BRDF gives at [`direction_pairs`] is finite and non-negative.
pub fn assert_brdf_sane(what: &str, brdf: &dyn Brdf) {
    for (wi, wo) in direction_pairs() {
        if let Some(v) = brdf.eval(wi, wo) {
            assert!(
                v.iter().all(|x| x.is_finite() && *x >= 0.0),
                "accepted, but {what}: f_r({wi}, {wo}) = {v:?}"
            );
        }
    }
}

fn unit(v: Vec3) -> bool {
    v.is_finite() && (v.length() - 1.0).abs() < 1e-3
}

/// Panics unless the scene is one the renderer can use.
pub fn assert_scene_sane(scene: &Scene) {
    let n = scene.positions.len();
    assert!(
        scene.normals.len() == n && scene.uvs.len() == n && scene.tangents.len() == n,
        "{n} positions, {} normals, {} UVs, {} tangents",
        scene.normals.len(),
        scene.uvs.len(),
        scene.tangents.len()
    );
    assert!(
        !scene.indices.is_empty(),
        "accepted a scene without triangles"
    );
    assert_eq!(scene.triangle_material.len(), scene.indices.len());
    for p in &scene.positions {
        assert!(p.is_finite(), "a position is {p}");
    }
    for v in &scene.normals {
        assert!(unit(*v), "a normal is {v}");
    }
    for t in &scene.tangents {
        assert!(unit(t.truncate()) && t.w.abs() == 1.0, "a tangent is {t}");
    }
    for uv in &scene.uvs {
        assert!(Vec2::is_finite(*uv), "a UV is {uv}");
    }
    for t in &scene.indices {
        assert!(
            t.iter().all(|&i| (i as usize) < n),
            "triangle {t:?} of {n} vertices"
        );
    }
    for &m in &scene.triangle_material {
        assert!(
            (m as usize) < scene.materials.len(),
            "triangle material {m}"
        );
    }
    for m in &scene.materials {
        let scalars = [m.metallic, m.roughness, m.specular, m.normal_scale];
        assert!(
            m.base_color.is_finite()
                && m.emissive.is_finite()
                && scalars.iter().all(|x| x.is_finite()),
            "material `{}` has a non-finite factor: {m:?}",
            m.name
        );
        let textures = [
            m.base_color_texture,
            m.metallic_roughness_texture,
            m.normal_texture,
            m.emissive_texture,
        ];
        for &t in textures.iter().flatten() {
            assert!(
                (t as usize) < scene.textures.len(),
                "material `{}` uses texture {t}",
                m.name
            );
        }
        if let Some(facet) = &m.facet {
            assert_brdf_sane(&format!("the fit of material `{}`", m.name), &*facet.fit);
        }
    }
    for t in &scene.textures {
        assert!(
            !t.texels.is_empty() && t.texels.len() == t.width as usize * t.height as usize,
            "texture `{}`: {} texels for {}×{}",
            t.name,
            t.texels.len(),
            t.width,
            t.height
        );
    }
    let c = &scene.camera;
    assert!(
        c.position.is_finite()
            && unit(c.forward)
            && unit(c.up)
            && c.forward.dot(c.up).abs() < 1e-3
            && c.yfov > 0.0
            && c.yfov < std::f32::consts::PI,
        "camera {c:?}"
    );
    for light in &scene.lights {
        let ok = match *light {
            Light::Point {
                position,
                intensity,
            } => position.is_finite() && intensity.is_finite(),
            Light::Spot {
                position,
                direction,
                intensity,
                inner_cone,
                outer_cone,
            } => {
                position.is_finite()
                    && unit(direction)
                    && intensity.is_finite()
                    && inner_cone.is_finite()
                    && outer_cone.is_finite()
            }
            Light::Directional {
                direction,
                irradiance,
            } => unit(direction) && irradiance.is_finite(),
        };
        assert!(ok, "light {light:?}");
    }
}

/// Panics unless the map and its sampling distribution are usable.
pub fn assert_env_sane(map: &EnvironmentMap) {
    let (w, h) = (map.width as usize, map.height as usize);
    assert!(
        w > 0 && h > 0 && map.texels.len() == w * h,
        "{} texels for {w}×{h}",
        map.texels.len()
    );
    for t in &map.texels {
        assert!(t.is_finite() && t.min_element() >= 0.0, "a texel is {t}");
    }
    let cdf = &map.marginal_cdf;
    assert!(
        cdf.len() == h + 1
            && cdf.windows(2).all(|p| p[0] <= p[1])
            && cdf.iter().all(|x| (0.0..=1.0).contains(x))
            && map.total.is_finite()
            && map.total > 0.0,
        "marginal CDF {:?}…, total {}",
        &cdf[..cdf.len().min(4)],
        map.total
    );
    for u in [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.999, 0.001),
    ] {
        let (d, pdf, radiance) = map.sample(u);
        assert!(
            unit(d) && pdf.is_finite() && pdf >= 0.0 && radiance.is_finite(),
            "sample({u}) = ({d}, {pdf}, {radiance})"
        );
        assert!(
            map.pdf(d).is_finite() && map.lookup(d).is_finite(),
            "pdf or lookup at {d}"
        );
    }
}
