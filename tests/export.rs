//! `facet export` as a user runs it: a GGX gold conductor and a GGX plastic fitted by
//! `facet fit`, written for Mitsuba 3, pbrt-v4 and glTF 2.0, and read back: the XML by a small
//! well-formedness check and by its values, the glTF through the `gltf` crate. The binary runs
//! in scratch folders under the target tmp dir, never in the repository.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

const GOLD: &str = "analytic:ggx?alpha=0.2&conductor=gold";
const PLASTIC: &str = "analytic:ggx?alpha=0.2&f0=0.04&kd=0.3,0.1,0.05";

fn facet(cwd: &Path, args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_facet"))
        .args(args)
        .current_dir(cwd)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// Runs `facet fit ARGS --backend cpu --out .` in `dir` and returns the one fit JSON written.
fn fit_one(dir: &Path, args: &[&str]) -> PathBuf {
    let mut all = vec!["fit"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--backend", "cpu", "--out", "."]);
    let (ok, stdout, stderr) = facet(dir, &all);
    assert!(ok, "{stdout}\n{stderr}");
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .unwrap()
}

/// The two fits, made once for every test of this file: (gold JSON, plastic JSON).
fn fits() -> &'static (PathBuf, PathBuf) {
    static FITS: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    FITS.get_or_init(|| {
        let dir = common::scratch("export_fits");
        let (ok, stdout, stderr) = facet(
            &dir,
            &[
                "fit",
                GOLD,
                PLASTIC,
                "--backend",
                "cpu",
                "--out",
                dir.to_str().unwrap(),
            ],
        );
        assert!(ok, "{stdout}\n{stderr}");
        let mut jsons: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        jsons.sort();
        let find = |what: &str| {
            jsons
                .iter()
                .find(|p| {
                    let v = json(p);
                    v["source"].as_str() == Some(what)
                })
                .unwrap_or_else(|| panic!("no fit of {what} in {jsons:?}"))
                .clone()
        };
        (find(GOLD), find(PLASTIC))
    })
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn rgb(v: &serde_json::Value) -> [f64; 3] {
    std::array::from_fn(|c| v[c].as_f64().unwrap())
}

/// Exports `fit` for `to` into a fresh folder; returns the file's text and stdout.
fn export(fit: &Path, to: &str, extra: &[&str]) -> (String, String) {
    let dir = common::scratch(&format!(
        "export_{to}_{}",
        fit.file_stem().unwrap().to_string_lossy()
    ));
    let out = dir.join(format!("material.{to}"));
    let mut args = vec![
        "export",
        fit.to_str().unwrap(),
        "--to",
        to,
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let (ok, stdout, stderr) = facet(&dir, &args);
    assert!(ok, "{stdout}\n{stderr}");
    (std::fs::read_to_string(&out).unwrap(), stdout)
}

/// A small XML well-formedness check: one root element, every tag closed in order, attribute
/// values quoted, comments closed and free of `--`.
fn well_formed(xml: &str) -> Result<String, String> {
    let mut rest = xml.trim_start();
    if let Some(r) = rest.strip_prefix("<?xml") {
        rest = &r[r.find("?>").ok_or("unclosed declaration")? + 2..];
    }
    let mut stack: Vec<String> = Vec::new();
    let mut root = None;
    loop {
        rest = rest.trim_start();
        if rest.is_empty() {
            break;
        }
        if let Some(r) = rest.strip_prefix("<!--") {
            let end = r.find("-->").ok_or("unclosed comment")?;
            if r[..end].contains("--") {
                return Err("`--` inside a comment".into());
            }
            rest = &r[end + 3..];
            continue;
        }
        if !rest.starts_with('<') {
            if stack.is_empty() {
                return Err(format!("text outside the root: {rest:.20}"));
            }
            rest = &rest[rest.find('<').ok_or("text to the end")?..];
            continue;
        }
        let end = rest.find('>').ok_or("unclosed tag")?;
        let tag = &rest[1..end];
        rest = &rest[end + 1..];
        if let Some(name) = tag.strip_prefix('/') {
            match stack.pop() {
                Some(open) if open == name.trim() => {}
                other => return Err(format!("</{name}> closes {other:?}")),
            }
            continue;
        }
        let self_closing = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let name = tag.split_whitespace().next().ok_or("empty tag")?.to_owned();
        // Attributes: name="value" pairs.
        let mut attrs = tag[name.len()..].trim();
        while !attrs.is_empty() {
            let eq = attrs
                .find("=\"")
                .ok_or(format!("bad attribute in <{tag}>"))?;
            let close = attrs[eq + 2..]
                .find('"')
                .ok_or(format!("unquoted value in <{tag}>"))?;
            if attrs[eq + 2..eq + 2 + close].contains('<') {
                return Err(format!("`<` in a value of <{tag}>"));
            }
            attrs = attrs[eq + 2 + close + 1..].trim_start();
        }
        if stack.is_empty() {
            if root.is_some() {
                return Err("two root elements".into());
            }
            root = Some(name.clone());
        }
        if !self_closing {
            stack.push(name);
        }
    }
    if !stack.is_empty() {
        return Err(format!("unclosed {stack:?}"));
    }
    root.ok_or("no root element".into())
}

/// The value of `<TYPE name="NAME" value="..."/>` in the XML.
fn xml_value<'a>(xml: &'a str, ty: &str, name: &str) -> &'a str {
    let key = format!("<{ty} name=\"{name}\" value=\"");
    let start = xml
        .find(&key)
        .unwrap_or_else(|| panic!("no {key} in\n{xml}"))
        + key.len();
    &xml[start..start + xml[start..].find('"').unwrap()]
}

fn numbers(s: &str, sep: char) -> Vec<f64> {
    s.split(sep)
        .filter(|x| !x.trim().is_empty())
        .map(|x| x.trim().parse().unwrap())
        .collect()
}

/// Gold: a roughconductor / conductor / metal with the fit's α and its conductor η, k exactly;
/// glTF roughness² = α, base colour = the Schlick F0.
#[test]
fn gold_exports_a_conductor_everywhere() {
    let (gold, _) = fits();
    let rec = json(gold);
    let ggx = &rec["ggx"];
    let alpha = ggx["alpha_x"].as_f64().unwrap();
    let fits = &ggx["fresnel_fits"];
    let (eta, k) = (rgb(&fits["conductor_eta"]), rgb(&fits["conductor_k"]));

    let (xml, stdout) = export(gold, "mitsuba", &[]);
    assert_eq!(well_formed(&xml), Ok("bsdf".into()), "{xml}");
    assert!(
        xml.contains(r#"<bsdf type="roughconductor""#) && xml.contains(r#"version="3.0.0""#),
        "{xml}"
    );
    assert_eq!(xml_value(&xml, "string", "distribution"), "ggx");
    assert_eq!(
        xml_value(&xml, "float", "alpha").parse::<f64>().unwrap(),
        alpha
    );
    assert_eq!(numbers(xml_value(&xml, "rgb", "eta"), ','), eta);
    assert_eq!(numbers(xml_value(&xml, "rgb", "k"), ','), k);
    // The statement: the recorded conductor error and the table error.
    let conductor_error = fits["conductor"]["error"].as_f64().unwrap();
    assert!(xml.contains(&format!("{conductor_error:e}")), "{xml}");
    assert!(xml.contains(&format!("{:e}", ggx["error"].as_f64().unwrap())));
    assert!(
        stdout.contains("mitsuba:") && stdout.contains("conductor Fresnel error"),
        "{stdout}"
    );

    let (pbrt, _) = export(gold, "pbrt", &[]);
    assert!(pbrt.contains("\"string type\" [ \"conductor\" ]"), "{pbrt}");
    let list = |key: &str| {
        let start = pbrt.find(key).unwrap() + key.len();
        let end = start + pbrt[start..].find(']').unwrap();
        numbers(pbrt[start..end].trim().trim_start_matches('['), ' ')
    };
    assert_eq!(list("\"rgb eta\" "), eta);
    assert_eq!(list("\"rgb k\" "), k);
    assert_eq!(list("\"float uroughness\" "), vec![alpha]);
    assert_eq!(list("\"float vroughness\" "), vec![alpha]);
    assert!(pbrt.contains("\"bool remaproughness\" [ false ]"));
    // Every line but the statement is the material.
    assert!(
        pbrt.lines().filter(|l| !l.starts_with('#')).count() == 7,
        "{pbrt}"
    );

    let (text, _) = export(gold, "gltf", &[]);
    let doc = gltf::Gltf::from_slice(text.as_bytes()).expect("the glTF parses");
    let m = doc.materials().next().expect("one material");
    let pbr = m.pbr_metallic_roughness();
    let r = pbr.roughness_factor() as f64;
    assert!(
        (r * r / alpha - 1.0).abs() < 1e-6,
        "roughness {r}, α {alpha}"
    );
    assert_eq!(pbr.metallic_factor(), 1.0);
    let f0 = rgb(&fits["schlick_f0"]);
    for (got, want) in pbr.base_color_factor().iter().zip(f0) {
        assert!((*got as f64 - want).abs() < 1e-6, "{got} {want}");
    }
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let extras = &v["materials"][0]["extras"]["facet_export"];
    assert_eq!(extras["fresnel"], "schlick");
    assert_eq!(
        extras["fresnel_error"].as_f64().unwrap(),
        fits["schlick"]["error"].as_f64().unwrap()
    );
}

/// The plastic: roughplastic / coateddiffuse / metallic 0, with ρd ≈ (0.3, 0.1, 0.05) and
/// η ≈ 1.5 (F0 = 0.04).
#[test]
fn plastic_exports_a_plastic_everywhere() {
    let (_, plastic) = fits();
    let rec = json(plastic);
    let alpha = rec["ggx"]["alpha_x"].as_f64().unwrap();
    let close = |got: &[f64]| {
        got.len() == 3
            && got
                .iter()
                .zip([0.3, 0.1, 0.05])
                .all(|(g, w)| (g - w).abs() <= 0.01 * w + 1e-3)
    };

    let (xml, _) = export(plastic, "mitsuba", &[]);
    assert_eq!(well_formed(&xml), Ok("bsdf".into()), "{xml}");
    assert!(xml.contains(r#"<bsdf type="roughplastic""#), "{xml}");
    assert_eq!(
        xml_value(&xml, "float", "alpha").parse::<f64>().unwrap(),
        alpha
    );
    // Mitsuba and pbrt evaluate the exact dielectric curve: the dielectric fit's η. The source
    // is a Schlick curve (F0 = 0.04, η = 1.5 at normal incidence), which no exact dielectric
    // follows at every θd: its least-squares η is 1.46, and the file says so.
    let eta = rec["ggx"]["fresnel_fits"]["dielectric_eta"]
        .as_f64()
        .unwrap();
    let ior: f64 = xml_value(&xml, "float", "int_ior").parse().unwrap();
    assert_eq!(ior, eta);
    assert!((ior - 1.5).abs() < 0.05, "int_ior {ior}");
    assert!(xml.contains("would match F0"), "{xml}");
    assert_eq!(xml_value(&xml, "float", "ext_ior"), "1");
    let kd = numbers(xml_value(&xml, "rgb", "diffuse_reflectance"), ',');
    assert!(close(&kd), "ρd {kd:?}");
    assert!(
        xml.contains("not ρd/π"),
        "the diffuse difference is stated: {xml}"
    );

    let (pbrt, _) = export(plastic, "pbrt", &[]);
    assert!(
        pbrt.contains("\"string type\" [ \"coateddiffuse\" ]"),
        "{pbrt}"
    );
    let start = pbrt.find("\"rgb reflectance\" [").unwrap() + 19;
    let end = start + pbrt[start..].find(']').unwrap();
    assert!(close(&numbers(&pbrt[start..end], ' ')), "{pbrt}");
    let start = pbrt.find("\"float eta\" [").unwrap() + 13;
    let end = start + pbrt[start..].find(']').unwrap();
    assert_eq!(pbrt[start..end].trim().parse::<f64>().unwrap(), eta);

    let (text, _) = export(plastic, "gltf", &[]);
    let doc = gltf::Gltf::from_slice(text.as_bytes()).expect("the glTF parses");
    let m = doc.materials().next().unwrap();
    let pbr = m.pbr_metallic_roughness();
    assert_eq!(pbr.metallic_factor(), 0.0);
    let r = pbr.roughness_factor() as f64;
    assert!((r * r / alpha - 1.0).abs() < 1e-6);
    let base: Vec<f64> = pbr.base_color_factor()[..3]
        .iter()
        .map(|&c| c as f64)
        .collect();
    assert!(close(&base), "baseColorFactor {base:?}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ior = v["materials"][0]["extensions"]["KHR_materials_ior"]["ior"]
        .as_f64()
        .unwrap();
    // glTF's Fresnel is Schlick's: ior from the Schlick fit's F0 = 0.04, i.e. 1.5.
    assert!((ior - 1.5).abs() < 1e-3, "ior {ior}");
    assert!(
        v["extensionsUsed"]
            .as_array()
            .unwrap()
            .contains(&"KHR_materials_ior".into())
    );
    // Isotropic: no anisotropy extension.
    assert!(v["materials"][0]["extensions"]["KHR_materials_anisotropy"].is_null());
}

/// Beckmann: Mitsuba writes the Beckmann fit; pbrt says GGX stands in for it.
#[test]
fn beckmann_is_mitsubas_only() {
    let (gold, _) = fits();
    let rec = json(gold);
    let (xml, _) = export(gold, "mitsuba", &["--model", "beckmann"]);
    assert_eq!(xml_value(&xml, "string", "distribution"), "beckmann");
    assert_eq!(
        xml_value(&xml, "float", "alpha").parse::<f64>().unwrap(),
        rec["beckmann"]["alpha_x"].as_f64().unwrap()
    );
    let (pbrt, stdout) = export(gold, "pbrt", &["--model", "beckmann"]);
    assert!(pbrt.contains("no Beckmann distribution"), "{pbrt}");
    assert!(stdout.contains("as a ggx conductor (ggx fit"), "{stdout}");
}

/// Bad input: a missing file, a JSON that is no fit, a fit without the asked model, an output
/// that exists or is the fit itself; each an error naming the file, none a panic.
#[test]
fn bad_input_is_an_error_naming_the_file() {
    let (gold, _) = fits();
    let dir = common::scratch("export_bad");
    let run = |args: &[&str]| facet(&dir, args);
    let check = |(ok, stdout, stderr): (bool, String, String), want: &[&str]| {
        assert!(!ok, "{stdout}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        for w in want {
            assert!(stderr.contains(w), "{w:?} not in {stderr}");
        }
    };
    check(
        run(&["export", "missing.json", "--to", "gltf"]),
        &["missing.json"],
    );
    std::fs::write(dir.join("other.json"), r#"{"hello": 1}"#).unwrap();
    check(
        run(&["export", "other.json", "--to", "pbrt"]),
        &["other.json", "fit file"],
    );
    // A fit without its Beckmann model (as `--model ggx` writes it).
    let mut v = json(gold);
    v.as_object_mut().unwrap().remove("beckmann");
    std::fs::write(dir.join("ggx-only.json"), v.to_string()).unwrap();
    check(
        run(&[
            "export",
            "ggx-only.json",
            "--to",
            "mitsuba",
            "--model",
            "beckmann",
        ]),
        &["ggx-only.json", "no Beckmann model"],
    );
    // The default output: the fit's stem in the current folder; a second run keeps it.
    let (ok, stdout, stderr) = run(&["export", "ggx-only.json", "--to", "gltf"]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(dir.join("ggx-only.gltf").exists());
    check(
        run(&["export", "ggx-only.json", "--to", "gltf"]),
        &["ggx-only.gltf", "exists", "--force"],
    );
    let (ok, _, stderr) = run(&["export", "ggx-only.json", "--to", "gltf", "--force"]);
    assert!(ok, "{stderr}");
    check(
        run(&[
            "export",
            "ggx-only.json",
            "--to",
            "pbrt",
            "-o",
            "ggx-only.json",
            "--force",
        ]),
        &["would replace the fit"],
    );
    // The fit survived every refused export.
    assert!(facet_fit::model::material::FittedMaterial::load(&dir.join("ggx-only.json")).is_ok());
}

/// A `--no-diffuse --model ggx` fit records no Fresnel fits: the export fits its curve to the
/// table and says its error is unknown; the fit has no Beckmann model to export.
#[test]
fn single_lobe_fit_exports_with_unknown_error() {
    let dir = common::scratch("export_single_lobe");
    let fit = fit_one(&dir, &[GOLD, "--no-diffuse", "--model", "ggx"]);
    assert!(json(&fit).get("fresnel_fits").is_none());
    let (pbrt, stdout) = export(&fit, "pbrt", &[]);
    assert!(stdout.contains("error unknown"), "{stdout}");
    assert!(
        pbrt.contains("unknown") && pbrt.contains("\"rgb eta\""),
        "{pbrt}"
    );
    let (ok, _, stderr) = facet(
        &dir,
        &[
            "export",
            fit.to_str().unwrap(),
            "--to",
            "mitsuba",
            "--model",
            "beckmann",
        ],
    );
    assert!(!ok && stderr.contains("no Beckmann model"), "{stderr}");
    assert!(stderr.contains(fit.file_name().unwrap().to_str().unwrap()));
}

/// An anisotropic fit (`--aniso`, small grid): Mitsuba gets alpha_u/alpha_v and a word on the
/// rotation it cannot make; glTF's KHR_materials_anisotropy, inverted, gives αx, αy and the
/// rotation back.
#[test]
fn anisotropic_fit_exports_both_alphas() {
    let dir = common::scratch("export_aniso");
    let fit = fit_one(
        &dir,
        &[
            "analytic:ggx?alpha_x=0.3&alpha_y=0.1&rotation=30&conductor=gold",
            "--aniso",
            "--resolution",
            "16",
            "--phi-resolution",
            "16",
            "--model",
            "ggx",
        ],
    );
    let rec = json(&fit);
    let ggx = &rec["ggx"];
    let (ax, ay, rot) = (
        ggx["alpha_x"].as_f64().unwrap(),
        ggx["alpha_y"].as_f64().unwrap(),
        ggx["rotation"].as_f64().unwrap(),
    );
    assert!(
        ax > ay && (rot.to_degrees() - 30.0).abs() < 1.0,
        "{ax} {ay} {rot}"
    );
    let (xml, _) = export(&fit, "mitsuba", &[]);
    assert_eq!(well_formed(&xml), Ok("bsdf".into()));
    assert_eq!(
        xml_value(&xml, "float", "alpha_u").parse::<f64>().unwrap(),
        ax
    );
    assert_eq!(
        xml_value(&xml, "float", "alpha_v").parse::<f64>().unwrap(),
        ay
    );
    assert!(xml.contains("cannot rotate"), "{xml}");
    let (text, _) = export(&fit, "gltf", &[]);
    gltf::Gltf::from_slice(text.as_bytes()).expect("the glTF parses");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let m = &v["materials"][0];
    let r = m["pbrMetallicRoughness"]["roughnessFactor"]
        .as_f64()
        .unwrap();
    let an = &m["extensions"]["KHR_materials_anisotropy"];
    let s = an["anisotropyStrength"].as_f64().unwrap();
    // glTF: α across = roughness², α along = mix(roughness², 1, strength²).
    let (across, along) = (r * r, r * r + (1.0 - r * r) * s * s);
    assert!((across / ay - 1.0).abs() < 1e-12 && (along / ax - 1.0).abs() < 1e-12);
    assert_eq!(an["anisotropyRotation"].as_f64().unwrap(), rot);
    assert!(
        v["extensionsUsed"]
            .as_array()
            .unwrap()
            .contains(&"KHR_materials_anisotropy".into())
    );
}

/// A fit with a coat (here attached by hand: the gold fit's own record as the base under a
/// coat of α 0.05) exported to Mitsuba 3: a `measured` `<bsdf>` naming the coated model's
/// table, written beside it and readable as an RGL file; the table is refused when it exists
/// (kept without --force), or when --out would take its name; `--no-coat` writes the single
/// layer and no table.
#[test]
fn coated_fit_exports_a_table_for_mitsuba() {
    let dir = common::scratch("export_coat_mitsuba");
    let fit = &fits().0;
    let mut rec = json(fit);
    let base = rec.clone();
    rec["coat"] = serde_json::json!({
        "eta": 1.5, "alpha": 0.05, "weight": 1.0,
        "error": 0.01, "ggx_error": 0.012, "beckmann_error": null,
        "base": base,
    });
    let coated = dir.join("coated.json");
    std::fs::write(&coated, serde_json::to_string(&rec).unwrap()).unwrap();
    let name = rec["name"].as_str().unwrap().to_string();
    let table = dir.join(format!(
        "{}.coated.bsdf",
        facet_fit::io::input::safe_file_stem(&name)
    ));

    // `facet export coated.json --to mitsuba EXTRA…` in the test's folder.
    let mitsuba = |extra: &[&str]| {
        let mut args = vec!["export", "coated.json", "--to", "mitsuba"];
        args.extend_from_slice(extra);
        facet(&dir, &args)
    };
    let (ok, stdout, stderr) = mitsuba(&[]);
    assert!(ok, "{stdout}\n{stderr}");
    let xml = std::fs::read_to_string(dir.join("coated.xml")).unwrap();
    assert_eq!(well_formed(&xml), Ok("bsdf".into()));
    assert!(xml.contains(r#"<bsdf type="measured""#), "{xml}");
    assert_eq!(
        xml_value(&xml, "string", "filename"),
        table.file_name().unwrap().to_str().unwrap()
    );
    assert!(stdout.contains("against the coated model"), "{stdout}");
    let file = facet_fit::sources::rgl::RglBsdf::open(&table).expect("the table reads");
    assert!(facet_fit::model::brdf::Brdf::is_isotropic(&file) && !file.is_spectral());

    // The table exists: refused, and neither file changes.
    std::fs::write(&table, b"mine").unwrap();
    let (ok, _, stderr) = mitsuba(&["-o", "other.xml"]);
    assert!(
        !ok && stderr.contains("exists") && stderr.contains("--force"),
        "{stderr}"
    );
    assert_eq!(std::fs::read(&table).unwrap(), b"mine");
    assert!(!dir.join("other.xml").exists());
    let (ok, _, stderr) = mitsuba(&["-o", "other.xml", "--force"]);
    assert!(ok, "{stderr}");
    assert!(facet_fit::sources::rgl::RglBsdf::open(&table).is_ok());
    let (ok, _, stderr) = mitsuba(&[
        "-o",
        table.file_name().unwrap().to_str().unwrap(),
        "--force",
    ]);
    assert!(!ok && stderr.contains("choose another --out"), "{stderr}");

    let (ok, _, stderr) = mitsuba(&["-o", "single.xml", "--no-coat"]);
    assert!(ok, "{stderr}");
    let single = std::fs::read_to_string(dir.join("single.xml")).unwrap();
    assert!(
        single.contains(r#"<bsdf type="roughconductor""#),
        "{single}"
    );
}
