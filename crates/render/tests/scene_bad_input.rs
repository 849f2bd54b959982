//! glTF files that are broken or partly broken: missing or invalid files, truncated GLB, missing
//! buffers, degenerate and NaN triangles, scenes with nothing to render.

mod common;

use common::{GltfBuilder, assert_all_finite, close, load, load_err, temp_dir};
use facet_render::RenderError;
use facet_render::scene::{LoadOptions, load_gltf};
use glam::Vec3;
use serde_json::json;
use std::path::Path;

#[test]
fn bad_files_are_errors_naming_them() {
    let dir = temp_dir("bad");
    let e = load_err(&dir.join("nowhere.gltf"), &LoadOptions::default());
    assert!(e.contains("nowhere.gltf"), "{e}");
    std::fs::write(
        dir.join("broken.gltf"),
        "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [",
    )
    .unwrap();
    let e = load_err(&dir.join("broken.gltf"), &LoadOptions::default());
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
    let e = load_err(&dir.join("cut.glb"), &LoadOptions::default());
    assert!(e.contains("cut.glb"), "{e}");

    // A buffer file that does not exist.
    doc["buffers"] = json!([{"byteLength": g.bin.len(), "uri": "gone.bin"}]);
    std::fs::write(dir.join("nobuf.gltf"), serde_json::to_string(&doc).unwrap()).unwrap();
    let e = load_err(&dir.join("nobuf.gltf"), &LoadOptions::default());
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

// ---------------------------------------------------------------------------------------------
// Hostile input: each class is an error (or a warning) naming the file and the field at fault,
// never a panic, a hang or a huge allocation.

use facet_render::scene::{EnvironmentMap, load_gltf_bytes};
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Runs `f` on a thread and fails the test if it does not return within 10 s (a read blocked
/// on a FIFO), or if it panics.
fn within_10s<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    match rx.recv_timeout(Duration::from_secs(10)) {
        Ok(v) => v,
        Err(mpsc::RecvTimeoutError::Timeout) => panic!("{what}: did not return within 10 s"),
        Err(mpsc::RecvTimeoutError::Disconnected) => panic!("{what}: panicked"),
    }
}

/// A one-triangle scene (mesh `floor`) with accessors POSITION 0, NORMAL 1, indices 2 and
/// views 0, 1, 2; `edit` changes the builder, then `edit_doc` the JSON; written to `name`.
fn triangle_file(
    dir: &Path,
    name: &str,
    edit: impl FnOnce(&mut GltfBuilder),
    edit_doc: impl FnOnce(&mut serde_json::Value),
) -> PathBuf {
    let mut g = GltfBuilder::default();
    let (p, n, i) = g.triangle();
    let mesh = g.mesh("floor", json!({"POSITION": p, "NORMAL": n}), Some(i), None);
    let root = g.node(json!({"mesh": mesh}));
    edit(&mut g);
    let mut doc = g.finish(&[root]);
    edit_doc(&mut doc);
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
    path
}

/// The error of loading `path` (on a thread, within 10 s), asserted to name the file.
fn hostile(path: &Path) -> String {
    let p = path.to_owned();
    let e = within_10s(&path.display().to_string(), move || {
        load_gltf(&p, &LoadOptions::default()).map(|_| ())
    })
    .expect_err("loaded but should not");
    let e = e.to_string();
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(e.contains(name), "the error does not name {name}: {e}");
    e
}

fn has_all(e: &str, words: &[&str]) {
    for w in words {
        assert!(e.contains(w), "`{w}` missing from: {e}");
    }
}

#[test]
fn byte_stride_shorter_than_the_element_is_an_error() {
    let dir = temp_dir("stride");
    let path = triangle_file(
        &dir,
        "stride.gltf",
        |g| g.views[0]["byteStride"] = json!(4),
        |_| {},
    );
    let e = hostile(&path);
    has_all(
        &e,
        &[
            "accessor 0",
            "POSITION of mesh `floor`, primitive 0",
            "byteStride 4",
        ],
    );
    // Not a multiple of 4, and too long.
    for (stride, word) in [(14, "multiple of 4"), (256, "252")] {
        let path = triangle_file(
            &dir,
            "stride2.gltf",
            |g| g.views[0]["byteStride"] = json!(stride),
            |_| {},
        );
        // 256 is refused by the gltf crate's own validation already; both name the view.
        let e = hostile(&path);
        assert!(e.contains(word) || e.contains("byteStride"), "{e}");
    }
}

#[test]
fn float_byte_and_short_indices_are_errors() {
    let dir = temp_dir("index-types");
    for (ct, name) in [(5126, "FLOAT"), (5120, "BYTE"), (5122, "SHORT")] {
        let path = triangle_file(
            &dir,
            "idx.gltf",
            |g| g.accessors[2]["componentType"] = json!(ct),
            |_| {},
        );
        let e = hostile(&path);
        has_all(
            &e,
            &[
                "accessor 2 (indices of mesh `floor`, primitive 0)",
                &format!("componentType {name} is not allowed for indices"),
            ],
        );
    }
    // Normalized indices, and a VEC3 index accessor.
    let path = triangle_file(
        &dir,
        "idx-norm.gltf",
        |g| {
            g.accessors[2]["componentType"] = json!(5121);
            g.accessors[2]["normalized"] = json!(true);
        },
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 2", "normalized"]);
    let path = triangle_file(
        &dir,
        "idx-vec.gltf",
        |g| g.accessors[2]["type"] = json!("VEC3"),
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 2", "type VEC3"]);
}

#[test]
fn unsigned_int_texture_coordinates_are_an_error() {
    let dir = temp_dir("uv-u32");
    let mut g = GltfBuilder::default();
    let (p, _, i) = g.triangle();
    let uv = g.floats(&[0.0; 6], "VEC2");
    g.accessors[uv]["componentType"] = json!(5125);
    let mesh = g.mesh(
        "floor",
        json!({"POSITION": p, "TEXCOORD_0": uv}),
        Some(i),
        None,
    );
    let root = g.node(json!({"mesh": mesh}));
    g.write(&[root], &dir.join("uv.gltf"));
    let e = hostile(&dir.join("uv.gltf"));
    has_all(
        &e,
        &[
            "accessor 3 (TEXCOORD_0 of mesh `floor`, primitive 0): componentType UNSIGNED_INT is not allowed for TEXCOORD_0",
        ],
    );
    // UNSIGNED_BYTE texture coordinates must be normalized; FLOAT positions must be VEC3.
    g.accessors[uv]["componentType"] = json!(5121);
    g.write(&[root], &dir.join("uv8.gltf"));
    has_all(
        &hostile(&dir.join("uv8.gltf")),
        &["accessor 3", "must be normalized"],
    );
    g.accessors[uv]["componentType"] = json!(5126);
    g.accessors[p]["type"] = json!("VEC4");
    g.write(&[root], &dir.join("pos4.gltf"));
    has_all(
        &hostile(&dir.join("pos4.gltf")),
        &["accessor 0 (POSITION", "type VEC4"],
    );
}

#[test]
fn camera_type_without_its_block_is_an_error_when_used_and_a_warning_otherwise() {
    let dir = temp_dir("camera-type");
    // The used camera (the first perspective one): type perspective, only an orthographic block.
    let path = triangle_file(
        &dir,
        "cam.gltf",
        |g| {
            g.cameras.push(json!({"type": "perspective",
                "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0}}));
            let c = g.node(json!({"camera": 0}));
            g.nodes[0]["children"] = json!([c]);
        },
        |_| {},
    );
    has_all(&hostile(&path), &["camera 0", "no `perspective` block"]);
    // Asked for by --camera: the same error.
    let e = load_gltf(
        &path,
        &LoadOptions {
            camera: Some("0".into()),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    has_all(&e, &["cam.gltf", "camera 0", "no `perspective` block"]);
    // Not used (type orthographic, a perspective block): a warning, and the framing default.
    let path = triangle_file(
        &dir,
        "cam2.gltf",
        |g| {
            g.cameras.push(json!({"type": "orthographic",
                "perspective": {"yfov": 0.5, "znear": 0.1}}));
            let c = g.node(json!({"camera": 0}));
            g.nodes[0]["children"] = json!([c]);
        },
        |_| {},
    );
    let s = load(&path);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("camera 0") && w.contains("no `orthographic` block")),
        "{:?}",
        s.warnings
    );
    // Bad perspective values of the used camera.
    for (persp, word) in [
        (json!({"yfov": 4.0, "znear": 0.1}), "yfov"),
        (json!({"yfov": 0.5, "znear": 0.0}), "znear"),
        (json!({"yfov": 0.5, "znear": 1.0, "zfar": 0.5}), "zfar"),
    ] {
        let path = triangle_file(
            &dir,
            "cam3.gltf",
            |g| {
                g.cameras
                    .push(json!({"type": "perspective", "perspective": persp}));
                let c = g.node(json!({"camera": 0}));
                g.nodes[0]["children"] = json!([c]);
            },
            |_| {},
        );
        has_all(&hostile(&path), &["camera 0", word]);
    }
}

#[test]
fn count_times_stride_overflow_is_an_error() {
    let dir = temp_dir("overflow");
    // A count far past any buffer, with a stride: refused by its size before any arithmetic.
    let path = triangle_file(
        &dir,
        "count.gltf",
        |g| {
            g.views[0]["byteStride"] = json!(12);
            g.accessors[0]["count"] = json!(u64::MAX / 8);
        },
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 0", "count"]);
    // A byteOffset near 2^64: offset + (count − 1) × stride + size overflows u64.
    let path = triangle_file(
        &dir,
        "offset.gltf",
        |g| {
            g.views[0]["byteStride"] = json!(12);
            g.accessors[0]["byteOffset"] = json!(u64::MAX - 3);
        },
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 0", "POSITION", "overflows"]);
    // An index accessor of 2^40 elements.
    let path = triangle_file(
        &dir,
        "indices.gltf",
        |g| g.accessors[2]["count"] = json!(3u64 << 40),
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 2", "indices", "count"]);
}

#[test]
fn an_accessor_range_past_its_view_is_an_error() {
    let dir = temp_dir("range");
    // Four positions in a view of three (and normals to match).
    let path = triangle_file(
        &dir,
        "range.gltf",
        |g| {
            g.accessors[0]["count"] = json!(4);
            g.accessors[1]["count"] = json!(4);
        },
        |_| {},
    );
    has_all(
        &hostile(&path),
        &[
            "accessor 0",
            "POSITION",
            "run past bufferView 0's byteLength 36",
        ],
    );
    // A byteOffset into the view that pushes the last element out.
    let path = triangle_file(
        &dir,
        "offs.gltf",
        |g| g.accessors[2]["byteOffset"] = json!(4),
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 2", "indices", "bufferView 2"]);
    // A misaligned byteOffset.
    let path = triangle_file(
        &dir,
        "align.gltf",
        |g| g.accessors[0]["byteOffset"] = json!(2),
        |_| {},
    );
    has_all(
        &hostile(&path),
        &["accessor 0", "byteOffset 2", "multiple of 4"],
    );
    // A count that differs from POSITION's.
    let path = triangle_file(
        &dir,
        "counts.gltf",
        |g| g.accessors[1]["count"] = json!(2),
        |_| {},
    );
    has_all(
        &hostile(&path),
        &["accessor 1", "NORMAL", "differs from POSITION's 3"],
    );
    // A count of zero.
    let path = triangle_file(
        &dir,
        "zero.gltf",
        |g| g.accessors[2]["count"] = json!(0),
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 2", "count is 0"]);
}

#[test]
fn a_view_past_its_buffer_is_an_error() {
    let dir = temp_dir("view");
    let path = triangle_file(
        &dir,
        "view.gltf",
        |g| g.views[2]["byteLength"] = json!(1000),
        |_| {},
    );
    has_all(
        &hostile(&path),
        &["accessor 2", "bufferView 2", "past the end of buffer 0"],
    );
    // A view offset near 2^64.
    let path = triangle_file(
        &dir,
        "view2.gltf",
        |g| g.views[0]["byteOffset"] = json!(u64::MAX - 3),
        |_| {},
    );
    has_all(
        &hostile(&path),
        &["accessor 0", "bufferView 0", "past the end of buffer 0"],
    );
    // A buffer whose data is shorter than its byteLength.
    let path = triangle_file(
        &dir,
        "short.gltf",
        |_| {},
        |d| d["buffers"][0]["byteLength"] = json!(1u64 << 40),
    );
    has_all(
        &hostile(&path),
        &["buffer 0", "byteLength is 1099511627776", "holds only"],
    );
}

#[test]
fn sparse_accessors_are_checked() {
    let dir = temp_dir("sparse");
    // Sparse values past their view (the indices view is reused for the sparse indices).
    let path = triangle_file(
        &dir,
        "sparse.gltf",
        |g| {
            g.accessors[0]["sparse"] = json!({"count": 2,
                "indices": {"bufferView": 2, "componentType": 5125},
                "values": {"bufferView": 2, "byteOffset": 8}});
        },
        |_| {},
    );
    has_all(
        &hostile(&path),
        &["accessor 0", "sparse.values", "bufferView 2"],
    );
    // A sparse count over the accessor's count.
    let path = triangle_file(
        &dir,
        "sparse2.gltf",
        |g| {
            g.accessors[0]["sparse"] = json!({"count": 9,
                "indices": {"bufferView": 2, "componentType": 5125},
                "values": {"bufferView": 0}});
        },
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 0", "sparse.count 9"]);
    // A valid sparse accessor without a bufferView (zeros, one vertex moved) loads.
    let path = triangle_file(
        &dir,
        "sparse-ok.gltf",
        |g| {
            let v = g.vec3s(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
            let idx = g.indices(&[1, 2]);
            let view = |a: usize, g: &GltfBuilder| g.accessors[a]["bufferView"].clone();
            let (iv, vv) = (view(idx, g), view(v, g));
            g.accessors[0] = json!({"componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0],
                "sparse": {"count": 2, "indices": {"bufferView": iv, "componentType": 5125},
                           "values": {"bufferView": vv}}});
        },
        |_| {},
    );
    let s = load(&path);
    assert_eq!(s.indices.len(), 1);
    // A sparse accessor without a bufferView has no data to bound its count: it is capped.
    let path = triangle_file(
        &dir,
        "sparse-huge.gltf",
        |g| {
            g.accessors[2] = json!({"componentType": 5125, "count": 3u64 << 40, "type": "SCALAR",
                "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5125},
                           "values": {"bufferView": 2}}});
        },
        |_| {},
    );
    has_all(&hostile(&path), &["accessor 2", "count 3298534883328"]);
}

#[test]
fn absolute_and_scheme_uris_are_refused() {
    let dir = temp_dir("uris");
    for (uri, word) in [
        ("/etc/passwd", "absolute path"),
        ("%2Fetc%2Fpasswd", "absolute path"),
        ("file:///etc/passwd", "scheme `file:`"),
        ("http://example.com/scene.bin", "scheme `http:`"),
        ("https://example.com/scene.bin", "scheme `https:`"),
    ] {
        let path = triangle_file(
            &dir,
            "uri.gltf",
            |_| {},
            |d| d["buffers"][0]["uri"] = json!(uri),
        );
        has_all(&hostile(&path), &["buffer 0", word]);
    }
    // An image with such a URI costs only its texture: a warning naming it.
    let path = triangle_file(
        &dir,
        "img.gltf",
        |g| {
            g.images.push(json!({"uri": "file:///etc/passwd"}));
            g.textures.push(json!({"source": 0}));
            let m = g.material(
                json!({"name": "m", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}),
            );
            g.meshes[0]["primitives"][0]["material"] = json!(m);
        },
        |_| {},
    );
    let s = load(&path);
    assert!(
        s.warnings.iter().any(|w| w.contains("file:///etc/passwd")
            && w.contains("scheme `file:`")
            && w.contains("`m`")),
        "{:?}",
        s.warnings
    );
}

/// Makes a FIFO at `path` (unix `mkfifo`).
#[cfg(unix)]
fn mkfifo(path: &Path) {
    let ok = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo")
        .success();
    assert!(ok, "mkfifo {}", path.display());
}

/// A scene whose buffer is the file `bin` and whose material's base colour is the image file
/// `png` (written unless they exist already).
fn external_files_scene(dir: &Path, name: &str, bin: &str, png: &str) -> PathBuf {
    let mut g = GltfBuilder::default();
    let (p, _, i) = g.triangle();
    g.images.push(json!({"uri": png}));
    g.textures.push(json!({"source": 0}));
    let m = g.material(
        json!({"name": "painted", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}),
    );
    let mesh = g.mesh("floor", json!({"POSITION": p}), Some(i), Some(m));
    let root = g.node(json!({"mesh": mesh}));
    let mut doc = g.finish(&[root]);
    doc["buffers"][0]["uri"] = json!(bin);
    if !dir.join(bin).exists() {
        std::fs::write(dir.join(bin), &g.bin).unwrap();
    }
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
    path
}

#[cfg(unix)]
#[test]
fn a_fifo_as_any_input_is_refused_without_blocking() {
    let dir = temp_dir("fifo");
    // The glTF itself.
    mkfifo(&dir.join("pipe.gltf"));
    has_all(&hostile(&dir.join("pipe.gltf")), &["FIFO"]);
    // Its buffer.
    mkfifo(&dir.join("pipe.bin"));
    let path = external_files_scene(&dir, "buf.gltf", "pipe.bin", "none.png");
    has_all(&hostile(&path), &["buffer 0", "pipe.bin", "FIFO"]);
    // A texture: a warning naming it.
    mkfifo(&dir.join("pipe.png"));
    let path = external_files_scene(&dir, "tex.gltf", "ok.bin", "pipe.png");
    let s = within_10s("texture FIFO", move || load(&path));
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("pipe.png") && w.contains("FIFO") && w.contains("painted")),
        "{:?}",
        s.warnings
    );
    // The environment map.
    mkfifo(&dir.join("pipe.exr"));
    let exr = dir.join("pipe.exr");
    let e = within_10s("EXR FIFO", move || EnvironmentMap::load(&exr).map(|_| ()))
        .unwrap_err()
        .to_string();
    has_all(&e, &["pipe.exr", "FIFO"]);
}

#[test]
fn a_directory_as_any_input_is_refused() {
    let dir = temp_dir("dirs");
    for sub in ["dir.gltf", "dir.bin", "dir.png", "dir.exr"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    has_all(&hostile(&dir.join("dir.gltf")), &["directory"]);
    let path = external_files_scene(&dir, "buf.gltf", "dir.bin", "none.png");
    has_all(&hostile(&path), &["buffer 0", "dir.bin", "directory"]);
    let path = external_files_scene(&dir, "tex.gltf", "ok.bin", "dir.png");
    let s = load(&path);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("dir.png") && w.contains("directory") && w.contains("painted")),
        "{:?}",
        s.warnings
    );
    let e = EnvironmentMap::load(&dir.join("dir.exr"))
        .unwrap_err()
        .to_string();
    has_all(&e, &["dir.exr", "directory"]);
}

/// Overwrites the box2i attribute `name` (xMin, yMin, xMax, yMax) in an EXR header.
fn patch_box2i(bytes: &mut [u8], name: &str, value: [i32; 4]) {
    let key = [name.as_bytes(), b"\0box2i\0", &16u32.to_le_bytes()].concat();
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .unwrap_or_else(|| panic!("no {name} attribute"))
        + key.len();
    for (k, v) in value.iter().enumerate() {
        bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
    }
}

#[test]
fn an_exr_header_of_100000_by_100000_is_refused_quickly() {
    let dir = temp_dir("exr-huge");
    let path = dir.join("huge.exr");
    exr::prelude::write_rgb_file(&path, 4, 2, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    for name in ["dataWindow", "displayWindow"] {
        patch_box2i(&mut bytes, name, [0, 0, 99_999, 99_999]);
    }
    std::fs::write(&path, &bytes).unwrap();
    assert!(bytes.len() < 4096, "the file stays tiny");
    let t = Instant::now();
    let p = path.clone();
    let e = within_10s("huge EXR", move || EnvironmentMap::load(&p).map(|_| ()))
        .unwrap_err()
        .to_string();
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
    has_all(&e, &["huge.exr", "100000 × 100000", "16384"]);
    // The same bytes from memory.
    let e = EnvironmentMap::from_exr_bytes(&path, &bytes)
        .unwrap_err()
        .to_string();
    has_all(&e, &["huge.exr", "100000 × 100000"]);
    // Within the sides but over the pixel count: 16384 × 16384.
    patch_box2i(&mut bytes, "dataWindow", [0, 0, 16_383, 16_383]);
    patch_box2i(&mut bytes, "displayWindow", [0, 0, 16_383, 16_383]);
    let e = EnvironmentMap::from_exr_bytes(&path, &bytes)
        .unwrap_err()
        .to_string();
    has_all(&e, &["huge.exr", "16384 × 16384", "67108864"]);
    // Within both limits (4096²) but far more chunks than the tiny file holds: refused before
    // the 200 MB pixel buffer is made.
    patch_box2i(&mut bytes, "dataWindow", [0, 0, 4095, 4095]);
    patch_box2i(&mut bytes, "displayWindow", [0, 0, 4095, 4095]);
    let e = EnvironmentMap::from_exr_bytes(&path, &bytes)
        .unwrap_err()
        .to_string();
    has_all(&e, &["huge.exr", "chunks"]);
    // Garbage after a valid magic number: an error, not a panic.
    let e = EnvironmentMap::from_exr_bytes(&path, &bytes[..40])
        .unwrap_err()
        .to_string();
    has_all(&e, &["huge.exr"]);
}

/// CRC-32 (IEEE), for patching PNG chunks.
fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

#[test]
fn a_png_announcing_100000_by_100000_is_a_warning_without_allocating() {
    let dir = temp_dir("png-huge");
    let img = image::RgbaImage::from_pixel(2, 2, image::Rgba([9, 9, 9, 255]));
    let mut png = std::io::Cursor::new(Vec::new());
    img.write_to(&mut png, image::ImageFormat::Png).unwrap();
    let mut png = png.into_inner();
    // IHDR: length (4) "IHDR" (4) width (4, BE) height (4, BE) … CRC over type + data.
    assert_eq!(&png[12..16], b"IHDR");
    png[16..20].copy_from_slice(&100_000u32.to_be_bytes());
    png[20..24].copy_from_slice(&100_000u32.to_be_bytes());
    let crc = crc32(&png[12..29]);
    png[29..33].copy_from_slice(&crc.to_be_bytes());
    std::fs::write(dir.join("big.png"), &png).unwrap();
    let path = external_files_scene(&dir, "big.gltf", "ok.bin", "big.png");
    let t = Instant::now();
    let s = within_10s("huge PNG", move || load(&path));
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    assert!(s.textures.is_empty());
    assert!(
        s.warnings.iter().any(|w| w.contains("big.png")
            && w.contains("100000×100000")
            && w.contains("16384")
            && w.contains("painted")),
        "{:?}",
        s.warnings
    );
    // The same image as a data URI: the warning names the image and the problem.
    let path = triangle_file(
        &dir,
        "big-data.gltf",
        |g| {
            g.images
                .push(json!({"uri": format!("data:image/png;base64,{}",
                facet_render::scene::data_uri::encode_base64(&png))}));
            g.textures.push(json!({"source": 0}));
            let m = g.material(json!({"name": "m", "emissiveTexture": {"index": 0}}));
            g.meshes[0]["primitives"][0]["material"] = json!(m);
        },
        |_| {},
    );
    let s = load(&path);
    assert!(
        s.warnings
            .iter()
            .any(|w| w.contains("image 0") && w.contains("100000×100000")),
        "{:?}",
        s.warnings
    );
}

#[test]
fn a_scene_without_triangles_says_why() {
    let dir = temp_dir("why-empty");
    let path = triangle_file(
        &dir,
        "lines.gltf",
        |g| {
            g.meshes[0]["primitives"][0]["mode"] = json!(1);
            // A mesh whose only triangle has zero area.
            let flat = g.vec3s(&[[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 2.0, 0.0]]);
            g.meshes
                .push(json!({"name": "bare", "primitives": [{"attributes": {"POSITION": flat}}]}));
            let n = g.node(json!({"mesh": 1}));
            g.nodes[0]["children"] = json!([n]);
        },
        |_| {},
    );
    match load_gltf(&path, &LoadOptions::default()) {
        Err(RenderError::Scene(m)) => has_all(
            &m,
            &[
                "lines.gltf",
                "no triangles",
                "mesh `floor`: primitive 0 has mode Lines, not Triangles; skipped",
                "mesh `bare`: dropped 1 triangle(s) with zero area",
            ],
        ),
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_lights_are_skipped_with_a_warning() {
    let dir = temp_dir("lights");
    let path = triangle_file(
        &dir,
        "lights.gltf",
        |g| {
            g.extensions_used.push("KHR_lights_punctual");
            g.lights.push(json!({"type": "point", "intensity": -5.0}));
            g.lights.push(
                json!({"type": "spot", "spot": {"innerConeAngle": 1.0, "outerConeAngle": 0.5}}),
            );
            g.lights.push(json!({"type": "point", "intensity": 2.0}));
            let a = g.node(json!({"extensions": {"KHR_lights_punctual": {"light": 0}}}));
            let b = g.node(json!({"extensions": {"KHR_lights_punctual": {"light": 1}}}));
            let c = g.node(json!({"extensions": {"KHR_lights_punctual": {"light": 2}}}));
            g.nodes[0]["children"] = json!([a, b, c]);
        },
        |_| {},
    );
    let s = load(&path);
    assert_eq!(s.lights.len(), 1);
    for (light, word) in [("light 0", "intensity -5"), ("light 1", "cone angles")] {
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains(light) && w.contains(word)),
            "{light}: {:?}",
            s.warnings
        );
    }
}

#[test]
fn glb_headers_and_in_memory_loads() {
    let dir = temp_dir("glb-header");
    let path = dir.join("mem.glb");
    for (bytes, word) in [
        (&b"glTF\x02\0\0\0\x04\0\0\0"[..], "length 4"),
        (&b"glTF\x02\0\0\0"[..], "12-byte header"),
        (&b"glTF\x01\0\0\0\x20\0\0\0"[..], "version 1"),
        (&b"glTF\x02\0\0\0\xff\xff\xff\xff"[..], "truncated"),
    ] {
        let e = load_gltf_bytes(&path, bytes, &LoadOptions::default())
            .unwrap_err()
            .to_string();
        has_all(&e, &["mem.glb", word]);
    }
    // A GLB whose buffer 1 claims the binary chunk too.
    let mut g = GltfBuilder::default();
    let (p, _, i) = g.triangle();
    let mesh = g.mesh("tri", json!({"POSITION": p}), Some(i), None);
    let root = g.node(json!({"mesh": mesh}));
    let mut doc = g.finish(&[root]);
    doc["buffers"] = json!([{"byteLength": g.bin.len()}, {"byteLength": 4}]);
    let text = serde_json::to_vec(&doc).unwrap();
    let e = load_gltf_bytes(Path::new("x.gltf"), &text, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    has_all(&e, &["x.gltf", "buffer 0", "no GLB binary chunk"]);
}
