//! Hostile input, one test per class (issue: a clean clone passes its tests; hostile input gets
//! a clear error and harms nothing). Inputs are built here; every case asserts no panic, a
//! message naming the file and the field at fault, and that nothing outside `--out` is written
//! and no input is replaced. The scene loaders' classes are in `crates/render/tests`.

mod common;

use common::scratch;
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::material::FittedMaterial;
use facet_fit::model::merl_grid::MerlTable;
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Runs `facet` with `args` in `cwd`, XDG_RUNTIME_DIR and FACET_NBRDF removed, killing it after
/// `limit`: (success, stdout, stderr).
fn facet_in(cwd: &Path, args: &[&str], limit: Duration) -> (bool, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_facet"))
        .args(args)
        .current_dir(cwd)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("FACET_NBRDF")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            child.kill().unwrap();
            panic!("facet {args:?} still ran after {limit:?} (a hang)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().unwrap();
    let s = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.success(), s(&out.stdout), s(&out.stderr))
}

/// [`facet_in`] a folder under the target tmp dir (shared, never emptied while tests run), not
/// the repository: an output written by default (`out/`) when an argument check fails to
/// refuse lands there, not in the checkout.
fn facet(args: &[&str]) -> (bool, String, String) {
    let cwd = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("hostile-cwd");
    std::fs::create_dir_all(&cwd).unwrap();
    facet_in(&cwd, args, Duration::from_secs(120))
}

/// Every file under `dir`, recursively.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files_under(&p));
        } else {
            out.push(p);
        }
    }
    out.sort();
    out
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

/// `f` on a thread; fails the test if it has not returned after 10 s.
fn within_10s<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(10))
        .unwrap_or_else(|_| panic!("{what}: no answer within 10 s (blocked)"))
}

#[test]
fn special_files_are_refused_at_once() {
    let dir = scratch("hostile_special");
    let fifo = dir.join("pipe.binary");
    mkfifo(&fifo);
    let json_fifo = dir.join("pipe.json");
    mkfifo(&json_fifo);
    let f = fifo.clone();
    let merl = within_10s("MERL FIFO", move || {
        MerlTable::read(&f).unwrap_err().to_string()
    });
    assert!(
        merl.contains("pipe.binary") && merl.contains("is a FIFO"),
        "{merl}"
    );
    let f = json_fifo.clone();
    let fit = within_10s("fit JSON FIFO", move || {
        FittedMaterial::load(&f).unwrap_err().to_string()
    });
    assert!(
        fit.contains("pipe.json") && fit.contains("is a FIFO"),
        "{fit}"
    );
    let f = json_fifo.clone();
    let lib = within_10s("nbrdf FIFO", move || {
        NbrdfLibrary::open(&f).err().unwrap().to_string()
    });
    assert!(
        lib.contains("pipe.json") && lib.contains("is a FIFO"),
        "{lib}"
    );
    for d in [
        MerlTable::read(&dir).unwrap_err().to_string(),
        FittedMaterial::load(&dir).unwrap_err().to_string(),
        NbrdfLibrary::open(&dir).err().unwrap().to_string(),
    ] {
        assert!(
            d.contains("hostile_special") && d.contains("is a directory"),
            "{d}"
        );
    }
    let dev = MerlTable::read(Path::new("/dev/zero"))
        .unwrap_err()
        .to_string();
    assert!(
        dev.contains("/dev/zero") && dev.contains("is a device"),
        "{dev}"
    );
    // The CLI under a timeout: each input kind and --nbrdf.
    let (fifo_s, json_s) = (fifo.to_str().unwrap(), json_fifo.to_str().unwrap());
    let out = dir.join("out");
    let out_s = out.to_str().unwrap();
    let limit = Duration::from_secs(30);
    for args in [
        vec!["fit", fifo_s, "--backend", "cpu", "--out", out_s],
        vec!["fit", json_s, "--backend", "cpu", "--out", out_s],
        vec![
            "fit",
            "nbrdf:alum-bronze",
            "--nbrdf",
            json_s,
            "--backend",
            "cpu",
            "--out",
            out_s,
        ],
        vec![
            "dpf",
            "--ndf",
            json_s,
            "--gamma",
            "5",
            "--theta-o",
            "30",
            "--theta-i",
            "30",
            "--dphi",
            "180",
            "--backend",
            "cpu",
        ],
    ] {
        let (ok, _, err) = facet_in(&dir, &args, limit);
        assert!(!ok && err.contains("is a FIFO"), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn sizes_declared_by_files_are_checked() {
    let dir = scratch("hostile_sizes");
    let fit = facet_fit::fitting::fit_material(
        &common::merl_from_spec("ggx?alpha=0.3"),
        "t",
        &facet_fit::FitConfig::isotropic(),
    )
    .unwrap();
    let good = serde_json::to_value(&fit.record).unwrap();
    // nu · nphi overflows usize and wraps to the table's length in a release build.
    for (nu, nphi) in [(1usize << 63, 2usize), (usize::MAX, 1), (3, usize::MAX / 2)] {
        let mut v = good.clone();
        v["tabulated"]["tables"]["nu"] = nu.into();
        v["tabulated"]["tables"]["nphi"] = nphi.into();
        let path = dir.join("wrapped.json");
        std::fs::write(&path, v.to_string()).unwrap();
        let err = FittedMaterial::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("wrapped.json") && err.contains("do not match nu · nphi"),
            "{err}"
        );
    }
    // A MERL header announcing the largest dimensions: refused by size, nothing allocated.
    let mut header = Vec::new();
    for _ in 0..3 {
        header.extend(i32::MAX.to_le_bytes());
    }
    header.extend([0u8; 64]);
    let path = dir.join("huge.binary");
    std::fs::write(&path, &header).unwrap();
    let err = MerlTable::read(&path).unwrap_err().to_string();
    assert!(
        err.contains("huge.binary") && err.contains("truncated"),
        "{err}"
    );
}

#[test]
fn values_that_would_break_the_extraction_are_refused_up_front() {
    let dir = scratch("hostile_values");
    // All samples 1e308: a finite file whose sums overflow.
    let mut bytes = Vec::new();
    for d in [90i32, 90, 180] {
        bytes.extend(d.to_le_bytes());
    }
    for _ in 0..3 * facet_fit::model::merl_grid::SAMPLES {
        bytes.extend(1e308f64.to_le_bytes());
    }
    let path = dir.join("huge-values.binary");
    std::fs::write(&path, &bytes).unwrap();
    let err = MerlTable::read(&path).unwrap_err().to_string();
    assert!(
        err.contains("huge-values.binary") && err.contains("is 1e308, above the 1e12"),
        "{err}"
    );
    // A source whose f_r cos θi passes MAX_X on the MERL grid is refused with the value.
    let mut t = MerlTable::sample(&parse_analytic("ggx?alpha=0.3").unwrap());
    (0..facet_fit::model::merl_grid::SAMPLES).for_each(|s| t.scale_sample(s, [1e13; 3]));
    let err = facet_fit::fitting::fit_material(
        &MerlBrdf::from_table("bright", t).unwrap(),
        "t",
        &facet_fit::FitConfig::isotropic(),
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("bright") && err.contains("outside"), "{err}");
}

#[test]
fn analytic_specs_are_checked_key_by_key() {
    for (spec, needle) in [
        (
            "ggx?alpha=1e-300",
            "`alpha=1e-300`: α must lie in [1e-4, 10]",
        ),
        ("ggx?alpha=inf", "`alpha=inf`: not a finite number"),
        ("ggx?alpha=nan", "`alpha=nan`: not a finite number"),
        ("ggx?alpha_x=0.2&alpha_y=0", "`alpha_y=0`: α must lie"),
        ("ggx?alpha=0.2&f0=1.5", "`f0=1.5`: f0 must lie in [0, 1]"),
        (
            "ggx?alpha=0.2&f0=0.5,0.5,-0.1",
            "`f0=0.5,0.5,-0.1`: f0 must lie",
        ),
        ("ggx?alpha=0.2&kd=1.2", "`kd=1.2`: kd must lie in [0, 1]"),
        ("ggx?alpha=0.2&ior=0", "`ior=0`: ior must lie"),
        ("ggx?alpha=0.2&eta=1,1,1&k=-1", "`k=-1`: k must lie"),
        ("ggx?alpha=0.2&rotation=1e9", "`rotation=1e9`"),
        ("ggx?alpha=0.2&alpha=0.3", "`alpha` is given twice"),
        (
            "ggx?alpha=0.2&alpha_x=0.3",
            "`alpha` and `alpha_x` set the same property",
        ),
        (
            "ggx?alpha=0.2&f0=0.04&ior=1.5",
            "`f0` and `ior` set the same property",
        ),
        (
            "ggx?alpha=0.2&conductor=gold&eta=1,1,1&k=1,1,1",
            "`conductor` and `eta`",
        ),
    ] {
        let err = parse_analytic(spec).err().unwrap().to_string();
        assert!(
            err.contains(&format!("analytic:{spec}")) && err.contains(needle),
            "{spec}: {err}"
        );
    }
    // The edges of each range are accepted.
    for spec in [
        "ggx?alpha=1e-4&f0=0",
        "beckmann?alpha=10&f0=1&kd=1",
        "ggx?alpha_x=0.1&alpha_y=0.3&rotation=-45&eta=0.2,0.4,1.1&k=3,2.5,2",
    ] {
        parse_analytic(spec).unwrap();
    }
}

#[test]
fn cli_bounds_name_the_argument() {
    for (args, needle) in [
        (
            vec![
                "fit",
                "analytic:ggx?alpha=0.2",
                "--aniso",
                "--resolution",
                "4096",
                "--phi-resolution",
                "1024",
            ],
            "--resolution 4096 × --phi-resolution 1024",
        ),
        (
            vec!["fit", "analytic:ggx?alpha=0.2", "--iterations", "0"],
            "--iterations",
        ),
        (
            vec!["fit", "analytic:ggx?alpha=0.2", "--iterations", "100000000"],
            "--iterations",
        ),
        (
            vec!["fit", "analytic:ggx?alpha=0.2", "--tolerance", "nan"],
            "--tolerance",
        ),
        (
            vec!["fit", "analytic:ggx?alpha=0.2", "--resolution", "-3"],
            "--resolution",
        ),
        (vec!["render", "x.gltf", "--exposure", "nan"], "--exposure"),
        (
            vec!["render", "x.gltf", "--time-limit", "nan"],
            "--time-limit",
        ),
        (
            vec!["render", "x.gltf", "--time-limit", "-1"],
            "positive number of seconds",
        ),
        (vec!["render", "x.gltf", "--spp", "-1"], "--spp"),
        (vec!["render", "x.gltf", "--width", "100000"], "--width"),
        (vec!["render", "x.gltf", "--wavefront", "1"], "--wavefront"),
        (
            vec![
                "render", "x.gltf", "--width", "16384", "--height", "16384", "--spp", "1048576",
            ],
            "--width 16384 × --height 16384 × --spp 1048576",
        ),
        (vec!["demo", "--spp", "0"], "--spp"),
        (
            vec!["dpf", "--ndf", "analytic:ggx?alpha=0.2", "--gamma", "nan"],
            "--gamma",
        ),
    ] {
        let (ok, _, err) = facet(&args);
        assert!(!ok, "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("-- -"), "{args:?} suggests `-- -N`: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    // A negative exposure is a value: the run gets past the arguments to the missing scene.
    let (ok, _, err) = facet(&["render", "no-such.gltf", "--exposure", "-2"]);
    assert!(
        !ok && err.contains("no-such.gltf") && err.contains("no such file"),
        "{err}"
    );
}

#[test]
fn outputs_stay_inside_out_and_never_replace_an_input() {
    let root = scratch("hostile_outputs");
    let out = root.join("out");
    let out_s = out.to_str().unwrap();
    // A fit JSON whose name climbs out of --out, and a proxy library whose key does.
    let fit = facet_fit::fitting::fit_material(
        &common::merl_from_spec("ggx?alpha=0.3"),
        "t",
        &facet_fit::FitConfig::isotropic(),
    )
    .unwrap();
    let mut record = fit.record.clone();
    record.name = "../../escaped".into();
    let climbing = root.join("climbing.json");
    std::fs::write(&climbing, serde_json::to_string(&record).unwrap()).unwrap();
    let lib: serde_json::Value =
        serde_json::from_str(include_str!("../crates/brdf/data/nbrdf/merl100.json")).unwrap();
    let evil = serde_json::json!({ "/tmp/evil": lib["alum-bronze"], "..": lib["alum-bronze"] });
    let nbrdf = root.join("evil-lib.json");
    std::fs::write(&nbrdf, evil.to_string()).unwrap();
    let (ok, stdout, err) = facet(&[
        "fit",
        climbing.to_str().unwrap(),
        "nbrdf:/tmp/evil",
        "nbrdf:..",
        "--nbrdf",
        nbrdf.to_str().unwrap(),
        "--model",
        "tabulated",
        "--backend",
        "cpu",
        "--out",
        out_s,
    ]);
    assert!(ok, "{stdout}\n{err}");
    let written = files_under(&root);
    let names: Vec<String> = written
        .iter()
        .map(|p| p.strip_prefix(&root).unwrap().display().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "climbing.json",
            "evil-lib.json",
            "out/__.json",
            "out/__.tables.csv",
            "out/___.._escaped.json",
            "out/___.._escaped.tables.csv",
            "out/_tmp_evil.json",
            "out/_tmp_evil.tables.csv",
            "out/summary.csv",
        ],
        "{stdout}"
    );
    assert!(!Path::new("/tmp/evil.json").exists());
    // An input inside --out with the output's name: refused before the first write, untouched.
    let inside = out.join("___.._escaped.json");
    let before = std::fs::read(&inside).unwrap();
    let (ok, _, err) = facet(&[
        "fit",
        inside.to_str().unwrap(),
        "--backend",
        "cpu",
        "--out",
        out_s,
    ]);
    assert!(!ok && err.contains("would replace the input"), "{err}");
    assert_eq!(std::fs::read(&inside).unwrap(), before);
    // Two inputs with one name get distinct files.
    let (ok, _, err) = facet(&[
        "fit",
        "analytic:ggx?alpha=0.2",
        "analytic:ggx?alpha=0.2",
        "--model",
        "tabulated",
        "--backend",
        "cpu",
        "--out",
        root.join("twice").to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(root.join("twice/analytic-ggx_alpha_0.2-2.json").exists());
}

#[test]
fn a_cpu_fit_prints_nothing_but_its_own_notices() {
    let (ok, stdout, err) = facet(&[
        "fit",
        "analytic:ggx?alpha=0.2",
        "--backend",
        "cpu",
        "--out",
        scratch("hostile_quiet").to_str().unwrap(),
    ]);
    assert!(ok, "{stdout}\n{err}");
    assert!(
        err.lines()
            .all(|l| l.starts_with("notice: ") || l.starts_with("warning: ")),
        "stderr holds more than Facet's notices:\n{err}"
    );
    assert!(
        err.is_empty(),
        "a CPU fit has nothing to say on stderr:\n{err}"
    );
}

#[test]
fn proxies_are_found_from_any_folder() {
    let empty = scratch("hostile_elsewhere");
    let (ok, stdout, err) = facet_in(
        &empty,
        &[
            "fit",
            "nbrdf:gold-metallic-paint",
            "--model",
            "tabulated",
            "--backend",
            "cpu",
        ],
        Duration::from_secs(120),
    );
    assert!(ok, "{stdout}\n{err}");
    assert!(
        empty.join("out/gold-metallic-paint.json").exists(),
        "{stdout}"
    );
    assert!(err.is_empty(), "{err}");
}

/// A one-triangle glTF whose material has a base-colour texture `tex.png` beside it.
fn textured_triangle(dir: &Path) -> PathBuf {
    let mut bin = Vec::new();
    for v in [[0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        v.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    for v in [[0f32, 0.0], [1.0, 0.0], [0.0, 1.0]] {
        v.iter().for_each(|x| bin.extend(x.to_le_bytes()));
    }
    let b64 = facet_render::scene::data_uri::encode_base64(&bin);
    let gltf = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{b64}")}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
        ],
        "images": [{"uri": "tex.png"}],
        "textures": [{"source": 0}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let path = dir.join("tri.gltf");
    std::fs::write(&path, gltf.to_string()).unwrap();
    image::save_buffer(
        dir.join("tex.png"),
        &[255u8, 0, 0, 255],
        1,
        1,
        image::ExtendedColorType::Rgba8,
    )
    .unwrap();
    path
}

#[test]
fn a_render_never_replaces_a_file_its_scene_reads() {
    let dir = scratch("hostile_render_outputs");
    let scene = textured_triangle(&dir);
    let tex = dir.join("tex.png");
    let before = std::fs::read(&tex).unwrap();
    let (ok, _, err) = facet(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        tex.to_str().unwrap(),
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
    ]);
    assert!(!ok, "rendering over the scene's texture succeeded");
    assert!(
        err.contains("would replace the input") && err.contains("tex.png"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(&tex).unwrap(),
        before,
        "the texture was replaced"
    );
    assert!(!dir.join("tex.exr").exists());
}

/// `facet fit` maps MERL files ([`MerlTable::map`]): every bad file gets the error a read gets,
/// word for word (the mapped path only takes standard files and hands the rest to the reader).
#[test]
fn a_mapped_merl_file_is_refused_as_a_read_one() {
    let dir = scratch("hostile_mapped");
    let header = |dims: [i32; 3]| {
        dims.iter()
            .flat_map(|d| d.to_le_bytes())
            .collect::<Vec<_>>()
    };
    let standard = |value: f64| {
        let mut b = header([90, 90, 180]);
        for _ in 0..3 * facet_fit::model::merl_grid::SAMPLES {
            b.extend(value.to_le_bytes());
        }
        b
    };
    let mut nan_at_end = standard(1.0);
    let n = nan_at_end.len();
    nan_at_end[n - 8..].copy_from_slice(&f64::NAN.to_le_bytes());
    let mut cases: Vec<(&str, Vec<u8>)> = vec![
        ("empty.binary", Vec::new()),
        ("short-header.binary", vec![90, 0, 0]),
        ("huge-values.binary", standard(1e308)),
        ("nan-last.binary", nan_at_end),
        ("small-dims.binary", header([1, 1, 1])),
    ];
    let mut swapped = standard(1.0);
    swapped[..12].copy_from_slice(&header([180, 90, 90]));
    cases.push(("swapped-dims.binary", swapped));
    let mut long = standard(1.0);
    long.push(0);
    cases.push(("one-byte-long.binary", long));
    for (name, bytes) in cases {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).unwrap();
        let read = MerlTable::read(&path).unwrap_err().to_string();
        let mapped = MerlTable::map(&path).unwrap_err().to_string();
        assert_eq!(mapped, read, "{name}");
        assert!(read.contains(name), "{read}");
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{name} changed");
    }
    for special in [dir.clone(), PathBuf::from("/dev/zero")] {
        let read = MerlTable::read(&special).unwrap_err().to_string();
        assert_eq!(MerlTable::map(&special).unwrap_err().to_string(), read);
    }
}
