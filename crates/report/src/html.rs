//! The page: one self-contained `index.html` (inline CSS and a few lines of inline JS to sort
//! the table), its images as PNG and SVG files in `img/` beside it.

use crate::delta_e::{DePair, NAMES, REFERENCE_WHITE};
use crate::false_colour::DE_MAX;
use crate::material::{MaterialReport, de_file, floor_file, reference, render_file, variants};
use crate::plots::{SCALE_FILE, SWEEP_FILE, fresnel_file, ndf_file};
use crate::scenes::{ENV_DEPTH, Lighting, N_MODELS, POINT_SPP, Variant};
use crate::sweep::SweepPoint;
use facet_fit::model::metric::Metric;
use std::fmt::Write;

/// What the page says about the run.
pub struct PageInfo {
    /// The adapter the spheres were rendered on, in words.
    pub adapter: String,
    /// Side of each sphere image, pixels.
    pub side: u32,
    /// Samples per pixel of the environment renders.
    pub env_spp: u32,
    /// Polar nodes N of the fits.
    pub resolution: usize,
    /// When a coat was searched (`--coat`).
    pub coat: &'static str,
    /// The environment map's name.
    pub env: String,
    /// The run's wall time, seconds.
    pub seconds: f64,
    /// Facet's version.
    pub version: &'static str,
}

/// The page-relative path of the database's mean ΔE image of one lighting and model.
pub fn mean_de_file(lighting: Lighting, model: usize) -> String {
    format!(
        "img/mean-{}-de-{}.png",
        lighting.key(),
        Variant::MODELS[model].key()
    )
}

/// A model's short name in the table's headers.
fn label(model: Variant) -> &'static str {
    match model {
        Variant::Model(facet_fit::model::material::ModelChoice::Tabulated) => "tab",
        Variant::Model(facet_fit::model::material::ModelChoice::Ggx) => "GGX",
        Variant::Model(facet_fit::model::material::ModelChoice::Beckmann) => "Beck",
        Variant::Coated => "coated",
        Variant::Measured => "measured",
    }
}

const STYLE: &str = "body{font-family:sans-serif;margin:1.5em;max-width:1400px}\
table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;padding:2px 6px;\
text-align:right}th{background:#eee}thead tr:last-child th{cursor:pointer}\
td:first-child{text-align:left}.scroll{overflow-x:auto}\
figure{display:inline-block;margin:4px;text-align:center;font-size:12px}\
figure img{display:block}section{border-top:1px solid #999;margin-top:1.5em}";

/// Sorts the table by the clicked column (a cell of the last header row): numbers as numbers,
/// the rest as text; a second click reverses.
const SORT_JS: &str = "document.querySelectorAll('table.sortable thead tr:last-child th')\
.forEach(th=>{th.onclick=()=>{const i=th.cellIndex;const b=th.closest('table').tBodies[0];const rows=[...b.rows];\
const asc=th.dataset.asc!=='1';th.dataset.asc=asc?'1':'0';\
const v=r=>{const t=r.cells[i].textContent;const n=parseFloat(t);return isNaN(n)?t:n};\
rows.sort((x,y)=>{const a=v(x),c=v(y);return (a<c?-1:a>c?1:0)*(asc?1:-1)});\
rows.forEach(r=>b.appendChild(r));}});";

/// `<`, `>`, `&` and `"` escaped.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("–".into(), |v| format!("{v:.digits$}"))
}

/// The mean of `values` (`None` when empty).
fn mean(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64)
}

/// The mean over the set of each lighting's and model's mean ΔE2000 and ΔE_ITP (`None` where
/// no material has one).
pub fn set_means(materials: &[MaterialReport]) -> [[Option<DePair<f64>>; N_MODELS]; 2] {
    std::array::from_fn(|l| {
        std::array::from_fn(|m| {
            let v: Vec<DePair<f64>> = materials.iter().filter_map(|r| r.mean_de[l][m]).collect();
            let de2000 = mean(&v.iter().map(|p| p.de2000).collect::<Vec<_>>())?;
            let itp = mean(&v.iter().map(|p| p.itp).collect::<Vec<_>>())?;
            Some(DePair { de2000, itp })
        })
    })
}

/// The mean and the median over the set of the noise floor, per lighting and difference
/// ([`DePair::both`] order).
pub fn floor_stats(materials: &[MaterialReport]) -> [[(f64, f64); 2]; 2] {
    std::array::from_fn(|l| {
        std::array::from_fn(|d| {
            let mut v: Vec<f64> = materials.iter().map(|m| m.floor[l].both()[d]).collect();
            v.sort_by(f64::total_cmp);
            let median = match v.len() {
                0 => 0.0,
                n if n % 2 == 1 => v[n / 2],
                n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
            };
            (mean(&v).unwrap_or(0.0), median)
        })
    })
}

/// The whole page.
pub fn page(info: &PageInfo, materials: &[MaterialReport], sweep: &[SweepPoint]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>Facet report</title><style>{STYLE}</style></head><body>\n"
    );
    s += &header(info, materials.len());
    let _ = writeln!(
        s,
        "<p>The metric the fits minimised: {}. The errors are given in both metrics: {}; {}.</p>",
        minimised(materials),
        metric_words(METRICS[0]),
        metric_words(METRICS[1])
    );
    s += &summary(materials);
    if !sweep.is_empty() {
        s += &sweep_section(sweep);
    }
    for m in materials {
        s += &material_section(m);
    }
    let _ = write!(s, "<script>{SORT_JS}</script>\n</body></html>\n");
    s
}

fn header(info: &PageInfo, n: usize) -> String {
    format!(
        "<h1>Facet report: {n} material(s)</h1>\n<p>Facet {}; adapter {}; {:.1} s in all. \
         Fits: isotropic, N = {} polar nodes, a diffuse lobe with every model; {}. Spheres {side}×{side} \
         pixels: (a) one point light, no environment, depth 1, {POINT_SPP} spp (only the pixel \
         positions vary: each pixel is f cos θ I / r²); (b) the environment {}, depth {ENV_DEPTH}, \
         {} spp; both with Owen-scrambled Sobol points, every sphere at the same seed.</p>\n<p>ΔE per pixel on the sphere (silhouette excluded) of each \
         model against the measurement (or, for a fit JSON, against the model it stands for as \
         a source: its coated tabulated model when it kept a coat, else its tabulated model), on \
         the colours the PNGs show: the tone map 1 − exp(−L) at exposure 0 read as linear \
         sRGB. Two differences: <b>ΔE2000</b> (CIEDE2000, CIELAB D65, by the <code>palette</code> \
         crate) and <b>ΔE_ITP</b> (ITU-R BT.2124: to BT.2020, display white at {REFERENCE_WHITE} \
         cd/m² — BT.2408's HDR reference white —, ICtCp with PQ; one unit about one \
         just-noticeable difference). The images show ΔE2000 in false colour: viridis from 0 \
         to {DE_MAX} (and above).</p>\n<img src=\"{SCALE_FILE}\" alt=\"ΔE colour scale\">\n",
        info.version,
        escape(&info.adapter),
        info.seconds,
        info.resolution,
        info.coat,
        escape(&info.env),
        info.env_spp,
        side = info.side,
    )
}

fn summary(materials: &[MaterialReport]) -> String {
    let means = set_means(materials);
    let mut s = String::from("<section><h2>Database summary</h2>\n");
    s += &means_table(materials, &means);
    s += &sortable_table(materials);
    s += "<h3>Mean ΔE2000 image over the set</h3>\n";
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        for (k, model) in Variant::MODELS.iter().enumerate() {
            if means[l][k].is_some() {
                s += &figure(
                    &mean_de_file(*lighting, k),
                    &format!("{} {}", model.key(), lighting.key()),
                );
            }
        }
        s += "<br>\n";
    }
    s + "</section>\n"
}

/// The mean ΔE2000 and ΔE_ITP per model over the set, a row per lighting and difference.
fn means_table(
    materials: &[MaterialReport],
    means: &[[Option<DePair<f64>>; N_MODELS]; 2],
) -> String {
    let with_coat = materials.iter().filter(|m| m.coated).count();
    let floors = floor_stats(materials);
    let mut s = format!(
        "<p>Mean over the set ({} material(s); the coated model's over the {with_coat} whose \
         fit kept a coat), and the noise floor — the reference rendered again at another seed \
         against itself: the ΔE of the renders' noise alone, mean and median over the set. A \
         model's ΔE near the floor is within the noise.</p>\n<table><tr><th>lighting</th>\
         <th>difference</th>",
        materials.len()
    );
    for model in Variant::MODELS {
        let _ = write!(s, "<th>{}</th>", label(model));
    }
    s += "<th>noise floor (mean)</th><th>noise floor (median)</th></tr>\n";
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        for (d, name) in NAMES.iter().enumerate() {
            let _ = write!(
                s,
                "<tr><td>{}</td><td>{name}</td>",
                lighting_name(*lighting)
            );
            for v in means[l] {
                let _ = write!(s, "<td>{}</td>", fmt_opt(v.map(|v| v.both()[d]), 2));
            }
            let (mean, median) = floors[l][d];
            let _ = writeln!(s, "<td>{mean:.2}</td><td>{median:.2}</td></tr>");
        }
    }
    s + "</table>\n"
}

/// The sortable table: a row per material; per lighting and difference, the mean over the
/// sphere per model and the noise floor; the metric the fit minimised and each model's error
/// in both metrics; the times. Two header rows: the groups, then
/// the columns (click one to sort).
fn sortable_table(materials: &[MaterialReport]) -> String {
    let mut s =
        String::from("<div class=\"scroll\"><table class=\"sortable\"><thead><tr><th></th>");
    for lighting in Lighting::ALL {
        for name in NAMES {
            let _ = write!(
                s,
                "<th colspan=\"{}\">{name}, {}</th>",
                N_MODELS + 1,
                lighting_name(lighting)
            );
        }
    }
    s += "<th></th>";
    for metric in METRICS {
        let _ = write!(
            s,
            "<th colspan=\"{N_MODELS}\">error, {} metric</th>",
            metric.name()
        );
    }
    s += "<th colspan=\"2\">time (s)</th></tr>\n<tr><th>material</th>";
    for group in 0..2 * NAMES.len() + METRICS.len() {
        // The ΔE groups end with the noise floor; the errors' groups follow the metric
        // minimised.
        if group == 2 * NAMES.len() {
            s += "<th>minimised</th>";
        }
        for model in Variant::MODELS {
            let _ = write!(s, "<th>{}</th>", label(model));
        }
        if group < 2 * NAMES.len() {
            s += "<th>noise</th>";
        }
    }
    s += "<th>fit</th><th>render</th></tr></thead><tbody>\n";
    for m in materials {
        s += &table_row(m);
    }
    s + "</tbody></table></div>\n"
}

/// One material's row of the sortable table.
fn table_row(m: &MaterialReport) -> String {
    let mut s = format!(
        "<tr><td><a href=\"#{}\">{}</a></td>",
        escape(&m.stem),
        escape(&m.name)
    );
    for l in 0..2 {
        for d in 0..NAMES.len() {
            for v in m.mean_de[l] {
                let _ = write!(s, "<td>{}</td>", fmt_opt(v.map(|v| v.both()[d]), 2));
            }
            let _ = write!(s, "<td>{:.2}</td>", m.floor[l].both()[d]);
        }
    }
    let _ = write!(s, "<td>{}</td>", m.record.metric.name());
    for metric in METRICS {
        for e in errors(m, metric) {
            let _ = write!(s, "<td>{}</td>", fmt_opt(e, 4));
        }
    }
    let _ = writeln!(
        s,
        "<td>{:.2}</td><td>{:.2}</td></tr>",
        m.fit_ms / 1e3,
        m.render_ms / 1e3
    );
    s
}

fn lighting_name(l: Lighting) -> &'static str {
    match l {
        Lighting::Point => "point light",
        Lighting::Environment => "environment",
    }
}

/// The metrics of the error columns, in the page's order.
const METRICS: [Metric; 2] = [Metric::Perceptual, Metric::Log];

/// Each model's error in `metric` ([`Variant::MODELS`] order: the tabulated, GGX and Beckmann
/// single layers and the coated tabulated model): the record's own errors where the fit
/// minimised `metric`, else its errors in the other metric (`None` where it has none).
fn errors(m: &MaterialReport, metric: Metric) -> [Option<f64>; N_MODELS] {
    let r = &m.record;
    if r.metric == metric {
        return [
            r.tabulated.error,
            r.ggx.as_ref().map(|p| p.error),
            r.beckmann.as_ref().map(|p| p.error),
            r.coat.as_ref().map(|c| c.error),
        ];
    }
    match &r.other_metric {
        Some(o) if o.metric == metric => [o.tabulated, o.ggx, o.beckmann, o.coated],
        _ => [None; N_MODELS],
    }
}

/// What a metric measures, for the page.
fn metric_words(metric: Metric) -> String {
    let floor = match metric {
        Metric::Log => "1".to_owned(),
        Metric::Perceptual => format!(
            "{} × the material's median x, at least {}",
            Metric::RELATIVE_FLOOR,
            Metric::MIN_FLOOR
        ),
    };
    format!(
        "<b>{}</b>: the mean over the MERL grid of |ln(1 + x_model/ε) − ln(1 + x_data/ε)|, \
         x = f cos θi, ε = {floor}",
        metric.name(),
    )
}

/// Which metric the set's fits minimised: each metric with its count.
fn minimised(materials: &[MaterialReport]) -> String {
    let counts: Vec<String> = METRICS
        .iter()
        .filter_map(|&metric| {
            let n = materials
                .iter()
                .filter(|m| m.record.metric == metric)
                .count();
            (n > 0).then(|| format!("{} ({n} of {})", metric.name(), materials.len()))
        })
        .collect();
    counts.join(", ")
}

fn figure(src: &str, caption: &str) -> String {
    format!(
        "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
        escape(src),
        escape(caption),
        escape(caption)
    )
}

fn sweep_section(points: &[SweepPoint]) -> String {
    let metric = points.first().map_or("", |p| p.metric.name());
    let mut s = format!(
        "<section><h2>Run time against error</h2>\n<img src=\"{SWEEP_FILE}\" alt=\"sweep\">\n\
         <table><thead><tr><th>material</th><th>N</th><th>fit (s)</th><th>power iteration (ms)</th><th>error tab ({metric})</th>\
         <th>error GGX ({metric})</th><th>error Beck ({metric})</th></tr></thead><tbody>\n"
    );
    for p in points {
        let _ = write!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{:.3}</td><td>{:.1}</td>",
            escape(&p.material),
            p.resolution,
            p.seconds,
            1e3 * p.extract_seconds
        );
        // Six significant digits: the errors may differ in the fourth.
        for e in p.errors {
            let _ = write!(
                s,
                "<td>{}</td>",
                e.map_or("–".into(), |e| format!("{e:.5e}"))
            );
        }
        s += "</tr>\n";
    }
    s + "</tbody></table></section>\n"
}

fn material_section(m: &MaterialReport) -> String {
    let reference = match reference(m.measured, m.coated) {
        Variant::Measured => "the measurement",
        Variant::Coated => "the coated model (a fit JSON: no measurement to render)",
        _ => "the tabulated model (a fit JSON: no measurement to render)",
    };
    let mut s = format!(
        "<section id=\"{}\"><h2>{}</h2>\n<p>Input <code>{}</code>; ΔE against {reference}; the noise floor: \
         {reference} rendered again at another seed, against its first render.</p>\n",
        escape(&m.stem),
        escape(&m.name),
        escape(&m.input)
    );
    for (l, lighting) in Lighting::ALL.iter().enumerate() {
        let _ = writeln!(s, "<h3>{}</h3>", lighting_name(*lighting));
        for v in variants(m.measured, m.coated) {
            s += &figure(&render_file(&m.stem, *lighting, v), v.key());
        }
        s += "<br>\n";
        for (k, model) in Variant::MODELS.iter().enumerate() {
            if let Some(mean) = m.mean_de[l][k] {
                s += &figure(
                    &de_file(&m.stem, *lighting, *model),
                    &format!(
                        "{}: ΔE2000 {:.2}, ΔE_ITP {:.2}",
                        model.key(),
                        mean.de2000,
                        mean.itp
                    ),
                );
            }
        }
        let floor = m.floor[l];
        s += &figure(
            &floor_file(&m.stem, *lighting),
            &format!(
                "noise floor: ΔE2000 {:.2}, ΔE_ITP {:.2}",
                floor.de2000, floor.itp
            ),
        );
        s += "<br>\n";
    }
    s += &figure(&ndf_file(&m.stem), "NDF (log scale)");
    s += &figure(&fresnel_file(&m.stem), "Fresnel");
    s += &record_table(m);
    s + "</section>\n"
}

/// The fit's errors in both metrics, its parameters and times.
fn record_table(m: &MaterialReport) -> String {
    let r = &m.record;
    let t = &r.timings_ms;
    let e = METRICS.map(|metric| errors(m, metric));
    let cells = |k: usize| -> String {
        e.iter()
            .map(|e| format!("<td>{}</td>", fmt_opt(e[k], 4)))
            .collect()
    };
    let alpha = |p: &Option<facet_fit::model::material::ParamRecord>| {
        p.as_ref()
            .map_or("–".into(), |p| format!("α {:.4}", p.alpha_x))
    };
    let coated = r.coat.as_ref().map_or(String::new(), |c| {
        format!(
            "<tr><td>coated</td>{}<td>coat η {}, α {:.4}, weight {:.3} over the base's \
             tabulated model (its own fit under the coat: N = {}, {} iterations)</td></tr>",
            cells(3),
            c.coat.eta,
            c.coat.alpha,
            c.coat.weight,
            c.base.resolution,
            c.base.iterations
        )
    });
    let heads: String = METRICS
        .iter()
        .map(|&metric| {
            let mark = if metric == r.metric {
                ", minimised"
            } else {
                ""
            };
            format!("<th>error ({}{mark})</th>", metric.name())
        })
        .collect();
    format!(
        "<p>The fit minimised the {} metric.</p>\n<table><tr><th>model</th>{heads}\
         <th>parameters</th></tr>\
         <tr><td>tabulated</td>{}<td>N = {}, {} iterations</td></tr>\
         <tr><td>GGX</td>{}<td>{}</td></tr>\
         <tr><td>Beckmann</td>{}<td>{}</td></tr>{coated}</table>\n\
         <p>Fit times (ms): load {:.0}, extract {:.0}, Fresnel and diffuse {:.0}, fits {:.0}, \
         coat search {:.0}, total {:.0}; fit here {:.0} ms, renders {:.0} ms.</p>\n",
        r.metric.name(),
        cells(0),
        r.resolution,
        r.iterations,
        cells(1),
        alpha(&r.ggx),
        cells(2),
        alpha(&r.beckmann),
        t.load,
        t.extract,
        t.fresnel,
        t.fit,
        t.coat,
        t.total,
        m.fit_ms,
        m.render_ms
    )
}
