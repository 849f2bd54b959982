//! Seeded, bounded mutation test of every loader that reads outside input: MERL tables, fit
//! JSON, neural BRDF JSON, RGL `.bsdf` tensor files (RGB, spectral, anisotropic), glTF scenes
//! (JSON and `.glb`, buffers embedded) and OpenEXR environment maps.
//!
//! Each loader gets valid seed inputs, built here, and thousands of mutated versions of them:
//! bit flips, bytes and words overwritten with interesting values, truncations, insertions,
//! deletions and duplicated chunks, and for JSON also token-level mutations (numbers replaced
//! by −1, 0, 1e308, huge integers or NaN-ish strings, strings replaced, arrays and objects
//! emptied, repeated or shortened, values of another type). Every case runs under
//! `catch_unwind` on a worker thread that the test watches: it must return within
//! [`harness::CALL_BUDGET`], and either refuse the input with an error whose message names the path it
//! was given, or return a value that passes a sanity check (finite values, indices in range,
//! BRDFs finite and non-negative where evaluated).
//!
//! The PRNG is SplitMix64 with a fixed seed per loader, so a failure names a case (loader and
//! number) that a rerun makes again; the first input of each distinct failure is saved under
//! `CARGO_TARGET_TMPDIR/loader_mutation/`. `LOADER_MUTATION_SAVE=loader:case` saves that case's
//! input before the call (for a case that never returns); `LOADER_MUTATION_TRACE=1` prints each
//! case before its call (for a case that aborts the process, as a failed allocation does);
//! `LOADER_MUTATION_SCALE=N` runs N times the cases and `LOADER_MUTATION_SEED=S` other ones.
//!
//! The files: `harness` (PRNG, panic capture, the watched worker), `mutate` (byte and JSON
//! token mutations, the target of the byte loaders), one per loader (`merl`, `json`, `gltf`,
//! `exr`, `rgl`: seeds and checks); the sanity checks themselves are `facet_oracles`', shared
//! with the fuzz targets. This file: the seeds shared between loaders and the campaigns.

mod exr;
mod gltf;
mod harness;
mod json;
mod merl;
mod mutate;
mod rgl;

use crate::exr::{check_exr, tiny_exr};
use crate::gltf::{check_gltf, glb, small_scene};
use crate::harness::{campaign, save_dir};
use crate::json::{check_fit, check_nbrdf, nbrdf_entries};
use crate::merl::Merl;
use crate::mutate::{Bytes, Form, Seed};
use crate::rgl::{bsdf_seeds, check_bsdf};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::merl_grid::{MerlTable, SAMPLES};
use facet_fit::sources::merl::MerlBrdf;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

// ---------------------------------------------------------------------------------------------
// Seeds shared between loaders.

/// GGX α = 0.2 sampled on the MERL grid.
pub fn ggx_table() -> &'static MerlTable {
    static TABLE: OnceLock<MerlTable> = OnceLock::new();
    TABLE.get_or_init(|| MerlTable::sample(&parse_analytic("ggx?alpha=0.2").unwrap()))
}

/// The fit of [`ggx_table`], as JSON.
fn ggx_fit_json() -> &'static str {
    static FIT: OnceLock<String> = OnceLock::new();
    FIT.get_or_init(|| {
        let src = MerlBrdf::from_table("ggx-0.2", ggx_table().clone()).unwrap();
        let fit =
            facet_fit::fit_material(&src, "ggx-0.2", &facet_fit::FitConfig::isotropic()).unwrap();
        serde_json::to_string(&fit.record).unwrap()
    })
}

/// A path in the repository.
pub fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

// ---------------------------------------------------------------------------------------------
// The campaigns.

#[test]
fn merl_loader_survives_mutation() {
    campaign("merl", 0x4D45_524C, 600, || Merl::new("campaign"));
}

#[test]
fn fit_json_loader_survives_mutation() {
    campaign("fit_json", 0x4649_544A, 20000, || {
        let dir = save_dir();
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated-fit.json"),
                    form: Form::Json(ggx_fit_json().as_bytes().to_vec()),
                    weight: 3,
                },
                Seed {
                    path: dir.join("mutated-default-fit.json"),
                    form: Form::Json(std::fs::read(repo("assets/demo/default_fit.json")).unwrap()),
                    weight: 1,
                },
            ],
            check_fit,
        )
    });
}

#[test]
fn nbrdf_loader_survives_mutation() {
    campaign("nbrdf", 0x4E42_5244, 20000, || {
        let dir = save_dir();
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated-one.json"),
                    form: Form::Json(nbrdf_entries(1)),
                    weight: 3,
                },
                Seed {
                    path: dir.join("mutated-two.json"),
                    form: Form::Json(nbrdf_entries(2)),
                    weight: 1,
                },
            ],
            check_nbrdf,
        )
    });
}

#[test]
fn gltf_loader_survives_mutation() {
    campaign("gltf", 0x674C_5446, 20000, || {
        let dir = save_dir().join("gltf");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("fit.json"), ggx_fit_json()).unwrap();
        let (embedded, for_glb, bin) = small_scene("fit.json");
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated.gltf"),
                    form: Form::Json(embedded),
                    weight: 10,
                },
                Seed {
                    path: dir.join("mutated.glb"),
                    form: Form::Glb(for_glb, bin),
                    weight: 10,
                },
                Seed {
                    path: repo("assets/demo/demo.gltf"),
                    form: Form::Json(std::fs::read(repo("assets/demo/demo.gltf")).unwrap()),
                    weight: 1,
                },
            ],
            check_gltf,
        )
    });
}

#[test]
fn exr_loader_survives_mutation() {
    campaign("exr_env", 0x4558_5221, 20000, || {
        let dir = save_dir();
        Bytes::new(
            vec![
                Seed {
                    path: dir.join("mutated-tiny.exr"),
                    form: Form::Bytes(tiny_exr()),
                    weight: 1,
                },
                Seed {
                    path: dir.join("mutated-sky.exr"),
                    form: Form::Bytes(std::fs::read(repo("assets/demo/sky.exr")).unwrap()),
                    weight: 1,
                },
            ],
            check_exr,
        )
    });
}

#[test]
fn bsdf_loader_survives_mutation() {
    campaign("bsdf", 0x4253_4446, 20000, || {
        let dir = save_dir();
        Bytes::new(
            bsdf_seeds()
                .into_iter()
                .map(|(name, bytes)| Seed {
                    path: dir.join(format!("mutated-{name}.bsdf")),
                    form: Form::Bytes(bytes),
                    weight: 1,
                })
                .collect(),
            check_bsdf,
        )
    });
}

/// The seeds themselves load: a mutation test whose seeds are refused tests nothing.
#[test]
fn seeds_are_accepted() {
    let dir = save_dir().join("seeds");
    std::fs::create_dir_all(&dir).unwrap();
    let merl = Merl::new("seeds");
    assert!(MerlTable::parse(&merl.path, &merl.bytes).is_ok());
    check_fit(&dir.join("seed-fit.json"), ggx_fit_json().as_bytes()).unwrap();
    check_fit(
        &repo("assets/demo/default_fit.json"),
        &std::fs::read(repo("assets/demo/default_fit.json")).unwrap(),
    )
    .unwrap();
    assert!(check_nbrdf(&dir.join("seed-nbrdf.json"), &nbrdf_entries(2)).unwrap());
    std::fs::write(dir.join("fit.json"), ggx_fit_json()).unwrap();
    let (embedded, for_glb, bin) = small_scene("fit.json");
    assert!(check_gltf(&dir.join("seed.gltf"), &embedded).unwrap());
    assert!(check_gltf(&dir.join("seed.glb"), &glb(&for_glb, &bin)).unwrap());
    let demo = repo("assets/demo/demo.gltf");
    assert!(check_gltf(&demo, &std::fs::read(&demo).unwrap()).unwrap());
    assert!(check_exr(&dir.join("seed.exr"), &tiny_exr()).unwrap());
    let sky = repo("assets/demo/sky.exr");
    assert!(check_exr(&sky, &std::fs::read(&sky).unwrap()).unwrap());
    for (name, bytes) in bsdf_seeds() {
        assert!(
            check_bsdf(&dir.join(format!("seed-{name}.bsdf")), &bytes).unwrap(),
            "{name}"
        );
    }
}

/// The fuzz targets' seeds, `fuzz/corpus/<target>/seed-*`: (target, file name, bytes).
/// The `merl` target expands a short input (see `fuzz/fuzz_targets/merl.rs`): byte 0 bit 0
/// clear, byte 1 the length change, 12 bytes XORed into the header, 12-byte value records.
fn fuzz_seeds() -> Vec<(&'static str, &'static str, Vec<u8>)> {
    let record = |index: u32, v: f64| [index.to_le_bytes().as_slice(), &v.to_le_bytes()].concat();
    let expanded = |records: &[Vec<u8>]| [vec![0u8; 14], records.concat()].concat();
    let mut small = vec![1u8];
    small.extend([1i32, 1, 1].iter().flat_map(|d| d.to_le_bytes()));
    small.extend([0.5f64, 0.6, 0.7].iter().flat_map(|v| v.to_le_bytes()));
    // A fit of the demo's, its tables thinned (every 8th NDF node, every 16th G1 node, every
    // 9th Fresnel angle) to a few KB; still a valid fit.
    let mut fit: facet_fit::model::material::FitRecord =
        serde_json::from_slice(&std::fs::read(repo("assets/demo/default_fit.json")).unwrap())
            .unwrap();
    let every = |v: &[f64], k: usize| v.iter().step_by(k).copied().collect::<Vec<f64>>();
    let t = &mut fit.tabulated.tables;
    assert_eq!(t.nphi, 1);
    (t.d, t.g1) = (every(&t.d, 8), every(&t.g1, 16));
    (t.nu, t.ng) = (t.d.len(), t.g1.len());
    let thin = |f: &mut facet_fit::model::fresnel::FresnelTable| {
        f.theta_d = every(&f.theta_d, 9);
        f.rgb = f.rgb.iter().step_by(9).copied().collect();
    };
    thin(&mut fit.fresnel);
    fit.ggx
        .iter_mut()
        .chain(fit.beckmann.iter_mut())
        .for_each(|p| thin(&mut p.fresnel));
    let (embedded, for_glb, bin) = small_scene("default_fit.json");
    vec![
        ("merl", "seed-valid", vec![0]),
        (
            "merl",
            "seed-values",
            expanded(&[record(1000, 0.5), record(2 * SAMPLES as u32 + 5, -1.0)]),
        ),
        ("merl", "seed-small", small),
        (
            "fit_json",
            "seed-thinned-demo-fit.json",
            serde_json::to_vec(&fit).unwrap(),
        ),
        ("nbrdf", "seed-one.json", nbrdf_entries(1)),
        ("gltf", "seed-small.gltf", embedded),
        ("gltf", "seed-small.glb", glb(&for_glb, &bin)),
        ("exr_env", "seed-tiny.exr", tiny_exr()),
        (
            "exr_env",
            "seed-sky.exr",
            std::fs::read(repo("assets/demo/sky.exr")).unwrap(),
        ),
    ]
}

/// The fuzz seeds are accepted by their loaders, the committed ones as well as those built
/// here; `FACET_WRITE_FUZZ_SEEDS=1` (re)writes them under `fuzz/corpus/`.
#[test]
fn fuzz_seeds_are_accepted() {
    let corpus = repo("fuzz/corpus");
    // A glTF seed names `default_fit.json`: beside the demo scene, where the fuzzer's
    // scratch folder puts it too.
    let check = |target: &str, name: &str, bytes: &[u8]| match target {
        "fit_json" => assert!(check_fit(&corpus.join(name), bytes).unwrap(), "{name}"),
        "nbrdf" => assert!(check_nbrdf(&corpus.join(name), bytes).unwrap(), "{name}"),
        "gltf" => assert!(
            check_gltf(&repo("assets/demo").join(name), bytes).unwrap(),
            "{name}"
        ),
        "exr_env" => assert!(check_exr(&corpus.join(name), bytes).unwrap(), "{name}"),
        _ => {} // merl: its seeds are recipes, tried by the target
    };
    let write = std::env::var_os("FACET_WRITE_FUZZ_SEEDS").is_some();
    let mut total = 0;
    for (target, name, bytes) in fuzz_seeds() {
        check(target, name, &bytes);
        total += bytes.len();
        if write {
            std::fs::create_dir_all(corpus.join(target)).unwrap();
            std::fs::write(corpus.join(target).join(name), &bytes).unwrap();
        }
    }
    assert!(total < 100_000, "the seeds are {total} bytes");
    for dir in std::fs::read_dir(&corpus).into_iter().flatten() {
        let dir = dir.unwrap().path();
        let target = dir.file_name().unwrap().to_string_lossy().into_owned();
        for file in std::fs::read_dir(&dir).unwrap() {
            let file = file.unwrap().path();
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            if name.starts_with("seed-") {
                check(&target, &name, &std::fs::read(&file).unwrap());
            }
        }
    }
}
