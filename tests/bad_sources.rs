//! Sources too poor or too damaged to fit, refused where they enter: a MERL table with too few
//! valid samples, a fit JSON whose NDF is no distribution, an RGL `.bsdf` whose reflectance,
//! NDF or projected areas make no material. Each error names the file and the problem, in the
//! library and in every `facet` command that reads the file: never a panic, a NaN or a file
//! of zeros.

mod common;

use common::facet_in as facet;
use common::scratch;
use facet_fit::export::rgl::{BsdfResolution, rgl_tensor};
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::metric::grid::{GridSamples, microfacet_errors};
use facet_fit::model::analytic::parse_analytic;
use facet_fit::model::fresnel::Fresnel;
use facet_fit::model::geometry::from_half_diff;
use facet_fit::model::material::FittedMaterial;
use facet_fit::model::merl_grid::{
    MIN_VALID_SAMPLES, MerlTable, PHI_D_RES, SAMPLES, THETA_D_RES, bin_angles, index,
};
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::rgl::RglBsdf;
use facet_fit::sources::rgl::tensor_file::{TensorFile, TensorWriter};
use facet_fit::{Brdf, FitError, Rgb};
use glam::DVec3;
use std::path::{Path, PathBuf};

/// Asserts a refusal: the command failed, said `needles` and did not panic.
fn refused(what: &str, (ok, stdout, stderr): (bool, String, String), needles: &[&str]) {
    assert!(!ok, "{what} succeeded: {stdout}");
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{what}: `{n}` not in {stderr}");
    }
}

/// A MERL table whose only valid samples (f_r = 0.5 / 1500 a channel) are `bins`.
fn merl_with(bins: impl IntoIterator<Item = usize>) -> MerlTable {
    let mut values = vec![-1.0f64; 3 * SAMPLES];
    for s in bins {
        (0..3).for_each(|c| values[c * SAMPLES + s] = 0.5);
    }
    let mut bytes = Vec::with_capacity(12 + 24 * SAMPLES);
    for d in [90i32, 90, 180] {
        bytes.extend(d.to_le_bytes());
    }
    values.iter().for_each(|v| bytes.extend(v.to_le_bytes()));
    MerlTable::parse(Path::new("built.binary"), &bytes).unwrap()
}

/// The first `n` bins of θh bin 10 (θh = 1.1°) at θd bins 0, 1, …: all above the horizon,
/// the first 180 backscattering (θd = 0).
fn near_normal(n: usize) -> impl Iterator<Item = usize> {
    (0..n).map(|m| index(10, m / PHI_D_RES, m % PHI_D_RES))
}

#[test]
fn merl_tables_with_too_few_valid_samples_are_refused_with_their_count() {
    let dir = scratch("bad_sources_merl");
    for n in [1, 2, 10, MIN_VALID_SAMPLES - 1] {
        let table = merl_with(near_normal(n));
        let path = dir.join(format!("sparse{n}.binary"));
        table.write(&path).unwrap();
        let count = format!("{n} valid sample");
        let need = format!("at least {MIN_VALID_SAMPLES}");
        for e in [MerlBrdf::open(&path).err(), MerlBrdf::map(&path).err()] {
            let e = e.expect("a sparse file read as a source").to_string();
            assert!(
                e.contains(&format!("sparse{n}.binary")) && e.contains(&count) && e.contains(&need),
                "{e}"
            );
        }
        // An in-memory table, as the library makes one.
        let e = MerlBrdf::from_table("sparse", table).err().unwrap();
        assert!(e.contains(&count) && e.contains(&need), "{e}");
    }
    // Samples below the horizon are no samples of the fit: θh 88° and θd 89°, most φd.
    let below = (0..PHI_D_RES)
        .map(|k| index(89, THETA_D_RES - 1, k))
        .filter(|&s| {
            let (i, j, k) = (
                s / (PHI_D_RES * THETA_D_RES),
                s / PHI_D_RES % THETA_D_RES,
                s % PHI_D_RES,
            );
            let (wi, wo) = from_half_diff(bin_angles(i, j, k));
            wi.z <= 0.0 || wo.z <= 0.0
        });
    let e = MerlBrdf::from_table("below", merl_with(near_normal(10).chain(below)))
        .err()
        .unwrap();
    assert!(e.contains("10 valid samples above the horizon"), "{e}");
    // Nothing valid at all: the backscattering slice is named first, with the count.
    let e = MerlBrdf::from_table("none", merl_with([])).err().unwrap();
    assert!(
        e.contains("no valid backscattering sample") && e.contains("among its 0 valid samples"),
        "{e}"
    );
    assert!(MerlBrdf::from_table("enough", merl_with(near_normal(MIN_VALID_SAMPLES))).is_ok());
}

#[test]
fn facet_commands_refuse_a_sparse_merl_file_by_name() {
    let dir = scratch("bad_sources_merl_cli");
    let path = dir.join("one.binary");
    merl_with(near_normal(1)).write(&path).unwrap();
    let p = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let file = path.to_str().unwrap();
    let needles = ["one.binary", "1 valid sample", "at least 92"];
    refused(
        "fit",
        facet(
            &dir,
            &["fit", file, "--out", &p("fits"), "--backend", "cpu"],
        ),
        &needles,
    );
    for out in ["one.json", "two.binary", "three.bsdf"] {
        refused(
            "convert",
            facet(&dir, &["convert", file, &p(out)]),
            &needles,
        );
        assert!(!dir.join(out).exists(), "{out}");
    }
    let query = [
        "--gamma",
        "5",
        "--theta-o",
        "30",
        "--theta-i",
        "30",
        "--dphi",
        "180",
    ];
    let mut args = vec!["dpf", "--backend", "cpu", "--ndf", file];
    args.extend(query);
    refused("dpf", facet(&dir, &args), &needles);
}

#[test]
fn a_source_with_no_sample_on_the_final_rows_fits_without_a_panic() {
    // θh bin 10 at θd bins 0 and 1: rows 10 + 0 and 10 + 1, neither ≡ 0 mod 4, so the quarter
    // of the grid on which the final steps run (the diagonal of stride 4) holds no sample.
    let src = MerlBrdf::from_table("off-diagonal", merl_with(near_normal(2 * PHI_D_RES))).unwrap();
    let set = GridSamples::new(&src);
    assert_eq!(set.len(), 2 * PHI_D_RES);
    let empty = set.diagonal(4);
    assert!(empty.is_empty());
    // One error per Fresnel curve, on an empty set too.
    let model = parse_analytic("ggx?alpha=0.2&f0=0.04").unwrap();
    let curves = [
        Fresnel::Schlick { f0: [0.04; 3] },
        Fresnel::Schlick { f0: [0.9; 3] },
    ];
    assert_eq!(microfacet_errors(&model, &curves, &empty), vec![0.0, 0.0]);
    let fit = fit_material(&src, "off-diagonal", &FitConfig::isotropic()).unwrap();
    let r = &fit.record;
    for e in [r.tabulated.error, r.ggx.as_ref().map(|p| p.error)] {
        assert!(e.is_some_and(f64::is_finite), "{e:?}");
    }
}

/// An in-memory source holding a few samples of a GGX on the MERL grid, its backscattering
/// complete: the extraction runs, the fit must refuse it.
struct FewSamples {
    model: facet_fit::model::microfacet::MicrofacetBrdf,
    table: MerlTable,
}

impl Brdf for FewSamples {
    fn name(&self) -> &str {
        "few-samples"
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        self.table.lookup_nearest(wi, wo)
    }

    fn backscatter(&self, theta: f64, phi: f64) -> Option<Rgb> {
        self.model.backscatter(theta, phi)
    }

    fn merl_table(&self) -> std::borrow::Cow<'_, MerlTable> {
        std::borrow::Cow::Borrowed(&self.table)
    }
}

#[test]
fn a_library_source_with_few_grid_samples_is_refused_by_the_fit() {
    let src = FewSamples {
        model: parse_analytic("ggx?alpha=0.2&f0=0.04").unwrap(),
        table: merl_with(near_normal(40)),
    };
    match fit_material(&src, "few", &FitConfig::isotropic()) {
        Err(e @ FitError::Extraction { .. }) => {
            let e = e.to_string();
            assert!(
                e.contains("few-samples")
                    && e.contains("40 valid samples on the MERL grid")
                    && e.contains("at least 92"),
                "{e}"
            );
        }
        Err(e) => panic!("another error: {e}"),
        Ok(_) => panic!("a fit of 40 samples"),
    }
}

/// The demo's fit JSON with its tabulated D table mapped by `d`.
fn demo_fit_with(d: impl Fn(f64) -> f64) -> String {
    let demo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/demo/default_fit.json");
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(demo).unwrap()).unwrap();
    let table = v["tabulated"]["tables"]["d"].as_array_mut().unwrap();
    for x in table.iter_mut() {
        *x = d(x.as_f64().unwrap()).into();
    }
    v.to_string()
}

#[test]
fn fit_json_whose_ndf_is_no_distribution_is_refused_when_read() {
    let dir = scratch("bad_sources_ndf");
    for (name, d, problem) in [
        ("scaled", (|x| x * 1e38) as fn(f64) -> f64, "integrates to"),
        ("huge", |_| 1e300, "integrates to"),
        ("tiny", |x| x * 1e-3, "integrates to"),
        ("overflowing", |_| 1e308, "overflows"),
    ] {
        let path = dir.join(format!("{name}.json"));
        std::fs::write(&path, demo_fit_with(d)).unwrap();
        let Err(e) = FittedMaterial::load(&path) else {
            panic!("{name}.json read");
        };
        let e = e.to_string();
        assert!(
            e.contains(&format!("{name}.json"))
                && e.contains("tabulated.tables")
                && e.contains(problem),
            "{e}"
        );
    }
    // Within the table quadrature's slack: read.
    let path = dir.join("doubled.json");
    std::fs::write(&path, demo_fit_with(|x| 2.0 * x)).unwrap();
    let fit = FittedMaterial::load(&path).unwrap();
    let Some(facet_fit::model::microfacet::Ndf::Tabulated(t)) = fit
        .model(facet_fit::model::material::ModelChoice::Tabulated)
        .map(|m| &m.ndf)
    else {
        panic!("no tabulated NDF");
    };
    assert!(
        (t.projected_area() - 2.0).abs() < 0.01,
        "{}",
        t.projected_area()
    );
}

#[test]
fn dpf_and_render_refuse_such_a_fit_json_with_the_same_message() {
    let dir = scratch("bad_sources_ndf_cli");
    let path = dir.join("scaled.json");
    std::fs::write(&path, demo_fit_with(|x| x * 1e38)).unwrap();
    let file = path.to_str().unwrap();
    let needles = ["scaled.json", "the NDF integrates to"];
    let query = [
        "--gamma",
        "5",
        "--theta-o",
        "30",
        "--theta-i",
        "30",
        "--dphi",
        "180",
    ];
    let mut args = vec!["dpf", "--backend", "cpu", "--ndf", file];
    args.extend(query);
    let dpf = facet(&dir, &args);
    assert!(!dpf.1.contains("NaN"), "{}", dpf.1);
    refused("dpf", dpf, &needles);
    let scene = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/demo/demo.gltf");
    let material = format!("tabulated={file}");
    let out = dir.join("render.png");
    let render = [
        "render",
        scene.to_str().unwrap(),
        "--material",
        &material,
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    refused("render", facet(&dir, &render), &needles);
    assert!(!out.exists());
    refused(
        "export",
        facet(
            &dir,
            &[
                "export",
                file,
                "--to",
                "mitsuba",
                "--out",
                &dir.join("x").to_string_lossy(),
            ],
        ),
        &needles,
    );
}

/// A small `.bsdf` of a GGX plastic (grids of 4 to 8, as the loaders' mutation test's seeds).
fn small_bsdf() -> Vec<u8> {
    let res = BsdfResolution {
        theta_i: 4,
        phi_i: 5,
        sample: 6,
        vndf: 8,
        ndf: 8,
    };
    let model = parse_analytic("ggx?alpha=0.3&f0=0.04&kd=0.3,0.1,0.05").unwrap();
    rgl_tensor(&model, &model.ndf, res, "plastic")
        .unwrap()
        .0
        .to_bytes()
}

/// `bytes` with the float field `field` mapped by `f` (value index, value).
fn patched(bytes: &[u8], field: &str, f: impl Fn(usize, f64) -> f64) -> Vec<u8> {
    let t = TensorFile::parse(bytes.to_vec()).unwrap();
    let mut w = TensorWriter::default();
    for name in t.names() {
        if ["description", "jacobian"].contains(&name) {
            w.u8s(name, t.u8s(name).unwrap());
            continue;
        }
        let (v, shape) = t.floats(name).unwrap();
        let mapped = v.iter().enumerate().map(|(i, &x)| match name == field {
            true => f(i, x) as f32,
            false => x as f32,
        });
        w.f32s(name, shape, &mapped.collect::<Vec<_>>());
    }
    w.to_bytes()
}

/// Damaged `.bsdf` files: (name, bytes, what the error says).
fn damaged_bsdfs() -> Vec<(&'static str, Vec<u8>, &'static str)> {
    let good = small_bsdf();
    vec![
        (
            "negated",
            patched(&good, "rgb", |_, x| -x),
            "`rgb` has no positive mass",
        ),
        (
            "black",
            patched(&good, "rgb", |_, _| 0.0),
            "`rgb` has no positive mass",
        ),
        (
            "flat",
            patched(&good, "sigma", |_, _| 0.0),
            "`sigma` is 0e0 at row 0, column 0",
        ),
        (
            "hole",
            patched(&good, "sigma", |i, x| if i == 3 { 0.0 } else { x }),
            "`sigma` is 0e0 at row 0, column 3",
        ),
        (
            "negative",
            patched(&good, "sigma", |_, x| -x),
            "a projected area is positive",
        ),
        (
            "no-ndf",
            patched(&good, "ndf", |_, _| 0.0),
            "`ndf` has no positive mass",
        ),
        (
            "negated-ndf",
            patched(&good, "ndf", |_, x| -x),
            "`ndf` has no positive mass",
        ),
        // Values a fit refuses on its grid (f cos θ past 1e12) are refused by the reader the
        // renderer shares: rendered as a measured material they made infinite pixels.
        (
            "huge",
            patched(&good, "rgb", |i, x| if i == 4 { 3e38 } else { x }),
            "`rgb` holds 3.000e38 at 4",
        ),
        (
            "huge-ndf",
            patched(&good, "ndf", |_, _| 3e38),
            "`ndf` holds 3.000e38 at 0",
        ),
    ]
}

#[test]
fn rgl_files_that_make_no_material_are_refused_when_read() {
    let dir = scratch("bad_sources_rgl");
    for (name, bytes, problem) in damaged_bsdfs() {
        let path = dir.join(format!("{name}.bsdf"));
        let e = RglBsdf::from_bytes(&path, bytes).err().unwrap().to_string();
        assert!(
            e.contains(&format!("{name}.bsdf")) && e.contains(problem),
            "{e}"
        );
    }
    // A measured file's noise, a few values below zero in the data and the NDF, is read (and
    // clipped where evaluated); so is its spectral twin.
    let good = small_bsdf();
    let noisy = patched(&good, "rgb", |i, x| if i % 7 == 0 { -0.01 } else { x });
    let noisy = patched(&noisy, "ndf", |i, x| if i % 5 == 0 { -1e-3 } else { x });
    let file = RglBsdf::from_bytes(&dir.join("noisy.bsdf"), noisy).unwrap();
    let v = file.eval(
        DVec3::new(0.3, 0.0, 0.95).normalize(),
        DVec3::new(-0.2, 0.1, 0.97).normalize(),
    );
    assert!(
        v.is_some_and(|v| v.iter().all(|c| c.is_finite() && *c >= 0.0)),
        "{v:?}"
    );
    let spectral = facet_oracles::fixtures::spectral_from_rgb(&good);
    assert!(RglBsdf::from_bytes(&dir.join("spectral.bsdf"), spectral).is_ok());
}

#[test]
fn facet_convert_and_fit_refuse_such_rgl_files_by_name() {
    let dir = scratch("bad_sources_rgl_cli");
    for (name, bytes, problem) in damaged_bsdfs().into_iter().take(3) {
        let path = dir.join(format!("{name}.bsdf"));
        std::fs::write(&path, bytes).unwrap();
        let file = path.to_str().unwrap();
        let needles = [&format!("{name}.bsdf") as &str, problem];
        let out = dir.join(format!("{name}.binary"));
        refused(
            "convert",
            facet(&dir, &["convert", file, out.to_str().unwrap()]),
            &needles,
        );
        assert!(!out.exists(), "{name}: a MERL file was written");
        let fits = dir.join("fits");
        refused(
            "fit",
            facet(
                &dir,
                &[
                    "fit",
                    file,
                    "--out",
                    fits.to_str().unwrap(),
                    "--backend",
                    "cpu",
                ],
            ),
            &needles,
        );
    }
}
