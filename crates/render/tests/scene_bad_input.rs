//! glTF files that are broken or partly broken: missing or invalid files, truncated GLB, missing
//! buffers, degenerate and NaN triangles, scenes with nothing to render.

mod common;

use common::{GltfBuilder, assert_all_finite, temp_dir};
use facet_render::RenderError;
use facet_render::scene::{LoadOptions, Scene, load_gltf};
use glam::Vec3;
use serde_json::json;
use std::path::Path;

fn load(path: &Path) -> Scene {
    load_gltf(path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn load_err(path: &Path) -> String {
    match load_gltf(path, &LoadOptions::default()) {
        Ok(_) => panic!("{} loaded but should not", path.display()),
        Err(e) => e.to_string(),
    }
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn bad_files_are_errors_naming_them() {
    let dir = temp_dir("bad");
    let e = load_err(&dir.join("nowhere.gltf"));
    assert!(e.contains("nowhere.gltf"), "{e}");
    std::fs::write(
        dir.join("broken.gltf"),
        "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [",
    )
    .unwrap();
    let e = load_err(&dir.join("broken.gltf"));
    assert!(e.contains("broken.gltf"), "{e}");

    // A valid GLB, then truncated.
    let mut g = GltfBuilder::default();
    let (p, _, i) = g.triangle();
    let mesh = g.mesh("tri", json!({"POSITION": p}), Some(i), None);
    let root = g.node(json!({"mesh": mesh}));
    let mut doc = g.finish(&[root]);
    doc["buffers"] = json!([{"byteLength": g.bin.len()}]);
    let mut text = serde_json::to_vec(&doc).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + g.bin.len();
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend((total as u32).to_le_bytes());
    glb.extend((text.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&text);
    glb.extend((g.bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&g.bin);
    std::fs::write(dir.join("ok.glb"), &glb).unwrap();
    assert_eq!(load(&dir.join("ok.glb")).indices.len(), 1);
    std::fs::write(dir.join("cut.glb"), &glb[..glb.len() - 20]).unwrap();
    let e = load_err(&dir.join("cut.glb"));
    assert!(e.contains("cut.glb"), "{e}");

    // A buffer file that does not exist.
    doc["buffers"] = json!([{"byteLength": g.bin.len(), "uri": "gone.bin"}]);
    std::fs::write(dir.join("nobuf.gltf"), serde_json::to_string(&doc).unwrap()).unwrap();
    let e = load_err(&dir.join("nobuf.gltf"));
    assert!(e.contains("nobuf.gltf") && e.contains("buffer"), "{e}");
}

#[test]
fn degenerate_triangles_are_dropped_and_nothing_is_nan() {
    let dir = temp_dir("degenerate");
    let mut g = GltfBuilder::default();
    let nan = f32::NAN;
    let p = g.vec3s(&[
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0], // good
        [0.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 2.0, 0.0], // collinear: zero area
        [nan, 0.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 1.0, 1.0], // NaN corner
        [5.0, 5.0, 5.0],
        [5.0, 5.0, 5.0],
        [5.0, 5.0, 5.0], // a point
    ]);
    let n = g.vec3s(&[[0.0, 0.0, 1.0], [nan, 0.0, 1.0], [0.0, 0.0, 0.0]].repeat(4));
    let uv = g.floats(&[0.0, 0.0, nan, 0.0, 0.0, 1.0].repeat(4), "VEC2");
    let mesh = g.mesh(
        "jagged",
        json!({"POSITION": p, "NORMAL": n, "TEXCOORD_0": uv}),
        None,
        None,
    );
    let root = g.node(json!({"mesh": mesh}));
    g.write(&[root], &dir.join("d.gltf"));
    let s = load(&dir.join("d.gltf"));
    assert_eq!(s.indices.len(), 1);
    assert_eq!(
        s.positions.len(),
        3,
        "vertices of dropped triangles are not kept"
    );
    assert_all_finite(&s);
    assert!(
        s.normals.iter().all(|n| close(*n, Vec3::Z)),
        "{:?}",
        s.normals
    );
    let dropped: Vec<_> = s
        .warnings
        .iter()
        .filter(|w| w.contains("dropped"))
        .collect();
    assert_eq!(dropped.len(), 1, "{:?}", s.warnings);
    assert!(
        dropped[0].contains("jagged") && dropped[0].contains('3'),
        "{}",
        dropped[0]
    );
}

#[test]
fn empty_scene_is_an_error() {
    let dir = temp_dir("empty");
    let mut g = GltfBuilder::default();
    let p = g.vec3s(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]);
    let mesh = g.mesh("line", json!({"POSITION": p}), None, None);
    let root = g.node(json!({"mesh": mesh}));
    g.write(&[root], &dir.join("e.gltf"));
    match load_gltf(&dir.join("e.gltf"), &LoadOptions::default()) {
        Err(RenderError::Scene(m)) => {
            assert!(m.contains("e.gltf") && m.contains("no triangles"), "{m}")
        }
        other => panic!("{other:?}"),
    }
}
