//! The report's plots, as SVG by plotters (no fonts needed: the SVG names a generic family):
//! a material's NDFs (log scale) and Fresnel curves, the N sweep's time against error, and the
//! ΔE colour scale.

use crate::IMG;
use crate::error::{ReportError, Result};
use crate::false_colour::{DE_MAX, colour};
use crate::sweep::SweepPoint;
use facet_fit::model::material::FittedMaterial;
use glam::DVec3;
use plotters::prelude::*;
use std::path::Path;

const SIZE: (u32, u32) = (420, 300);

/// The page-relative path of a material's NDF plot.
pub fn ndf_file(stem: &str) -> String {
    format!("{IMG}/{stem}-ndf.svg")
}

/// The page-relative path of a material's Fresnel plot.
pub fn fresnel_file(stem: &str) -> String {
    format!("{IMG}/{stem}-fresnel.svg")
}

/// The page-relative path of the ΔE colour scale.
pub const SCALE_FILE: &str = "img/delta-e-scale.svg";
/// The page-relative path of the sweep plot.
pub const SWEEP_FILE: &str = "img/sweep.svg";

fn plot_error<E: std::fmt::Debug>(e: E) -> ReportError {
    ReportError::Plot(format!("{e:?}"))
}

/// D(θh) at φ = 0 of the extracted NDF, of the GGX and Beckmann fits and, for a fit that kept a
/// coat, of the base's extracted NDF under it; θh in 0°–89°, on a log axis from 10⁻⁴ of the
/// largest value.
pub fn write_ndf_plot(fit: &FittedMaterial, path: &Path) -> Result<()> {
    let thetas: Vec<f64> = (0..=178).map(|k| 0.5 * k as f64).collect();
    let h = |deg: f64| {
        let t = deg.to_radians();
        DVec3::new(t.sin(), 0.0, t.cos())
    };
    let mut curves = vec![("extracted", RGBColor(0, 0, 0), &fit.tabulated)];
    if let Some(m) = &fit.ggx {
        curves.push(("GGX", RGBColor(214, 39, 40), m));
    }
    if let Some(m) = &fit.beckmann {
        curves.push(("Beckmann", RGBColor(31, 119, 180), m));
    }
    if let Some(c) = &fit.coated {
        curves.push((
            "base under the coat",
            RGBColor(140, 140, 140),
            &c.base.tabulated,
        ));
    }
    let series: Vec<_> = curves
        .iter()
        .map(|(name, c, m)| {
            let pts: Vec<(f64, f64)> = thetas.iter().map(|&t| (t, m.ndf.d(h(t)))).collect();
            (*name, *c, pts)
        })
        .collect();
    let top = series
        .iter()
        .flat_map(|s| s.2.iter().map(|p| p.1))
        .fold(1e-12f64, f64::max);
    let (lo, hi) = (top * 1e-4, top * 2.0);
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("NDF D(θh)", ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(52)
        .build_cartesian_2d(0f64..90f64, (lo..hi).log_scale())
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("θh (degrees)")
        .y_desc("D")
        .draw()
        .map_err(plot_error)?;
    for (name, c, pts) in series {
        let clipped = pts.into_iter().map(|(t, d)| (t, d.clamp(lo, hi)));
        chart
            .draw_series(LineSeries::new(clipped, c.stroke_width(2)))
            .map_err(plot_error)?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], c.stroke_width(2)));
    }
    legend(&mut chart)?;
    root.present().map_err(plot_error)
}

/// F(θd) per channel: the tabulated model's (thick) and the GGX fit's (thin).
pub fn write_fresnel_plot(fit: &FittedMaterial, path: &Path) -> Result<()> {
    let thetas: Vec<f64> = (0..=180).map(|k| 0.5 * k as f64).collect();
    let channels = [
        ("R", RGBColor(214, 39, 40)),
        ("G", RGBColor(44, 160, 44)),
        ("B", RGBColor(31, 119, 180)),
    ];
    let root = SVGBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let mut chart = ChartBuilder::on(&root)
        .caption("Fresnel F(θd)", ("sans-serif", 16))
        .margin(8)
        .x_label_area_size(32)
        .y_label_area_size(44)
        .build_cartesian_2d(0f64..90f64, 0f64..1.05f64)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("θd (degrees)")
        .y_desc("F")
        .draw()
        .map_err(plot_error)?;
    let mut models = vec![("tabulated", &fit.tabulated, 2)];
    if let Some(m) = &fit.ggx {
        models.push(("GGX", m, 1));
    }
    for (model, m, width) in models {
        for (k, (ch, c)) in channels.iter().enumerate() {
            let pts = thetas
                .iter()
                .map(|&t| (t, m.fresnel.eval(t.to_radians().cos())[k].clamp(0.0, 1.05)));
            let (c, label) = (*c, format!("{model} {ch}"));
            chart
                .draw_series(LineSeries::new(pts, c.stroke_width(width)))
                .map_err(plot_error)?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 16, y)], c.stroke_width(width))
                });
        }
    }
    legend(&mut chart)?;
    root.present().map_err(plot_error)
}

/// The series labels in a box at the upper right.
fn legend<'a, X, Y>(chart: &mut ChartContext<'a, SVGBackend<'a>, Cartesian2d<X, Y>>) -> Result<()>
where
    X: plotters::coord::ranged1d::Ranged,
    Y: plotters::coord::ranged1d::Ranged,
{
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 11))
        .draw()
        .map_err(plot_error)
}

/// Run time against error of the N sweep: per material and model, the fits at each N joined
/// by a line, N written beside each point.
pub fn write_sweep_plot(points: &[SweepPoint], path: &Path) -> Result<()> {
    let models = [
        ("tabulated", RGBColor(0, 0, 0)),
        ("GGX", RGBColor(214, 39, 40)),
        ("Beckmann", RGBColor(31, 119, 180)),
    ];
    let t_max = points.iter().map(|p| p.seconds).fold(1e-3, f64::max) * 1.1;
    let errors = points
        .iter()
        .flat_map(|p| p.errors.iter().flatten().copied());
    let e_max = errors.clone().fold(1e-9, f64::max) * 1.5;
    let e_min = errors.fold(e_max, f64::min) / 1.5;
    let root = SVGBackend::new(path, (640, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "fit time against error, N = 32, 64, 90, 128",
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(0f64..t_max, (e_min..e_max).log_scale())
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("fit time (s)")
        .y_desc(format!(
            "error ({} metric)",
            points.first().map_or("", |p| p.metric.name())
        ))
        .draw()
        .map_err(plot_error)?;
    let mut materials: Vec<&str> = points.iter().map(|p| p.material.as_str()).collect();
    materials.dedup();
    for (k, (model, c)) in models.iter().enumerate() {
        let c = *c;
        for (i, material) in materials.iter().enumerate() {
            let pts: Vec<(f64, f64, usize)> = points
                .iter()
                .filter(|p| p.material == *material)
                .filter_map(|p| p.errors[k].map(|e| (p.seconds, e, p.resolution)))
                .collect();
            let series = chart
                .draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.0, p.1)),
                    c.stroke_width(1),
                ))
                .map_err(plot_error)?;
            if i == 0 {
                series
                    .label(*model)
                    .legend(move |(x, y)| PathElement::new([(x, y), (x + 16, y)], c));
            }
            chart
                .draw_series(pts.iter().map(|&(t, e, n)| {
                    EmptyElement::at((t, e))
                        + Circle::new((0, 0), 3, c.filled())
                        + Text::new(format!("{n}"), (4, -10), ("sans-serif", 10))
                }))
                .map_err(plot_error)?;
        }
    }
    legend(&mut chart)?;
    root.present().map_err(plot_error)
}

/// The ΔE colour scale: a bar from 0 to [`DE_MAX`] with ticks every 2 (written by hand: a few
/// rectangles and labels).
pub fn write_scale(path: &Path) -> Result<()> {
    let (w, bar_h, steps) = (400.0, 18.0, 100);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"44\" font-family=\"sans-serif\" font-size=\"11\">\n",
        w + 40.0
    );
    for k in 0..steps {
        let de = DE_MAX * (k as f32 + 0.5) / steps as f32;
        let [r, g, b] = colour(de);
        let x = 10.0 + w * k as f64 / steps as f64;
        s += &format!(
            "<rect x=\"{x:.1}\" y=\"2\" width=\"{:.2}\" height=\"{bar_h}\" fill=\"rgb({r},{g},{b})\"/>\n",
            w / steps as f64 + 0.3
        );
    }
    for tick in (0..=DE_MAX as u32).step_by(2) {
        let x = 10.0 + w * tick as f64 / DE_MAX as f64;
        let plus = if tick == DE_MAX as u32 { "+" } else { "" };
        s += &format!(
            "<line x1=\"{x:.1}\" y1=\"{bar_h}\" x2=\"{x:.1}\" y2=\"{:.0}\" stroke=\"black\"/>\n<text x=\"{x:.1}\" y=\"38\" text-anchor=\"middle\">{tick}{plus}</text>\n",
            bar_h + 6.0
        );
    }
    s += "</svg>\n";
    std::fs::write(path, s).map_err(ReportError::write(path))
}
