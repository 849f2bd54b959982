//! The window: its panels — material (left), plots (right), preview (centre) — laid out over the
//! UI state ([`ViewerApp`]), which knows nothing of them.

mod material;
mod preview_panel;

pub use material::material_panel;
pub use preview_panel::{preview_panel, screenshot_step};

use crate::app::ViewerApp;

impl ViewerApp {
    /// The whole UI inside `ui` (the eframe app and the tests call this).
    pub fn show(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.handle_drops(&ctx);
        if self.poll_fit() | self.poll_scene_fit() {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        material_panel(self, ui);
        plots_panel(self, ui);
        preview_panel(self, ui);
        self.sync_material();
        self.sync_split();
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.show(ui);
        screenshot_step(self, ui.ctx());
    }
}

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
