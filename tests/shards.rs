//! Renders split into shards (`facet render --samples A..B`) and joined (`facet merge`): the
//! union of disjoint shards is the one render of all their samples, and parts that do not belong
//! together are refused before anything is written.

mod common;

use facet_render::Image;
use facet_render::output::shard::{PixelKind, ShardRecord};
use std::path::{Path, PathBuf};

/// The render of the test scene: 48 × 27 pixels, `samples` ("A..B") or `--spp N`, with
/// `--variance`, into `out`; any `extra` options. The GGX sphere takes a copy of the scene's fit
/// (`ggx_fit.json`), so that the scene reads several files (which it lists in no fixed order:
/// the digest must not depend on it).
fn render(dir: &Path, scene: &Path, samples: &[&str], out: &str, extra: &[&str]) {
    let sky = dir.join("sky.exr");
    let ggx_fit = dir.join("ggx_fit.json");
    if !ggx_fit.exists() {
        std::fs::copy(dir.join("default_fit.json"), &ggx_fit).unwrap();
    }
    let ggx = format!("ggx={}", ggx_fit.display());
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--material",
        &ggx,
        "--env",
        sky.to_str().unwrap(),
        "--width",
        "48",
        "--height",
        "27",
        "--variance",
        "--out",
        out,
    ];
    args.extend(samples);
    args.extend(extra);
    let (ok, stdout, err) = common::facet_in(dir, &args);
    assert!(ok, "{args:?}: {stdout}\n{err}");
}

fn merge(dir: &Path, args: &[&str]) -> (bool, String, String) {
    let mut all = vec!["merge"];
    all.extend(args);
    common::facet_in(dir, &all)
}

fn read(path: PathBuf) -> (Image, ShardRecord) {
    Image::read_shard_exr(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// The demo with glints (1000× fewer flakes, so that lavapipe repeats it bit for bit: see
/// `common::reproducible_demo_copy`) and its full render at 8 spp.
fn scene_and_full_render(dir: &Path) -> PathBuf {
    let scene = common::reproducible_demo_copy(dir);
    render(dir, &scene, &["--spp", "8"], "full/r.png", &[]);
    scene
}

/// Four shards of 2 spp, merged in a shuffled order, are the 8 spp render: each pixel's mean
/// equal within the f32 rounding of the sums (each shard's sum and the full render's sum are
/// rounded at every add, ≤ 8 adds of relative error 2⁻²⁴: 1e-6 relative, kept at 4e-6), and its
/// variance within the rounding of Σ L² that both compute it from (relative to Σ L² / (n (n − 1)),
/// the size of the terms that cancel).
#[test]
fn four_shards_merge_to_the_one_render() {
    if facet_gpu::gpu_for_tests("four_shards_merge_to_the_one_render").is_none() {
        return;
    }
    let dir = common::scratch("shards_merge");
    let scene = scene_and_full_render(&dir);
    for (k, s) in ["0..2", "2..4", "4..6", "6..8"].iter().enumerate() {
        render(
            &dir,
            &scene,
            &["--samples", s],
            &format!("part{k}/r.png"),
            &[],
        );
    }
    let (ok, stdout, err) = merge(
        &dir,
        &[
            "part2/r.exr",
            "part0/r.exr",
            "part3/r.exr",
            "part1/r.exr",
            "--variance",
            "--out",
            "merged/m.png",
        ],
    );
    assert!(ok, "{stdout}\n{err}");
    assert!(stdout.contains("samples 0..8 (8 spp)"), "{stdout}");
    assert!(err.is_empty(), "a full cover gives no notice: {err}");
    assert!(dir.join("merged/m.png").exists());
    let (_, full_rec) = read(dir.join("full/r.exr"));
    let (_, merged_rec) = read(dir.join("merged/m.exr"));
    assert_eq!(
        merged_rec, full_rec,
        "the merged record is the full render's"
    );
    assert_eq!(full_rec.samples, vec![[0, 8]]);
    let (_, var_rec) = read(dir.join("merged/m.variance.exr"));
    assert_eq!(var_rec.pixels, PixelKind::VarianceOfMean);
    let (mean, var, noisy) =
        common::render_differences(&dir.join("full/r.exr"), &dir.join("merged/m.exr"), 8.0);
    assert!(mean <= 4e-6, "mean: worst relative difference {mean:e}");
    assert!(var <= 2e-5, "variance: worst relative difference {var:e}");
    assert!(noisy > 0, "the scene has noisy (glint) pixels");
    println!("worst relative difference: mean {mean:e}, variance {var:e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// A part of another seed, size, scene or range overlapping another, a variance image given as
/// a part, an EXR that Facet did not render, a missing variance and an output over a part are
/// each refused, naming the part; nothing is written.
#[test]
fn parts_that_do_not_belong_together_are_refused() {
    if facet_gpu::gpu_for_tests("parts_that_do_not_belong_together_are_refused").is_none() {
        return;
    }
    let dir = common::scratch("shards_refused");
    let scene = common::reproducible_demo_copy(&dir);
    render(&dir, &scene, &["--samples", "0..2"], "a/r.png", &[]);
    render(&dir, &scene, &["--samples", "1..3"], "overlap/r.png", &[]);
    render(
        &dir,
        &scene,
        &["--samples", "2..4"],
        "seed/r.png",
        &["--seed", "7"],
    );
    render(
        &dir,
        &scene,
        &["--samples", "2..4"],
        "depth/r.png",
        &["--max-depth", "2"],
    );
    let sky = dir.join("sky.exr");
    let (ok, _, err) = common::facet_in(
        &dir,
        &[
            "render",
            scene.to_str().unwrap(),
            "--env",
            sky.to_str().unwrap(),
            "--width",
            "40",
            "--height",
            "27",
            "--samples",
            "2..4",
            "--out",
            "size/r.png",
        ],
    );
    assert!(ok, "{err}");
    std::fs::create_dir_all(dir.join("novar")).unwrap();
    std::fs::copy(dir.join("a/r.exr"), dir.join("novar/r.exr")).unwrap();
    let cases: [(&[&str], &str, &str); 9] = [
        (
            &["a/r.exr", "overlap/r.exr"],
            "overlap/r.exr",
            "overlap the samples 0..2",
        ),
        (&["a/r.exr", "a/r.exr"], "a/r.exr", "overlap"),
        (&["a/r.exr", "seed/r.exr"], "seed/r.exr", "another seed (7)"),
        (
            &["a/r.exr", "depth/r.exr"],
            "depth/r.exr",
            "another scene or settings",
        ),
        (&["a/r.exr", "size/r.exr"], "size/r.exr", "40 × 27 pixels"),
        (
            &["a/r.exr", "a/r.variance.exr"],
            "a/r.variance.exr",
            "a variance image",
        ),
        (&["a/r.exr", "sky.exr"], "sky.exr", "no \"facet\" attribute"),
        (
            &["a/r.exr", "novar/r.exr", "--variance"],
            "novar/r.exr",
            "no novar/r.variance.exr",
        ),
        (
            &["a/r.exr", "--out", "a/r.png"],
            "a/r.exr",
            "would replace the part",
        ),
    ];
    for (args, part, problem) in cases {
        let mut all = args.to_vec();
        if !all.contains(&"--out") {
            all.extend(["--out", "merged/m.png"]);
        }
        let (ok, stdout, err) = merge(&dir, &all);
        assert!(!ok, "{args:?} merged: {stdout}");
        assert!(
            err.contains(part) && err.contains(problem),
            "{args:?}: the message should name {part} and say {problem:?}: {err}"
        );
        assert!(!dir.join("merged").exists(), "{args:?} wrote something");
    }
    // Samples not from 0 are not an error: the union is an estimate of fewer samples, said in
    // a notice.
    let (ok, stdout, err) = merge(&dir, &["overlap/r.exr", "--out", "gap/m.png"]);
    assert!(ok, "{err}");
    assert!(stdout.contains("samples 1..3 (2 spp)"), "{stdout}");
    assert!(
        err.contains("notice: the parts hold the samples 1..3 only"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[path = "../crates/render/tests/common/mod.rs"]
mod render_common;

/// A triangle whose base colour texture `tex.png` is beside the glTF and whose normal map
/// `nope.png` is missing, seen by a camera at z = 2.
fn textured_triangle(dir: &Path) -> PathBuf {
    let mut g = render_common::GltfBuilder::default();
    let (p, n, i) = g.triangle();
    g.images.push(serde_json::json!({"uri": "tex.png"}));
    g.images.push(serde_json::json!({"uri": "nope.png"}));
    g.textures.push(serde_json::json!({"source": 0}));
    g.textures.push(serde_json::json!({"source": 1}));
    let m = g.material(serde_json::json!({
        "name": "painted",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
        "normalTexture": {"index": 1}
    }));
    let mesh = g.mesh(
        "tri",
        serde_json::json!({"POSITION": p, "NORMAL": n}),
        Some(i),
        Some(m),
    );
    g.cameras.push(
        serde_json::json!({"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}),
    );
    let tri = g.node(serde_json::json!({"mesh": mesh}));
    let cam = g.node(serde_json::json!({"camera": 0, "translation": [0.3, 0.3, 2.0]}));
    let scene = dir.join("tri.gltf");
    g.write(&[tri, cam], &scene);
    write_png(&dir.join("tex.png"), [200, 40, 40]);
    scene
}

fn write_png(path: &Path, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(2, 2, image::Rgb(rgb))
        .save(path)
        .unwrap();
}

/// A scene whose texture is missing renders a shard (with the warning, the factor alone): the
/// digest is made of the bytes the load read, not of the files read again. It is the same for
/// the same files, and changes when a file's bytes change or the missing texture appears.
#[test]
fn a_scene_with_a_missing_texture_renders_a_shard() {
    if facet_gpu::gpu_for_tests("a_scene_with_a_missing_texture_renders_a_shard").is_none() {
        return;
    }
    let dir = common::scratch("shards_missing_texture");
    let scene = textured_triangle(&dir);
    let shard = |out: &str| {
        let args = [
            "render",
            scene.to_str().unwrap(),
            "--env-color",
            "1",
            "--width",
            "16",
            "--height",
            "16",
            "--max-depth",
            "1",
            "--samples",
            "0..2",
            "--out",
            out,
        ];
        let (ok, stdout, err) = common::facet_in(&dir, &args);
        assert!(ok, "{args:?}: {stdout}\n{err}");
        (read(dir.join(out).with_extension("exr")).1.digest, err)
    };
    let (first, err) = shard("a/r.png");
    assert!(
        err.contains("nope.png") && err.contains("using the factor alone"),
        "{err}"
    );
    let (again, _) = shard("b/r.png");
    assert_eq!(again, first, "the same files, the same digest");
    write_png(&dir.join("tex.png"), [40, 200, 40]);
    let (recoloured, _) = shard("c/r.png");
    assert_ne!(recoloured, first, "tex.png's bytes changed");
    std::fs::copy(dir.join("tex.png"), dir.join("nope.png")).unwrap();
    let (found, err) = shard("d/r.png");
    assert!(!err.contains("nope.png"), "{err}");
    assert_ne!(found, recoloured, "the missing texture is there now");
    std::fs::remove_dir_all(&dir).ok();
}
