//! The window's panels: material (left), plots (right), preview (centre).

mod material;
mod preview_panel;

pub use material::material_panel;
pub use preview_panel::{preview_panel, screenshot_step};

use crate::app::ViewerApp;

/// The right panel: NDF slice, Fresnel curves, fit errors.
pub fn plots_panel(app: &mut ViewerApp, ui: &mut egui::Ui) {
    egui::Panel::right("plots")
        .resizable(true)
        .default_size(320.0)
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                crate::plots::plots(&app.material, ui);
            });
        });
}
