//! Plots drawn with egui's painter: an NDF slice (log scale) of the data's fit and of the
//! edited model, the Fresnel curve per channel, the fit errors.

use crate::material::{EditedMaterial, MaterialKey, Shown};
use egui::{Color32, Pos2, Rect, Stroke, Ui, pos2, vec2};
use facet_fit::model::material::FittedMaterial;
use glam::DVec3;
use std::sync::{Arc, Mutex};

static EDITED: Mutex<Option<(MaterialKey, Arc<FittedMaterial>)>> = Mutex::new(None);

fn edited_fit(m: &EditedMaterial) -> Option<Arc<FittedMaterial>> {
    let key = m.key();
    let mut cache = EDITED.lock().unwrap();
    if let Some((k, f)) = cache.as_ref()
        && *k == key
    {
        return Some(f.clone());
    }
    let f = m.fitted().ok()?;
    *cache = Some((key, f.clone()));
    Some(f)
}

/// A frame with axes; returns the plot rect and a mapper from data to screen.
fn frame(
    ui: &mut Ui,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
) -> (egui::Painter, impl Fn(f64, f64) -> Pos2 + use<>) {
    ui.label(title);
    let w = ui.available_width().max(100.0);
    let (rect, _) = ui.allocate_exact_size(vec2(w, 140.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(20));
    let r: Rect = rect.shrink(4.0);
    let map = move |px: f64, py: f64| {
        let tx = ((px - x.0) / (x.1 - x.0)).clamp(0.0, 1.0) as f32;
        let ty = ((py - y.0) / (y.1 - y.0)).clamp(-0.05, 1.05) as f32;
        pos2(r.left() + tx * r.width(), r.bottom() - ty * r.height())
    };
    (painter, map)
}

fn legend(ui: &mut Ui, items: &[(&str, Color32)]) {
    ui.horizontal_wrapped(|ui| {
        for (name, c) in items {
            ui.colored_label(*c, format!("— {name}"));
        }
    });
}

pub fn plots(m: &EditedMaterial, ui: &mut Ui) {
    ui.heading("Plots");
    ndf_slice(m, ui);
    ui.add_space(8.0);
    fresnel_curves(m, ui);
    ui.add_space(8.0);
    fit_errors(m, ui);
}

/// The NDF slice at φ = 0 of the data's fit and of the edited model.
fn ndf_slice(m: &EditedMaterial, ui: &mut Ui) {
    // log10 D against θ in degrees.
    let thetas: Vec<f64> = (0..=160).map(|i| i as f64 * 0.5).collect();
    let slice = |ndf: &facet_fit::model::microfacet::Ndf| -> Vec<f64> {
        thetas
            .iter()
            .map(|t| {
                let t = t.to_radians();
                ndf.d(DVec3::new(t.sin(), 0.0, t.cos())).max(1e-6).log10()
            })
            .collect()
    };
    let data = slice(&m.base.tabulated.ndf);
    let choice = m.model();
    let edited = edited_fit(m);
    let model = edited
        .as_ref()
        .and_then(|f| f.model(choice))
        .map(|b| slice(&b.ndf));
    let (lo, hi) = data
        .iter()
        .chain(model.iter().flatten())
        .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    let (lo, hi) = (lo.max(hi - 8.0).floor(), hi.ceil().max(lo + 1.0));
    let (painter, map) = frame(
        ui,
        &format!("NDF slice φ = 0: log₁₀ D(θ), θ 0–80°, [{lo}, {hi}]"),
        (0.0, 80.0),
        (lo, hi),
    );
    let line = |vals: &[f64], c: Color32| {
        let pts: Vec<Pos2> = thetas.iter().zip(vals).map(|(t, v)| map(*t, *v)).collect();
        painter.add(egui::Shape::line(pts, Stroke::new(1.5, c)));
    };
    line(&data, Color32::from_rgb(120, 200, 255));
    if let Some(v) = &model {
        line(v, Color32::from_rgb(255, 180, 60));
    }
    legend(
        ui,
        &[
            ("data's fit (tabulated)", Color32::from_rgb(120, 200, 255)),
            (
                &format!("edited {}", m.shown.label()),
                Color32::from_rgb(255, 180, 60),
            ),
        ],
    );
}

/// F(θd) per channel of the edited model.
fn fresnel_curves(m: &EditedMaterial, ui: &mut Ui) {
    let rec = m.edited_record();
    let table = match m.lobe() {
        Shown::Ggx | Shown::Glint => rec.ggx.as_ref().map(|p| &p.fresnel),
        Shown::Beckmann => rec.beckmann.as_ref().map(|p| &p.fresnel),
        _ => None,
    }
    .unwrap_or(&rec.fresnel)
    .clone();
    let angles: Vec<f64> = (0..=90).map(|i| i as f64).collect();
    let vals: Vec<[f64; 3]> = angles.iter().map(|a| table.eval(a.to_radians())).collect();
    let fmax = vals
        .iter()
        .flat_map(|v| v.iter().copied())
        .fold(1e-6f64, f64::max)
        * 1.05;
    let (painter, map) = frame(
        ui,
        &format!("Fresnel F(θd), θd 0–90°, 0–{fmax:.3}"),
        (0.0, 90.0),
        (0.0, fmax),
    );
    for (c, col) in [
        Color32::from_rgb(255, 80, 80),
        Color32::from_rgb(80, 220, 80),
        Color32::from_rgb(90, 140, 255),
    ]
    .into_iter()
    .enumerate()
    {
        let pts: Vec<Pos2> = angles
            .iter()
            .zip(&vals)
            .map(|(a, v)| map(*a, v[c]))
            .collect();
        painter.add(egui::Shape::line(pts, Stroke::new(1.5, col)));
    }
}

/// The fit's recorded errors, as bars.
fn fit_errors(m: &EditedMaterial, ui: &mut Ui) {
    ui.label("Fit errors (relative, as recorded by the fit):");
    let r = &m.base.record;
    let rows = [
        ("tabulated", r.tabulated.error),
        ("GGX", r.ggx.as_ref().map(|p| p.error)),
        ("Beckmann", r.beckmann.as_ref().map(|p| p.error)),
    ];
    let emax = rows.iter().filter_map(|(_, e)| *e).fold(1e-9f64, f64::max);
    for (name, e) in rows {
        ui.horizontal(|ui| {
            ui.label(format!("{name:>10}"));
            match e {
                Some(e) => {
                    let (rect, _) = ui.allocate_exact_size(vec2(120.0, 12.0), egui::Sense::hover());
                    let w = (e / emax) as f32 * rect.width();
                    ui.painter().rect_filled(
                        Rect::from_min_size(rect.min, vec2(w.max(1.0), rect.height())),
                        1.0,
                        Color32::from_rgb(200, 160, 80),
                    );
                    ui.label(format!("{e:.4}"));
                }
                None => {
                    ui.label("not fitted");
                }
            }
        });
    }
    ui.label(format!(
        "eigenvector residual {:.2e}, {} iterations",
        r.residual, r.iterations
    ));
}
