//! glTF: a small scene with every part the loader reads, as JSON and as `.glb`.

use crate::harness::refused;
use facet_oracles::scene_sane;
use facet_render::scene::data_uri::encode_base64;
use facet_render::scene::{LoadOptions, load_gltf_bytes};
use std::path::Path;

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

/// A small scene with every part the loader reads, its buffer and image embedded: a quad with
/// normals, UVs, tangents and u16 indices, a second primitive with positions only, a mirrored
/// child node, a textured material and one with a Facet fit (`fit.json` beside the scene), a
/// camera, and point, spot and directional lights. Returns (JSON with the buffer as a data
/// URI, JSON for a `.glb` whose buffer is the BIN chunk, the buffer).
pub fn small_scene(fit: &str) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let mut buf: Vec<u8> = Vec::new();
    let mut put = |vs: &[f32]| vs.iter().for_each(|v| buf.extend(v.to_le_bytes()));
    put(&[-1., 0., -1., 1., 0., -1., 1., 0., 1., -1., 0., 1.]); // 0: positions, 48 bytes
    put(&[0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1., 0.]); // 48: normals
    put(&[0., 0., 1., 0., 1., 1., 0., 1.]); // 96: UVs, 32 bytes
    put(&[
        1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1., 1., 0., 0., 1.,
    ]); // 128: tangents
    for i in [0u16, 2, 1, 0, 3, 2] {
        buf.extend(i.to_le_bytes()); // 192: indices, 12 bytes
    }
    let mut png = Vec::new();
    image::RgbaImage::from_fn(2, 2, |x, y| {
        image::Rgba([255 * x as u8, 128, 255 * y as u8, 255])
    })
    .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
    .unwrap();
    let json = |buffer: String| {
        format!(
            r#"{{
"asset": {{"version": "2.0"}},
"extensionsUsed": ["KHR_lights_punctual"],
"scene": 0,
"scenes": [{{"nodes": [0, 2, 3, 4, 5]}}],
"nodes": [
  {{"name": "quad", "mesh": 0, "translation": [0, 0, -3], "rotation": [0, 0.3826834, 0, 0.9238795], "scale": [1, 2, 1], "children": [1]}},
  {{"name": "mirror", "mesh": 0, "matrix": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 1, 0, 1]}},
  {{"name": "eye", "camera": 0, "translation": [0, 1, 2]}},
  {{"name": "bulb", "translation": [0, 3, 0], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}},
  {{"name": "spot", "rotation": [-0.7071068, 0, 0, 0.7071068], "extensions": {{"KHR_lights_punctual": {{"light": 1}}}}}},
  {{"name": "sun", "extensions": {{"KHR_lights_punctual": {{"light": 2}}}}}}
],
"cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.8, "znear": 0.1, "zfar": 100, "aspectRatio": 1.5}}}}],
"extensions": {{"KHR_lights_punctual": {{"lights": [
  {{"type": "point", "color": [1, 0.9, 0.8], "intensity": 10}},
  {{"type": "spot", "intensity": 5, "spot": {{"innerConeAngle": 0.2, "outerConeAngle": 0.5}}}},
  {{"type": "directional", "intensity": 2}}
]}}}},
"meshes": [{{"name": "quad", "primitives": [
  {{"attributes": {{"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 3}}, "indices": 4, "material": 0}},
  {{"attributes": {{"POSITION": 5}}, "material": 1}}
]}}],
"materials": [
  {{"name": "painted", "pbrMetallicRoughness": {{"baseColorFactor": [0.8, 0.2, 0.1, 1], "baseColorTexture": {{"index": 0}}, "metallicFactor": 0.5, "roughnessFactor": 0.4, "metallicRoughnessTexture": {{"index": 0}}}}, "normalTexture": {{"index": 0, "scale": 1}}, "emissiveFactor": [0.1, 0.1, 0.1], "emissiveTexture": {{"index": 0}}}},
  {{"name": "fitted", "extras": {{"facet": {{"fit": "{fit}", "model": "ggx", "glint": {{"density": 1000000, "gamma_deg": 2, "threshold": 50}}}}}}}}
],
"textures": [{{"source": 0, "sampler": 0}}],
"samplers": [{{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33648}}],
"images": [{{"uri": "data:image/png;base64,{png}"}}],
"accessors": [
  {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]}},
  {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
  {{"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"}},
  {{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC4"}},
  {{"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}},
  {{"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 3, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]}}
],
"bufferViews": [
  {{"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962}},
  {{"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962}},
  {{"buffer": 0, "byteOffset": 96, "byteLength": 32, "target": 34962}},
  {{"buffer": 0, "byteOffset": 128, "byteLength": 64, "target": 34962}},
  {{"buffer": 0, "byteOffset": 192, "byteLength": 12, "target": 34963}}
],
"buffers": [{{"byteLength": {len}{buffer}}}]
}}"#,
            png = encode_base64(&png),
            len = buf.len(),
            fit = fit,
        )
        .into_bytes()
    };
    let embedded = json(format!(
        r#", "uri": "data:application/octet-stream;base64,{}""#,
        encode_base64(&buf)
    ));
    (embedded, json(String::new()), buf)
}

/// The glTF loader on `bytes` as if read from `path`: refused with an error naming `path`, or
/// a scene that passes `facet_oracles::scene_sane`.
pub fn check_gltf(path: &Path, bytes: &[u8]) -> Result<bool, String> {
    match load_gltf_bytes(path, bytes, &LoadOptions::default()) {
        Ok(scene) => scene_sane(&scene)
            .map(|()| true)
            .map_err(|p| format!("accepted, but {p}")),
        Err(e) => refused(path, e),
    }
}
