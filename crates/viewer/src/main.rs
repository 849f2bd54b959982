//! `facet-viewer [--material SPEC] [--screenshot PATH --frames N]`

use anyhow::{Context, Result, bail};
use facet_viewer::ViewerApp;
use facet_viewer::app::ScreenshotPlan;
use facet_viewer::material::Shown;
use facet_viewer::preview::Preview;
use std::path::PathBuf;

/// Preview resolution (the image is scaled to the panel).
const PREVIEW: (u32, u32) = (256, 256);

fn main() -> Result<()> {
    let mut args = std::env::args().skip(1);
    let (mut screenshot, mut frames, mut material, mut shown) = (None, 16u32, None, None);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--screenshot" => {
                screenshot = Some(PathBuf::from(args.next().context("--screenshot PATH")?))
            }
            "--frames" => frames = args.next().context("--frames N")?.parse()?,
            "--material" => material = Some(args.next().context("--material SPEC")?),
            "--shown" => {
                let name = args.next().context("--shown MODEL")?;
                shown = Some(
                    Shown::ALL
                        .into_iter()
                        .find(|s| {
                            s.label().eq_ignore_ascii_case(&name)
                                || format!("{s:?}").eq_ignore_ascii_case(&name)
                        })
                        .with_context(|| {
                            format!("--shown {name}: measured, tabulated, ggx, beckmann or glint")
                        })?,
                );
            }
            "-h" | "--help" => {
                println!(
                    "facet-viewer [--material SPEC] [--shown MODEL] [--screenshot PATH.png --frames N]"
                );
                return Ok(());
            }
            other => bail!("unknown argument {other}"),
        }
    }
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    // The renderer needs the adapter's own limits (storage buffers per stage, binding sizes).
    setup.device_descriptor = std::sync::Arc::new(facet_gpu::Gpu::device_descriptor);
    setup.instance_descriptor.backends = wgpu::Backends::VULKAN | wgpu::Backends::GL;
    let options = eframe::NativeOptions {
        renderer: eframe::Renderer::Wgpu,
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 800.0])
            .with_title("Facet viewer")
            .with_drag_and_drop(true),
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
            ..Default::default()
        },
        ..Default::default()
    };
    eframe::run_native(
        "Facet viewer",
        options,
        Box::new(move |cc| {
            let mut app = match ViewerApp::with_default_material() {
                Ok(a) => a,
                Err(e) => return Err(format!("the default material: {e}").into()),
            };
            if let Some(spec) = &material {
                app.open(spec);
            }
            if let Some(s) = shown
                && app.material.available(s)
            {
                app.material.shown = s;
            }
            match &cc.wgpu_render_state {
                Some(rs) => {
                    let gpu = facet_gpu::Gpu::from_parts(
                        rs.adapter.clone(),
                        rs.device.clone(),
                        rs.queue.clone(),
                    );
                    match app.material.render_material() {
                        Ok(m) => {
                            let ctx = cc.egui_ctx.clone();
                            app.preview = Some(Preview::start(gpu, m, PREVIEW, move || {
                                ctx.request_repaint()
                            }));
                            // The worker starts on this material: generation 0 is it.
                            app.sent_key = Some(app.material.key());
                        }
                        Err(e) => app.preview_error = Some(e),
                    }
                }
                None => {
                    app.preview_error = Some("no GPU adapter (wgpu render state missing)".into())
                }
            }
            if let Some(path) = screenshot {
                app.screenshot = Some(ScreenshotPlan {
                    path,
                    frames,
                    stage: 0,
                    started: std::time::Instant::now(),
                    saved: Default::default(),
                });
            }
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow::anyhow!("the window: {e}"))
}
