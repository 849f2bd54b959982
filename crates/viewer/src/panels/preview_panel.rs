//! The preview panel: the accumulated image, orbit and zoom, timings; the screenshot run.

use crate::app::ViewerApp;
use crate::preview::Command;
use std::sync::atomic::Ordering;

pub fn preview_panel(app: &mut ViewerApp, ui: &mut egui::Ui) {
    egui::CentralPanel::default().show(ui, |ui| contents(app, ui));
}

fn contents(app: &mut ViewerApp, ui: &mut egui::Ui) {
    let Some(shared) = app.preview.as_ref().map(|p| p.shared.clone()) else {
        ui.heading("No preview");
        ui.colored_label(
            egui::Color32::from_rgb(230, 80, 60),
            app.preview_error
                .as_deref()
                .unwrap_or("no GPU adapter: the preview is off"),
        );
        return;
    };
    let s = shared.lock().unwrap().clone();
    if let Some(e) = app
        .preview
        .as_ref()
        .and_then(|p| p.gpu_error.lock().unwrap().clone())
    {
        ui.colored_label(
            egui::Color32::from_rgb(230, 80, 60),
            format!("GPU error: {e}"),
        );
    }
    if let Some(e) = &s.error {
        ui.colored_label(egui::Color32::from_rgb(230, 80, 60), format!("Error: {e}"));
    }
    // The worker tone maps on the GPU: a new exposure goes to it, a new frame comes back.
    if app.exposure != app.sent_exposure {
        if let Some(p) = &app.preview {
            p.send(Command::Exposure(app.exposure));
        }
        app.sent_exposure = app.exposure;
    }
    if s.frame != app.shown_frame && !s.rgba.is_empty() {
        let pixels: Vec<egui::Color32> = s
            .rgba
            .iter()
            .map(|p| egui::Color32::from_rgb(p[0], p[1], p[2]))
            .collect();
        let image = egui::ColorImage::new([s.width as usize, s.height as usize], pixels);
        match &mut app.texture {
            Some(t) => t.set(image, egui::TextureOptions::LINEAR),
            None => {
                app.texture = Some(ui.ctx().load_texture(
                    "preview",
                    image,
                    egui::TextureOptions::LINEAR,
                ))
            }
        }
        app.shown_frame = s.frame;
    }
    let current = s.generation == app.generation;
    ui.label(format!(
        "{} · {:.1} ms/frame ({} spp each) · {} spp · {:.2} Msamples/s · edit to frame {}{}",
        s.adapter,
        s.frame_ms,
        s.spp_per_frame,
        if current { s.samples } else { 0 },
        s.samples_per_s / 1e6,
        s.latency_ms
            .map_or("–".to_string(), |l| format!("{l:.0} ms")),
        if s.rebuilding {
            " · rebuilding pipelines..."
        } else {
            ""
        }
    ));
    let avail = ui.available_size();
    let side = avail.x.min(avail.y).max(64.0);
    let (rect, response) =
        ui.allocate_exact_size(egui::vec2(side, side), egui::Sense::click_and_drag());
    app.preview_rect = Some(rect);
    if let Some(t) = &app.texture {
        ui.painter().image(
            t.id(),
            rect,
            egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
            egui::Color32::WHITE,
        );
    }
    let mut orbit = app.orbit;
    if response.dragged() {
        let d = response.drag_delta();
        orbit.yaw -= d.x * 0.01;
        orbit.pitch = (orbit.pitch + d.y * 0.01).clamp(-0.2, 1.4);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            orbit.distance = (orbit.distance * (-scroll * 0.002).exp()).clamp(1.5, 20.0);
        }
    }
    if orbit != app.orbit {
        app.orbit = orbit;
        if let Some(p) = &app.preview {
            p.send(Command::Camera(orbit));
        }
    }
}

/// The `--screenshot` run: after frames/2 preview frames αx is nudged (as a slider move
/// would), then after `frames` frames of the new material the window is captured to a PNG
/// with a JSON of the preview rectangle and the timings beside it, and the window closes.
pub fn screenshot_step(app: &mut ViewerApp, ctx: &egui::Context) {
    let Some(mut plan) = app.screenshot.take() else {
        return;
    };
    ctx.request_repaint();
    let (samples, gen_now, stats) = match &app.preview {
        Some(p) => {
            let s = p.shared.lock().unwrap();
            (
                s.samples,
                s.generation,
                (
                    s.frame_ms,
                    s.samples_per_s,
                    s.spp_per_s,
                    s.latency_ms,
                    s.error.clone(),
                ),
            )
        }
        None => (0, 0, (0.0, 0.0, 0.0, None, app.preview_error.clone())),
    };
    // Without a preview (no GPU) there is nothing to wait for.
    let timed_out = plan.started.elapsed().as_secs() > 240 || app.preview.is_none();
    let current = gen_now == app.generation;
    match plan.stage {
        0 if (current && samples >= (plan.frames / 2).max(1)) || timed_out => {
            if let Some((ax, ay, rot)) = app.material.alpha() {
                app.material.set_alpha(ax * 1.25, ay * 1.25, rot);
                app.edited_at = Some(std::time::Instant::now());
            }
            plan.stage = 1;
        }
        1 if (current && samples >= plan.frames) || timed_out || stats.4.is_some() => {
            let path = plan.path.clone();
            let saved = plan.saved.clone();
            let meta = serde_json::json!({
                "preview_rect": app.preview_rect.map(|r| [r.min.x, r.min.y, r.max.x, r.max.y]),
                "pixels_per_point": ctx.pixels_per_point(),
                "frame_ms": stats.0,
                "samples_per_s": stats.1,
                "spp_per_s": stats.2,
                "edit_to_frame_ms": stats.3,
                "samples": samples,
                "error": stats.4,
            });
            let _ = std::fs::write(path.with_extension("json"), meta.to_string());
            ctx.request_screenshot(move |img: std::sync::Arc<egui::ColorImage>| {
                let [w, h] = img.size;
                let bytes: Vec<u8> = img.pixels.iter().flat_map(|c| c.to_array()).collect();
                if let Err(e) =
                    image::save_buffer(&path, &bytes, w as u32, h as u32, image::ColorType::Rgba8)
                {
                    eprintln!("cannot write {}: {e}", path.display());
                }
                saved.store(true, Ordering::SeqCst);
            });
            plan.stage = 2;
        }
        2 if plan.saved.load(Ordering::SeqCst) => {
            plan.stage = 3;
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        _ => {}
    }
    app.screenshot = Some(plan);
}
