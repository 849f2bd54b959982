//! The material panel: open, model choice, sliders, save.

use crate::app::ViewerApp;
use crate::material::{EditedMaterial, Shown};
use std::time::Instant;

pub fn material_panel(app: &mut ViewerApp, ui: &mut egui::Ui) {
    egui::Panel::left("material")
        .resizable(true)
        .default_size(340.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| contents(app, ui));
        });
}

fn contents(app: &mut ViewerApp, ui: &mut egui::Ui) {
    open_section(app, ui);
    let m = &mut app.material;
    let before = m.key();
    ui.label("Shown:");
    for s in Shown::ALL {
        let enabled = m.available(s);
        ui.add_enabled_ui(enabled, |ui| {
            ui.radio_value(&mut m.shown, s, s.label());
        });
    }
    // Picked while a fit runs: the choice holds for the fit when it arrives, too.
    if m.shown != before.shown && app.fit_job.is_some() {
        app.wanted = Some(m.shown);
    }
    let can_split = m.available(Shown::Measured) && app.gltf.is_none();
    ui.add_enabled_ui(can_split, |ui| {
        ui.checkbox(
            &mut app.split,
            "split: the measured data on the sphere's left half",
        )
        .on_disabled_hover_text("needs a measurement (not a fit JSON) and the sphere preview");
    });
    alpha_sliders(m, ui);
    diffuse_edit(m, ui);
    tint_edit(m, ui);
    if m.shown == Shown::Glint {
        glint_sliders(m, ui);
    }
    if m.has_coat() && m.shown != Shown::Measured {
        coat_sliders(m, ui);
    }
    if m.key() != before {
        app.edited_at = Some(Instant::now());
    }
    save_section(app, ui);
}

/// The open field, the neural proxies, the fit in progress, the last error, the source.
fn open_section(app: &mut ViewerApp, ui: &mut egui::Ui) {
    ui.heading("Material");
    let hint = ui
        .label("MERL file, fit JSON, nbrdf:NAME, analytic:SPEC, or a glTF scene (or drop a file):");
    ui.horizontal(|ui| {
        let r = ui
            .add(egui::TextEdit::singleline(&mut app.open_text).desired_width(200.0))
            .labelled_by(hint.id);
        let enter = r.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if ui.button("Open").clicked() || enter {
            let spec = app.open_text.clone();
            app.open(&spec);
        }
    });
    let mut chosen = None;
    egui::ComboBox::from_label("neural proxy")
        .selected_text("choose...")
        .height(300.0)
        .show_ui(ui, |ui| match app.proxies() {
            Ok(names) => {
                for name in names {
                    if ui.selectable_label(false, name).clicked() {
                        chosen = Some(format!("nbrdf:{name}"));
                    }
                }
            }
            Err(e) => {
                ui.label(format!("no proxies: {e}"));
            }
        });
    if let Some(spec) = chosen {
        app.open_text = spec.clone();
        app.open(&spec);
    }
    if let Some(job) = &app.fit_job {
        let what = format!("{}: {}", job.label, job.stage.lock().unwrap());
        job_line(ui, &what, job.started);
    }
    if let Some(job) = &app.scene_fit {
        let what = format!("the sampling NDF of {} for the scene", job.label);
        job_line(ui, &what, job.started);
    }
    if let Some(e) = app.error.clone() {
        ui.horizontal(|ui| {
            ui.colored_label(egui::Color32::from_rgb(230, 80, 60), format!("Error: {e}"));
            if ui.small_button("dismiss").clicked() {
                app.error = None;
            }
        });
    }
    ui.label(format!("Source: {}", app.material.source));
    ui.separator();
}

/// αx, αy (locked or not) and the rotation of the shown model, or the stretch of its
/// tabulated NDF.
fn alpha_sliders(m: &mut EditedMaterial, ui: &mut egui::Ui) {
    if let Some((mut ax, mut ay, rot)) = m.alpha() {
        let rot_deg0 = rot.to_degrees();
        let mut rot_deg = rot_deg0;
        let what = if m.lobe() == Shown::Tabulated {
            "stretch of the tabulated NDF"
        } else {
            "α of the model"
        };
        if m.coat_shown() {
            ui.label(format!("{what} (the base under the coat; ρd and tint too)"));
        } else {
            ui.label(what);
        }
        let old = (ax, ay);
        ui.add(
            egui::Slider::new(&mut ax, 0.01..=2.0)
                .logarithmic(true)
                .text("αx"),
        );
        ui.add(
            egui::Slider::new(&mut ay, 0.01..=2.0)
                .logarithmic(true)
                .text("αy"),
        );
        ui.checkbox(&mut m.lock, "lock (isotropic scaling)");
        if m.lock {
            if ax != old.0 && old.0 > 0.0 {
                ay = old.1 * ax / old.0;
            } else if ay != old.1 && old.1 > 0.0 {
                ax = old.0 * ay / old.1;
            }
        }
        ui.add(egui::Slider::new(&mut rot_deg, -90.0..=90.0).text("rotation °"));
        if (ax, ay) != old || rot_deg != rot_deg0 {
            let rot = if rot_deg != rot_deg0 {
                rot_deg.to_radians()
            } else {
                rot
            };
            m.set_alpha(ax, ay, rot);
        }
    } else {
        ui.label("The measurement itself is shown (no edits): its table on the GPU.");
    }
}

/// The diffuse albedo ρd, where the shown model has one.
fn diffuse_edit(m: &mut EditedMaterial, ui: &mut egui::Ui) {
    if let (Some(albedo), Some(fitted)) = (m.diffuse(), m.fitted_diffuse()) {
        ui.label("Diffuse albedo ρd (f = ρd/π):");
        let mut rgb = albedo.map(|v| v as f32);
        // Only an edit counts: the picker's colour-space round trip moves the value by ~1e-7.
        let mut edited = None;
        ui.horizontal(|ui| {
            if ui.color_edit_button_rgb(&mut rgb).changed() {
                edited = Some(rgb.map(|v| v as f64));
            }
            ui.label(format!(
                "{:.3} {:.3} {:.3}",
                albedo[0], albedo[1], albedo[2]
            ));
            if ui.small_button("fitted").clicked() {
                edited = Some(fitted);
            }
        });
        if let Some(albedo) = edited {
            m.set_diffuse(albedo);
        }
    }
}

/// The Fresnel tint.
fn tint_edit(m: &mut EditedMaterial, ui: &mut egui::Ui) {
    ui.label("Fresnel tint:");
    let tint0 = m.tint.map(|v| v as f32);
    let mut tint = tint0;
    ui.horizontal(|ui| {
        ui.color_edit_button_rgb(&mut tint);
        if ui.small_button("reset").clicked() {
            tint = [1.0; 3];
        }
    });
    if tint != tint0 {
        m.tint = tint.map(|v| v as f64);
    }
}

/// The glint parameters.
fn glint_sliders(m: &mut EditedMaterial, ui: &mut egui::Ui) {
    ui.label("Glints:");
    if m.record.ggx.is_some() {
        ui.checkbox(&mut m.glint.tabulated, "flakes from the tabulated NDF");
    }
    ui.add(
        egui::Slider::new(&mut m.glint.density, 1e3..=1e7)
            .logarithmic(true)
            .text("density"),
    );
    ui.add(egui::Slider::new(&mut m.glint.gamma_deg, 0.25..=5.0).text("γ °"));
    ui.add(
        egui::Slider::new(&mut m.glint.threshold, 1.0..=1e4)
            .logarithmic(true)
            .text("threshold"),
    );
}

/// The fit's clear coat: on or off, its weight, α and η. While it is on, the α, ρd and tint
/// edits above are the base's under it; off, the single layer's.
fn coat_sliders(m: &mut EditedMaterial, ui: &mut egui::Ui) {
    ui.label("Clear coat (the fit's):");
    let fitted = m.base.record.coat.as_ref().map(|c| c.coat);
    let mut on = m.coat.is_some();
    ui.horizontal(|ui| {
        ui.checkbox(&mut on, "coat");
        if ui.small_button("fitted").clicked() {
            m.coat = fitted;
            on = true;
        }
    });
    if !on {
        m.coat = None;
        return;
    }
    let mut c = m.coat.or(fitted).expect("has_coat: the fit has a coat");
    ui.add(egui::Slider::new(&mut c.weight, 0.0..=1.0).text("weight"));
    ui.add(
        egui::Slider::new(&mut c.alpha, 1e-3..=1.0)
            .logarithmic(true)
            .text("α"),
    );
    ui.add(egui::Slider::new(&mut c.eta, 1.05..=2.5).text("η"));
    m.coat = Some(c);
}

/// The exposure, the save field and the status line.
fn save_section(app: &mut ViewerApp, ui: &mut egui::Ui) {
    ui.separator();
    ui.add(egui::Slider::new(&mut app.exposure, -6.0..=6.0).text("exposure"));
    ui.separator();
    let hint = ui.label("Save the edited material as a fit JSON:");
    ui.horizontal(|ui| {
        ui.add(egui::TextEdit::singleline(&mut app.save_text).desired_width(180.0))
            .labelled_by(hint.id);
        if ui.button("Save fit JSON").clicked() {
            let p = std::path::PathBuf::from(app.save_text.trim());
            app.save(&p);
        }
    });
    if !app.status.is_empty() {
        ui.label(app.status.as_str());
    }
}

/// A running job's line: a spinner, "fitting WHAT (N s)".
fn job_line(ui: &mut egui::Ui, what: &str, started: std::time::Instant) {
    ui.horizontal(|ui| {
        ui.spinner();
        let secs = started.elapsed().as_secs_f64();
        ui.label(format!("fitting {what} ({secs:.0} s)"));
    });
}
