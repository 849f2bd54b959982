//! What the fuzz targets assert about a loader's answer, and the seed inputs
//! (`examples/seeds.rs` writes them to `corpus/<target>/seed-*`).
//!
//! Every target: no panic; an error's message names the path given to the loader; an accepted
//! input gives a value the renderer and the fitter can use (finite values, indices in range,
//! BRDFs finite and non-negative where evaluated). A broken assertion panics, which libFuzzer
//! reports as a crash.

use facet_fit::Brdf;
use facet_render::scene::{EnvironmentMap, Light, Scene};
use glam::{DVec3, Vec2, Vec3};
use std::path::Path;

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
    assert!(!scene.indices.is_empty(), "accepted a scene without triangles");
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
        assert!(t.iter().all(|&i| (i as usize) < n), "triangle {t:?} of {n} vertices");
    }
    for &m in &scene.triangle_material {
        assert!((m as usize) < scene.materials.len(), "triangle material {m}");
    }
    for m in &scene.materials {
        let scalars = [m.metallic, m.roughness, m.specular, m.normal_scale];
        assert!(
            m.base_color.is_finite() && m.emissive.is_finite() && scalars.iter().all(|x| x.is_finite()),
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
            assert!((t as usize) < scene.textures.len(), "material `{}` uses texture {t}", m.name);
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
            Light::Point { position, intensity } => position.is_finite() && intensity.is_finite(),
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
            Light::Directional { direction, irradiance } => unit(direction) && irradiance.is_finite(),
        };
        assert!(ok, "light {light:?}");
    }
}

/// Panics unless the map and its sampling distribution are usable.
pub fn assert_env_sane(map: &EnvironmentMap) {
    let (w, h) = (map.width as usize, map.height as usize);
    assert!(w > 0 && h > 0 && map.texels.len() == w * h, "{} texels for {w}×{h}", map.texels.len());
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
    for u in [Vec2::new(0.1, 0.2), Vec2::new(0.5, 0.5), Vec2::new(0.999, 0.001)] {
        let (d, pdf, radiance) = map.sample(u);
        assert!(
            unit(d) && pdf.is_finite() && pdf >= 0.0 && radiance.is_finite(),
            "sample({u}) = ({d}, {pdf}, {radiance})"
        );
        assert!(map.pdf(d).is_finite() && map.lookup(d).is_finite(), "pdf or lookup at {d}");
    }
}

/// A `.glb`: 12-byte header, the JSON chunk padded with spaces, the BIN chunk padded with zeros.
pub fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let (jl, bl) = (pad(json.len()), pad(bin.len()));
    let total = 12 + 8 + jl + 8 + bl;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(jl as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(12 + 8 + jl, b' ');
    out.extend_from_slice(&(bl as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out.resize(total, 0);
    out
}

/// The fit file beside the fuzzed glTF (the `gltf` target writes it there): the demo's.
pub const FIT_NAME: &str = "default_fit.json";
pub const FIT_JSON: &str = include_str!("../../assets/demo/default_fit.json");

/// A small scene with every part the glTF loader reads, its buffer and image embedded: a quad
/// with normals, UVs, tangents and u16 indices, a second primitive with positions only, a
/// mirrored child, a textured material and one with a Facet fit ([`FIT_NAME`] beside the
/// scene), a camera, point, spot and directional lights. Returns (JSON with the buffer as a
/// data URI, JSON for a `.glb` whose buffer is the BIN chunk, the buffer).
pub fn small_scene(png: &[u8]) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    use facet_render::scene::data_uri::encode_base64;
    let mut buf: Vec<u8> = Vec::new();
    let mut put = |vs: &[f32]| vs.iter().for_each(|v| buf.extend(v.to_le_bytes()));
    put(&[-1., 0., -1., 1., 0., -1., 1., 0., 1., -1., 0., 1.]); // 0: positions, 48 bytes
    put(&[0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1., 0.]); // 48: normals
    put(&[0., 0., 1., 0., 1., 1., 0., 1.]); // 96: UVs, 32 bytes
    put(&[1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1.]); // 128: tangents
    for i in [0u16, 2, 1, 0, 3, 2] {
        buf.extend(i.to_le_bytes()); // 192: indices, 12 bytes
    }
    let json = |buffer: String| {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_lights_punctual"],"scene":0,
"scenes":[{{"nodes":[0,2,3,4,5]}}],
"nodes":[{{"name":"quad","mesh":0,"translation":[0,0,-3],"rotation":[0,0.3826834,0,0.9238795],"scale":[1,2,1],"children":[1]}},
{{"name":"mirror","mesh":0,"matrix":[-1,0,0,0,0,1,0,0,0,0,1,0,0,1,0,1]}},
{{"name":"eye","camera":0,"translation":[0,1,2]}},
{{"name":"bulb","translation":[0,3,0],"extensions":{{"KHR_lights_punctual":{{"light":0}}}}}},
{{"name":"spot","rotation":[-0.7071068,0,0,0.7071068],"extensions":{{"KHR_lights_punctual":{{"light":1}}}}}},
{{"name":"sun","extensions":{{"KHR_lights_punctual":{{"light":2}}}}}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.8,"znear":0.1,"zfar":100,"aspectRatio":1.5}}}}],
"extensions":{{"KHR_lights_punctual":{{"lights":[{{"type":"point","color":[1,0.9,0.8],"intensity":10}},
{{"type":"spot","intensity":5,"spot":{{"innerConeAngle":0.2,"outerConeAngle":0.5}}}},{{"type":"directional","intensity":2}}]}}}},
"meshes":[{{"name":"quad","primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2,"TANGENT":3}},"indices":4,"material":0}},
{{"attributes":{{"POSITION":5}},"material":1}}]}}],
"materials":[{{"name":"painted","pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.2,0.1,1],"baseColorTexture":{{"index":0}},"metallicFactor":0.5,"roughnessFactor":0.4,"metallicRoughnessTexture":{{"index":0}}}},"normalTexture":{{"index":0,"scale":1}},"emissiveFactor":[0.1,0.1,0.1],"emissiveTexture":{{"index":0}}}},
{{"name":"fitted","extras":{{"facet":{{"fit":"{fit}","model":"ggx","glint":{{"density":1000000,"gamma_deg":2,"threshold":50}}}}}}}}],
"textures":[{{"source":0,"sampler":0}}],"samplers":[{{"magFilter":9729,"minFilter":9987,"wrapS":10497,"wrapT":33648}}],
"images":[{{"uri":"data:image/png;base64,{png}"}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,0,-1],"max":[1,0,1]}},
{{"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"}},{{"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"}},
{{"bufferView":3,"componentType":5126,"count":4,"type":"VEC4"}},{{"bufferView":4,"componentType":5123,"count":6,"type":"SCALAR"}},
{{"bufferView":0,"byteOffset":12,"componentType":5126,"count":3,"type":"VEC3","min":[-1,0,-1],"max":[1,0,1]}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48,"target":34962}},{{"buffer":0,"byteOffset":48,"byteLength":48,"target":34962}},
{{"buffer":0,"byteOffset":96,"byteLength":32,"target":34962}},{{"buffer":0,"byteOffset":128,"byteLength":64,"target":34962}},
{{"buffer":0,"byteOffset":192,"byteLength":12,"target":34963}}],
"buffers":[{{"byteLength":{len}{buffer}}}]}}"#,
            fit = FIT_NAME,
            png = encode_base64(png),
            len = buf.len(),
        )
        .into_bytes()
    };
    let embedded = json(format!(
        r#","uri":"data:application/octet-stream;base64,{}""#,
        encode_base64(&buf)
    ));
    (embedded, json(String::new()), buf)
}
