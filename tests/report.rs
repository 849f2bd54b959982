//! `facet report`: the page on three proxies, every image it names present and decodable, the
//! page loaded in a real browser (headless Chromium) with every image loaded; the ΔE path
//! (palette's CIEDE2000 on the displayed colours) against Sharma, Wu & Dalal's test data; ΔE_ITP
//! (BT.2124) against published PQ levels and the BT.2087 matrix, and against values computed
//! independently from the BT.2100 formulas.

mod common;

use common::{facet_in, scratch};
// The report's ΔE module, facet-report's public API.
use facet_render::Image;
use facet_report::delta_e::{
    REC709_TO_REC2020, REFERENCE_WHITE, ciede2000, delta_e_image, delta_e_itp, displayed, ictcp,
    lab, pq,
};
use palette::{Lab, LinSrgb};
use std::path::Path;
use std::process::Command;

/// Every `src="…"` of the page, in order.
fn image_sources(html: &str) -> Vec<String> {
    html.split("src=\"")
        .skip(1)
        .map(|rest| rest.split('"').next().unwrap().to_owned())
        .collect()
}

/// Three proxies at 24×24 pixels, 2 spp, no sweep but of the first: index.html names every
/// render, ΔE image, plot and mean image, and each exists and decodes (PNG by `image`, SVG as
/// an `<svg` document).
#[test]
fn report_on_three_proxies_writes_every_image() {
    if facet_gpu::gpu_for_tests("report_on_three_proxies_writes_every_image").is_none() {
        return;
    }
    let dir = scratch("report_three");
    let out = dir.join("page");
    let (ok, stdout, stderr) = facet_in(
        &dir,
        &[
            "report",
            "nbrdf:gold-metallic-paint",
            "nbrdf:blue-acrylic",
            "nbrdf:alum-bronze",
            "--out",
            "page",
            "--resolution",
            "24",
            "--spp",
            "2",
            "--fit-resolution",
            "32",
            "--sweep",
            "1",
        ],
    );
    assert!(ok, "{stdout}\n{stderr}");
    assert!(stdout.contains("mean ΔE (point)"), "{stdout}");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    let sources = image_sources(&html);
    // Per material 8 renders, 6 ΔE images, 2 of the noise floor, 2 plots, and 2 renders and 2
    // ΔE images more where the fit kept a coat; the scale, the sweep, 6 mean images (8 when a
    // fit kept a coat).
    let coated = ["gold-metallic-paint", "blue-acrylic", "alum-bronze"]
        .iter()
        .filter(|name| html.contains(&format!("img/{name}-point-coated.png")))
        .count();
    let means = if coated > 0 { 8 } else { 6 };
    assert_eq!(
        sources.len(),
        3 * 18 + 4 * coated + 1 + 1 + means,
        "{sources:?}"
    );
    for src in &sources {
        check_image(&out.join(src));
    }
    for name in ["gold-metallic-paint", "blue-acrylic", "alum-bronze"] {
        assert!(
            html.contains(&format!("id=\"{name}\"")),
            "{name} has no section"
        );
    }
    // A second run into the same folder is refused without --force.
    let (ok, _, stderr) = facet_in(&dir, &["report", "nbrdf:blue-acrylic", "--out", "page"]);
    assert!(!ok && stderr.contains("not empty"), "{stderr}");
}

/// `facet report ARGS… --out page` in `dir` at 32² pixels, 2 spp, no sweep: its stdout and
/// `page/index.html`.
fn small_report(dir: &Path, args: &[&str]) -> (String, String) {
    let mut all = vec!["report"];
    all.extend_from_slice(args);
    all.extend([
        "--out",
        "page",
        "--resolution",
        "32",
        "--spp",
        "2",
        "--sweep",
        "0",
    ]);
    let (ok, stdout, stderr) = facet_in(dir, &all);
    assert!(ok, "{stdout}\n{stderr}");
    let html = std::fs::read_to_string(dir.join("page/index.html")).unwrap();
    (stdout, html)
}

/// The mean ΔE of `model` under `lighting` (`point` or `env`) as the run prints it:
/// `mean ΔE (point): tabulated 1.26, ggx 2.06, beckmann 5.99, coated 0.62`.
fn printed_mean(stdout: &str, lighting: &str, model: &str) -> f64 {
    let line = stdout
        .lines()
        .find(|l| l.starts_with(&format!("mean ΔE ({lighting}):")))
        .unwrap_or_else(|| panic!("no {lighting} means in {stdout}"));
    line.split([':', ','])
        .find_map(|part| part.trim().strip_prefix(&format!("{model} ")))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {model} mean in `{line}`"))
}

/// The noise floor of `lighting` (`point` or `env`) as the run prints it, ΔE2000 and ΔE_ITP
/// means: `noise floor (env): ΔE mean 0.412 median 0.398, ΔE_ITP mean 1.730 median 1.702`.
fn printed_floor(stdout: &str, lighting: &str) -> (f64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with(&format!("noise floor ({lighting}):")))
        .unwrap_or_else(|| panic!("no {lighting} noise floor in {stdout}"));
    let after = |key: &str| -> f64 {
        let rest = &line[line
            .find(key)
            .unwrap_or_else(|| panic!("{key} in `{line}`"))
            + key.len()..];
        rest.split_whitespace().next().unwrap().parse().unwrap()
    };
    (after("ΔE mean "), after("ΔE_ITP mean "))
}

/// The noise floor (the measurement rendered again at another seed, against its first render)
/// of one material at 8 and 32 spp: two independent estimates of a pixel (two randomisations of
/// its scrambled Sobol points) differ by noise of σ √2 / √N, and for small noise ΔE is
/// proportional to it, so quadrupling N halves the floor (ratio 0.5; the Sobol points'
/// stratification can only make it smaller, little on these integrands with the sun's and the
/// lobe choice's discontinuities: 0.47 and 0.45 measured on the proxies from 16 to 64 and from
/// 64 to 256 spp; ±0.12 for that, the ~700 pixels' own scatter and ΔE's curvature). Under the
/// point light only the pixel positions vary, so its floor is far below the environment's
/// (below a quarter of it).
#[test]
fn noise_floor_halves_when_the_samples_quadruple() {
    const TEST: &str = "noise_floor_halves_when_the_samples_quadruple";
    if facet_gpu::gpu_for_tests(TEST).is_none() {
        return;
    }
    let dir = scratch("report_floor");
    let floor_at = |spp: &str| {
        let out = format!("page-{spp}");
        let (ok, stdout, stderr) = facet_in(
            &dir,
            &[
                "report",
                "analytic:ggx?alpha=0.2&conductor=gold",
                "--out",
                &out,
                "--resolution",
                "32",
                "--spp",
                spp,
                "--fit-resolution",
                "32",
                "--coat",
                "off",
                "--sweep",
                "0",
            ],
        );
        assert!(ok, "{stdout}\n{stderr}");
        let html = std::fs::read_to_string(dir.join(&out).join("index.html")).unwrap();
        assert!(html.contains("-env-de-noise.png"), "no noise floor image");
        (
            printed_floor(&stdout, "env"),
            printed_floor(&stdout, "point"),
        )
    };
    let ((env8, itp8), (point8, _)) = floor_at("8");
    let ((env32, itp32), _) = floor_at("32");
    eprintln!("noise floor (env): ΔE2000 {env8:.3} → {env32:.3}, ΔE_ITP {itp8:.3} → {itp32:.3}");
    assert!(env8 > 0.0 && itp8 > 0.0, "{env8} {itp8}");
    for (ratio, what) in [(env32 / env8, "ΔE2000"), (itp32 / itp8, "ΔE_ITP")] {
        assert!(
            (ratio - 0.5).abs() < 0.12,
            "{what}: 8 → 32 spp ratio {ratio}"
        );
    }
    assert!(point8 < 0.25 * env8, "point {point8}, env {env8}");
}

/// A measurement made from a known coat (η 1.5, α 0.05, weight 1) over GGX α 0.3 gold, reported
/// with `--coat always`: the fit keeps the coat, and the page shows its coated model (one more
/// sphere per lighting, its ΔE images and error). The coated model is the measurement's own
/// (the fit recovers it within 2 %: `crates/fit/tests/coat.rs`), so under the point light,
/// where a pixel is f cos θ I / r² and nothing else differs, its ΔE is below half the single
/// layer's, which cannot show the coat's sharp highlight over the rough base.
#[test]
fn report_of_a_coated_measurement_shows_its_coated_model() {
    const TEST: &str = "report_of_a_coated_measurement_shows_its_coated_model";
    if facet_gpu::gpu_for_tests(TEST).is_none() {
        return;
    }
    use facet_fit::model::coat::{Coat, CoatLayer, Coated};
    use facet_fit::model::merl_grid::MerlTable;
    use facet_fit::model::microfacet::{AnalyticNdf, MicrofacetBrdf, Ndf, NdfKind};
    let dir = scratch("report_coated");
    let truth = Coated {
        layer: CoatLayer::new(Coat::new(1.5, 0.05, 1.0)).unwrap(),
        base: MicrofacetBrdf {
            name: "gold".into(),
            ndf: Ndf::Analytic(AnalyticNdf::isotropic(NdfKind::Ggx, 0.3)),
            fresnel: facet_fit::model::fresnel::Fresnel::GOLD,
            diffuse: [0.0; 3],
        },
    };
    MerlTable::sample(&truth)
        .write(&dir.join("coated-gold.binary"))
        .unwrap();
    let (stdout, html) = small_report(&dir, &["coated-gold.binary", "--coat", "always"]);
    let sources = image_sources(&html);
    // 5 renders, 4 ΔE images and the noise floor's per lighting, 2 plots; the scale and 8 mean
    // images.
    assert_eq!(sources.len(), 2 * 10 + 2 + 1 + 8, "{sources:?}");
    for src in &sources {
        check_image(&dir.join("page").join(src));
    }
    for want in ["point-coated.png", "env-de-coated.png", "<th>coated</th>"] {
        assert!(html.contains(want), "no {want} on the page");
    }
    let (coated, single) = (
        printed_mean(&stdout, "point", "coated"),
        printed_mean(&stdout, "point", "tabulated"),
    );
    eprintln!("mean ΔE (point) against the measurement: coated {coated:.3}, single {single:.3}");
    assert!(coated < 0.5 * single, "ΔE coated {coated}, single {single}");
}

/// `facet fit` of a GGX α 0.3 gold into `dir/fits`: its JSON file and record.
fn gold_fit_record(dir: &Path) -> (std::path::PathBuf, serde_json::Value) {
    let (ok, _, stderr) = facet_in(
        dir,
        &[
            "fit",
            "analytic:ggx?alpha=0.3&conductor=gold",
            "--out",
            "fits",
        ],
    );
    assert!(ok, "{stderr}");
    let path = std::fs::read_dir(dir.join("fits"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "json"))
        .expect("a fit JSON");
    let record = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    (path, record)
}

/// A fit JSON that kept a coat (attached here by hand: the fit's own record as the base under a
/// coat of α 0.05, weight 1) stands for its coated model: that is the reference, and the single
/// layer's tabulated model, rendered without the coat, differs from it visibly (a mean ΔE above
/// 1 under the point light, where the coat adds a highlight 6 times narrower than the base's
/// lobe and about as bright as its peak; rendered coated by mistake it would be 0).
#[test]
fn report_of_a_coated_fit_json_compares_with_its_coated_model() {
    const TEST: &str = "report_of_a_coated_fit_json_compares_with_its_coated_model";
    if facet_gpu::gpu_for_tests(TEST).is_none() {
        return;
    }
    let dir = scratch("report_coated_json");
    let (_, mut rec) = gold_fit_record(&dir);
    let base = rec.clone();
    rec["coat"] = serde_json::json!({
        "eta": 1.5, "alpha": 0.05, "weight": 1.0,
        "error": 0.01, "ggx_error": null, "beckmann_error": null,
        "base": base,
    });
    std::fs::write(dir.join("coated.json"), rec.to_string()).unwrap();
    let (stdout, html) = small_report(&dir, &["coated.json"]);
    assert!(html.contains("ΔE against the coated model"), "{html}");
    // The coated model is the reference: it has no ΔE of its own.
    assert!(!html.contains("de-coated.png"), "{html}");
    let single = printed_mean(&stdout, "point", "tabulated");
    eprintln!("mean ΔE (point) of the single layer against the coated model: {single:.3}");
    assert!(
        single > 1.0,
        "ΔE of the single layer against the coated model: {single}"
    );
}

/// A fit JSON's record names the metric its fit minimised and its models' errors in the other:
/// the page says which was minimised and shows each error in its metric's column — as
/// written, and again with the two metrics swapped in the JSON (the page must follow the
/// record, not assume the default).
#[test]
fn report_shows_the_metric_minimised_and_the_errors_in_both() {
    const TEST: &str = "report_shows_the_metric_minimised_and_the_errors_in_both";
    if facet_gpu::gpu_for_tests(TEST).is_none() {
        return;
    }
    let dir = scratch("report_metric");
    let (path, rec) = gold_fit_record(&dir);
    let minimised = rec["metric"].as_str().unwrap().to_owned();
    let other = rec["other_metric"]["metric"].as_str().unwrap().to_owned();
    assert_ne!(minimised, other);
    let own = rec["tabulated"]["error"].as_f64().unwrap();
    let theirs = rec["other_metric"]["tabulated"].as_f64().unwrap();
    // The record table's tabulated row: the perceptual column first, then the log one.
    let row = |perceptual: f64, log: f64| {
        format!("<tr><td>tabulated</td><td>{perceptual:.4}</td><td>{log:.4}</td>")
    };
    let order = |metric: &str, value: f64, other_value: f64| match metric {
        "perceptual" => (value, other_value),
        "log" => (other_value, value),
        m => panic!("unknown metric {m}"),
    };
    let (_, html) = small_report(&dir, &[path.to_str().unwrap()]);
    let (p, l) = order(&minimised, own, theirs);
    for want in [
        format!("The fit minimised the {minimised} metric."),
        format!("<th>error ({minimised}, minimised)</th>"),
        format!("<th>error ({other})</th>"),
        format!("<td>{minimised}</td>"),
        row(p, l),
    ] {
        assert!(html.contains(&want), "no {want} on the page");
    }
    // The same record with the metrics swapped.
    let mut swapped = rec.clone();
    swapped["metric"] = other.clone().into();
    swapped["other_metric"]["metric"] = minimised.clone().into();
    swapped["tabulated"]["error"] = theirs.into();
    swapped["other_metric"]["tabulated"] = own.into();
    std::fs::write(dir.join("swapped.json"), swapped.to_string()).unwrap();
    std::fs::remove_dir_all(dir.join("page")).unwrap();
    let (_, html) = small_report(&dir, &["swapped.json"]);
    let (p, l) = order(&other, theirs, own);
    assert!(html.contains(&format!("The fit minimised the {other} metric.")));
    assert!(html.contains(&row(p, l)), "no {} on the page", row(p, l));
}

/// A PNG decodes to a non-empty image; an SVG is an `<svg …>` document.
fn check_image(path: &Path) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    match path.extension().and_then(|e| e.to_str()) {
        Some("png") => {
            let im = image::load_from_memory(&bytes)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(im.width() > 0 && im.height() > 0, "{}", path.display());
        }
        Some("svg") => {
            let text = String::from_utf8(bytes).unwrap();
            assert!(
                text.contains("<svg") && text.trim_end().ends_with("</svg>"),
                "{}",
                path.display()
            );
        }
        other => panic!("{}: unexpected image type {other:?}", path.display()),
    }
}

/// The first of chromium, chromium-browser, google-chrome that runs; without one the test is
/// reported skipped (or fails under `FACET_REQUIRE_CHROMIUM=1`, as `.ci/run` sets).
fn chromium_for_tests(test: &str) -> Option<&'static str> {
    for name in ["chromium", "chromium-browser", "google-chrome"] {
        if Command::new(name)
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success())
        {
            return Some(name);
        }
    }
    let why = "no chromium, chromium-browser or google-chrome on PATH (apt-get install chromium)";
    if std::env::var("FACET_REQUIRE_CHROMIUM").is_ok_and(|v| v == "1") {
        panic!("{test}: FACET_REQUIRE_CHROMIUM=1 but {why}");
    }
    facet_gpu::report_skip(test, why);
    None
}

/// The page of one proxy, with a script appended that marks the document once every `<img>`
/// is `complete` with a `naturalWidth` above 0, loaded by headless Chromium: its DOM carries
/// the mark (and a failing image would have left it out).
#[test]
fn report_page_loads_in_a_browser_with_every_image() {
    const TEST: &str = "report_page_loads_in_a_browser_with_every_image";
    let Some(browser) = chromium_for_tests(TEST) else {
        return;
    };
    if facet_gpu::gpu_for_tests(TEST).is_none() {
        return;
    }
    let dir = scratch("report_browser");
    let (ok, stdout, stderr) = facet_in(
        &dir,
        &[
            "report",
            "nbrdf:gold-metallic-paint",
            "--out",
            "page",
            "--resolution",
            "16",
            "--spp",
            "1",
            "--fit-resolution",
            "32",
            "--sweep",
            "0",
        ],
    );
    assert!(ok, "{stdout}\n{stderr}");
    let page = dir.join("page");
    let html = std::fs::read_to_string(page.join("index.html")).unwrap();
    let n = image_sources(&html).len();
    let mark = "<script>window.addEventListener('load',()=>{const i=[...document.images];\
        const good=i.filter(x=>x.complete&&x.naturalWidth>0).length;\
        document.body.setAttribute('data-images',good+'/'+i.length);});</script>";
    let checked = page.join("browser-check.html");
    std::fs::write(&checked, html.replace("</body>", &format!("{mark}</body>"))).unwrap();
    let out = Command::new(browser)
        .args([
            "--headless",
            "--disable-gpu",
            "--no-sandbox",
            "--allow-file-access-from-files",
            "--virtual-time-budget=5000",
            "--dump-dom",
        ])
        .arg(format!(
            "file://{}",
            checked.canonicalize().unwrap().display()
        ))
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&out.stdout);
    let want = format!("data-images=\"{n}/{n}\"");
    assert!(
        dom.contains(&want),
        "expected {want} in the DOM; stderr:\n{}\nDOM head:\n{}",
        String::from_utf8_lossy(&out.stderr),
        &dom[..dom.len().min(2000)]
    );
}

/// Sharma, Wu & Dalal (2005), "The CIEDE2000 color-difference formula: implementation notes,
/// supplementary test data and mathematical observations", Table 1: pairs (L*, a*, b*) and
/// ΔE00, typed from the paper (pairs 1–4, 7, 13, 17–20, 25 and 34).
const SHARMA: [([f32; 3], [f32; 3], f32); 12] = [
    ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
    ([50.0, 3.1571, -77.2803], [50.0, 0.0, -82.7485], 2.8615),
    ([50.0, 2.8361, -74.0200], [50.0, 0.0, -82.7485], 3.4412),
    ([50.0, -1.3802, -84.2814], [50.0, 0.0, -82.7485], 1.0000),
    ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
    ([50.0, 2.4900, -0.0010], [50.0, -2.4900, 0.0009], 7.1792),
    ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
    ([50.0, 2.5, 0.0], [61.0, -5.0, 29.0], 22.8977),
    ([50.0, 2.5, 0.0], [56.0, -27.0, -3.0], 31.9030),
    ([50.0, 2.5, 0.0], [58.0, 24.0, 15.0], 19.4535),
    (
        [60.2574, -34.0099, 36.2677],
        [60.4626, -34.1751, 39.4387],
        1.2644,
    ),
    (
        [2.0776, 0.0795, -1.1350],
        [0.9033, -0.0636, -0.5514],
        0.9082,
    ),
];

/// The paper's ΔE00 to its 4 decimals: within 5·10⁻⁵ (its rounding) plus 2·10⁻⁴ for palette's
/// f32 arithmetic (ΔE of a few tens carries about 10⁻⁶ relative per operation).
#[test]
fn ciede2000_matches_sharma_wu_dalal_test_data() {
    for (a, b, want) in SHARMA {
        let lab_of = |v: [f32; 3]| Lab::new(v[0], v[1], v[2]);
        let got = ciede2000(lab_of(a), lab_of(b));
        assert!(
            (got - want).abs() < 2.5e-4,
            "{a:?} {b:?}: {got} against {want}"
        );
        // Symmetric, as the formula is.
        let back = ciede2000(lab_of(b), lab_of(a));
        assert!(
            (back - want).abs() < 2.5e-4,
            "{b:?} {a:?}: {back} against {want}"
        );
    }
}

/// The colour path: the tone map d = 1 − e^−L, then linear sRGB to CIELAB (D65). L = ∞ shows
/// white, L* = 100; L = ln 2 shows d = ½, L* = 116·(½)^⅓ − 16 = 76.069 (the CIE cube root, as
/// ½ > (6/29)³); linear sRGB red (1, 0, 0) is CIELAB (53.24, 80.09, 67.20) (its XYZ
/// (0.4124, 0.2126, 0.0193) over the D65 white (0.9505, 1, 1.089)).
#[test]
fn displayed_colours_have_the_expected_lab() {
    let white = lab(displayed([f32::INFINITY; 3]));
    assert!((white.l - 100.0).abs() < 1e-3 && white.a.abs() < 1e-3 && white.b.abs() < 1e-3);
    let grey = lab(displayed([std::f32::consts::LN_2; 3]));
    let l_half = 116.0 * 0.5f32.cbrt() - 16.0;
    assert!((grey.l - l_half).abs() < 1e-3, "{grey:?} against {l_half}");
    let red = lab(palette::LinSrgb::new(1.0, 0.0, 0.0));
    for (got, want) in [(red.l, 53.24), (red.a, 80.09), (red.b, 67.20)] {
        // The published values to 2 decimals (±0.005), and the primaries' own 4 digits.
        assert!((got - want).abs() < 0.02, "{red:?}");
    }
}

/// An image against itself: ΔE 0 (both differences) at every masked pixel, none elsewhere;
/// against a copy with one pixel changed, both above 1 there alone (a ΔE that is always 0 would
/// fail here).
#[test]
fn delta_e_of_an_image_against_itself_is_zero() {
    let pixels: Vec<[f32; 3]> = (0..64)
        .map(|i| [0.01 * i as f32, 0.3, 2.0 - 0.02 * i as f32])
        .collect();
    let image = Image {
        width: 8,
        height: 8,
        pixels,
        samples: vec![1; 64],
    };
    let mask = |x: u32, _y: u32| x < 6;
    let same = delta_e_image(&image, &image, &mask);
    assert_eq!(same.values.iter().flatten().count(), 48);
    assert!(
        same.values
            .iter()
            .flatten()
            .all(|v| v.de2000 == 0.0 && v.itp == 0.0)
    );
    let mean = same.mean();
    assert_eq!((mean.de2000, mean.itp), (0.0, 0.0));
    let mut other = image.clone();
    other.pixels[9] = [0.5, 0.1, 0.1];
    let diff = delta_e_image(&image, &other, &mask);
    let changed = diff.values[9].unwrap();
    assert!(changed.de2000 > 1.0 && changed.itp > 1.0, "{changed:?}");
    assert_eq!(
        diff.values
            .iter()
            .flatten()
            .filter(|v| v.de2000 > 0.0 || v.itp > 0.0)
            .count(),
        1
    );
}

/// The PQ inverse EOTF (SMPTE ST 2084) at the signal levels ITU-R BT.2408 publishes: 100 cd/m²
/// → 0.508 (50.8 %), 203 cd/m² → 0.58 (58 %, its HDR reference white), 1000 cd/m² → 0.752
/// (75.2 %), within half their last digit; 10 000 cd/m² → 1 and 0 → c1^m2 = 0.8359375^78.84375
/// = 7.3096·10⁻⁷ by the formula's own constants (to 10⁻¹⁰).
#[test]
fn pq_matches_published_signal_levels() {
    for (cd, want, within) in [
        (100.0, 0.508, 5e-4),
        (203.0, 0.58, 5e-3),
        (1000.0, 0.752, 5e-4),
        (10_000.0, 1.0, 1e-12),
        (0.0, 7.309_56e-7, 1e-10),
    ] {
        let got = pq(cd);
        assert!((got - want).abs() < within, "PQ({cd}) = {got}, want {want}");
    }
}

/// The Rec. 709 → BT.2020 matrix: each row sums to 1 (D65 white to D65 white, to 10⁻¹²), and
/// it is ITU-R BT.2087's printed matrix within its 4 decimals' rounding (5·10⁻⁵).
#[test]
fn rec709_to_rec2020_is_bt2087s_matrix() {
    let printed = [
        [0.6274, 0.3293, 0.0433],
        [0.0691, 0.9195, 0.0114],
        [0.0164, 0.0880, 0.8956],
    ];
    for (row, want) in REC709_TO_REC2020.iter().zip(printed) {
        assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-12, "{row:?}");
        for (got, want) in row.iter().zip(want) {
            assert!((got - want).abs() <= 5e-5, "{row:?} against {want}");
        }
    }
}

/// ICtCp and ΔE_ITP against values computed independently, in Python (double precision), from
/// the BT.2100 and BT.2124 formulas as published: the 709 → 2020 matrix derived in exact
/// fractions from the two sets of primaries and D65 (0.3127, 0.3290); LMS = [1688 2146 262;
/// 683 2951 462; 99 309 3688]/4096 · RGB₂₀₂₀ · 203 cd/m²; PQ with m1 = 2610/16384,
/// m2 = 2523/4096·128, c1 = 3424/4096, c2 = 2413/4096·32, c3 = 2392/4096·32 on Y = Fd/10000;
/// I = ½L′ + ½M′, Ct = (6610 L′ − 13613 M′ + 7003 S′)/4096, Cp = (17933 L′ − 17390 M′ −
/// 543 S′)/4096; ΔE_ITP = 720 √(ΔI² + (½ΔCt)² + ΔCp²). The inputs are exact in f32 (dyadic),
/// so the only differences are double rounding (about 10⁻¹⁵ relative): 10⁻⁹ covers them with
/// room. White shows I = PQ(203) and Ct = Cp = 0 by theory (the LMS rows sum to 4096 and the
/// Ct and Cp rows to 0).
#[test]
fn ictcp_and_delta_e_itp_match_independent_values() {
    assert_eq!(REFERENCE_WHITE, 203.0);
    let rgb = |c: [f32; 3]| LinSrgb::new(c[0], c[1], c[2]);
    let white = ictcp(rgb([1.0; 3]));
    assert!((white[0] - pq(203.0)).abs() < 1e-12, "{white:?}");
    assert!(
        white[1].abs() < 1e-12 && white[2].abs() < 1e-12,
        "{white:?}"
    );
    let colours: [([f32; 3], [f64; 3]); 4] = [
        (
            [1.0, 0.0, 0.0],
            [
                0.42788028436228087,
                -0.11570435976966692,
                0.2787289473753569,
            ],
        ),
        (
            [0.0, 1.0, 0.0],
            [
                0.5397602802111274,
                -0.28124791880456723,
                -0.04948450651597002,
            ],
        ),
        (
            [0.0, 0.0, 1.0],
            [
                0.35598362802705463,
                0.2693341555682033,
                -0.16137109768327434,
            ],
        ),
        (
            [0.5, 0.25, 0.125],
            [
                0.45709449739191776,
                -0.06778701164057643,
                0.06341792416056771,
            ],
        ),
    ];
    for (c, want) in colours {
        let got = ictcp(rgb(c));
        for k in 0..3 {
            assert!(
                (got[k] - want[k]).abs() < 1e-9,
                "{c:?}: {got:?} against {want:?}"
            );
        }
    }
    let pairs: [([f32; 3], [f32; 3], f64); 5] = [
        ([0.5, 0.5, 0.5], [0.5078125, 0.5, 0.5], 0.751123846162787),
        (
            [0.5, 0.25, 0.125],
            [0.4375, 0.28125, 0.125],
            13.528704623814072,
        ),
        ([1.0, 1.0, 1.0], [0.875, 0.875, 0.875], 10.016530201019798),
        (
            [0.015625, 0.03125, 0.0078125],
            [0.0234375, 0.03125, 0.01171875],
            12.312849615665444,
        ),
        ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 256.68012347128337),
    ];
    for (a, b, want) in pairs {
        let got = delta_e_itp(ictcp(rgb(a)), ictcp(rgb(b)));
        assert!(
            (got - want).abs() < 1e-9 * want,
            "{a:?} {b:?}: {got} against {want}"
        );
        // Symmetric, and 0 against itself.
        assert_eq!(got, delta_e_itp(ictcp(rgb(b)), ictcp(rgb(a))));
        assert_eq!(delta_e_itp(ictcp(rgb(a)), ictcp(rgb(a))), 0.0);
    }
}

/// `--force` writes into a folder that holds files, but never over an input: a fit JSON named
/// `index.html` in `--out`, or an input (or the `--env` map) in `--out/img/`, is refused before
/// anything is written, naming it, and is left as it was. (Refused before the GPU is asked for,
/// so it runs without an adapter.)
#[test]
fn the_report_never_replaces_its_inputs() {
    let dir = scratch("report_inputs_kept");
    let (fit, _) = gold_fit_record(&dir);
    std::fs::create_dir_all(dir.join("page/img")).unwrap();
    let index = dir.join("page/index.html");
    std::fs::copy(&fit, &index).unwrap();
    let in_img = dir.join("page/img/gold.json");
    std::fs::copy(&fit, &in_img).unwrap();
    let before = std::fs::read(&fit).unwrap();
    for args in [
        vec!["report", "page/index.html"],
        vec!["report", "page/img/gold.json"],
        vec!["report", "fits/../page/img/gold.json"],
        vec![
            "report",
            "analytic:ggx?alpha=0.2",
            "--env",
            "page/img/gold.json",
        ],
    ] {
        let mut all = args.clone();
        all.extend(["--out", "page", "--force"]);
        let (ok, _, stderr) = facet_in(&dir, &all);
        assert!(
            !ok && stderr.contains("would replace this input"),
            "{args:?}: {stderr}"
        );
        assert!(
            stderr.contains("page/index.html") || stderr.contains("gold.json"),
            "{stderr}"
        );
    }
    assert_eq!(std::fs::read(&index).unwrap(), before);
    assert_eq!(std::fs::read(&in_img).unwrap(), before);
}
