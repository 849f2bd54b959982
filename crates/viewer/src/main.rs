//! `facet-viewer [--material SPEC] [--shown MODEL] [--scene PATH.gltf] [--screenshot PATH --frames N]`
//!
//! Opens the window on eframe's wgpu backend with the device the renderer needs (the
//! adapter's own limits); the preview shares that device. Where wgpu finds no adapter or
//! cannot start, the window opens on the glow (OpenGL) backend instead and says so, with the
//! preview off: the material panel, plots, fitting and saving still work.

use anyhow::{Context, Result, bail};
use facet_viewer::ViewerApp;
use facet_viewer::app::ScreenshotPlan;
use facet_viewer::material::Shown;
use facet_viewer::preview::Preview;
use std::path::PathBuf;

/// Preview resolution (the image is scaled to the panel).
const PREVIEW: (u32, u32) = (256, 256);

#[derive(Clone)]
struct Args {
    screenshot: Option<PathBuf>,
    frames: u32,
    material: Option<String>,
    shown: Option<Shown>,
    scene: Option<PathBuf>,
}

fn parse() -> Result<Option<Args>> {
    let mut a = Args {
        screenshot: None,
        frames: 16,
        material: None,
        shown: None,
        scene: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--screenshot" => {
                a.screenshot = Some(PathBuf::from(args.next().context("--screenshot PATH")?))
            }
            "--frames" => a.frames = args.next().context("--frames N")?.parse()?,
            "--material" => a.material = Some(args.next().context("--material SPEC")?),
            "--scene" => a.scene = Some(PathBuf::from(args.next().context("--scene PATH.gltf")?)),
            "--shown" => {
                let name = args.next().context("--shown MODEL")?;
                a.shown = Some(
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
                    "facet-viewer [--material SPEC] [--shown MODEL] [--scene PATH.gltf] [--screenshot PATH.png --frames N]"
                );
                return Ok(None);
            }
            other => bail!("unknown argument {other}"),
        }
    }
    Ok(Some(a))
}

fn options(renderer: eframe::Renderer, gpu: &facet_gpu::GpuOptions) -> eframe::NativeOptions {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    // The renderer needs the adapter's own limits (storage buffers per stage, binding sizes).
    setup.device_descriptor = std::sync::Arc::new(facet_gpu::Gpu::device_descriptor);
    setup.instance_descriptor.backends = gpu
        .backends
        .unwrap_or(wgpu::Backends::VULKAN | wgpu::Backends::GL);
    if let Some(name) = gpu.adapter_name.clone() {
        let name = name.to_ascii_lowercase();
        setup.native_adapter_selector = Some(std::sync::Arc::new(move |adapters, _| {
            adapters
                .iter()
                .find(|a| a.get_info().name.to_ascii_lowercase().contains(&name))
                .cloned()
                .ok_or_else(|| format!("no adapter matches FACET_ADAPTER={name}"))
        }));
    }
    eframe::NativeOptions {
        renderer,
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1280.0, 800.0])
            .with_title("Facet viewer")
            .with_drag_and_drop(true),
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// Runs the window; `no_gpu` says why the preview is off (glow backend).
fn run_wgpu(args: Args, gpu: &facet_gpu::GpuOptions) -> Result<(), eframe::Error> {
    run_with(args, options(eframe::Renderer::Wgpu, gpu), None)
}

fn run(
    args: Args,
    renderer: eframe::Renderer,
    no_gpu: Option<String>,
) -> Result<(), eframe::Error> {
    run_with(args, options(renderer, &Default::default()), no_gpu)
}

fn run_with(
    args: Args,
    options: eframe::NativeOptions,
    no_gpu: Option<String>,
) -> Result<(), eframe::Error> {
    eframe::run_native(
        "Facet viewer",
        options,
        Box::new(move |cc| {
            let mut app = ViewerApp::with_default_material()
                .map_err(|e| format!("the default material: {e}"))?;
            if let Some(spec) = &args.material {
                app.open(spec);
            }
            if let Some(s) = args.shown
                && app.material.available(s)
            {
                app.material.shown = s;
            }
            match (&cc.wgpu_render_state, no_gpu) {
                (Some(rs), _) => {
                    let gpu = facet_gpu::Gpu::from_parts(
                        rs.adapter.clone(),
                        rs.device.clone(),
                        rs.queue.clone(),
                    );
                    let scene = match app.preview_scene(args.scene.as_deref()) {
                        Err(e) if args.scene.is_some() => {
                            app.error = Some(format!("the scene: {e}"));
                            app.preview_scene(None)
                        }
                        r => r,
                    };
                    match scene {
                        Ok(scene) => {
                            let ctx = cc.egui_ctx.clone();
                            app.orbit = scene.orbit;
                            app.preview = Some(Preview::start(gpu, scene, PREVIEW, move || {
                                ctx.request_repaint()
                            }));
                            // The worker starts on this material: generation 0 is it.
                            app.sent_key = Some(app.material.key());
                        }
                        Err(e) => app.preview_error = Some(e),
                    }
                }
                (None, why) => {
                    app.preview_error = Some(format!(
                        "{}; the preview is off",
                        why.unwrap_or_else(|| "no GPU adapter: wgpu did not start".into())
                    ))
                }
            }
            if let Some(path) = &args.screenshot {
                app.screenshot = Some(ScreenshotPlan {
                    path: path.clone(),
                    frames: args.frames,
                    stage: 0,
                    started: std::time::Instant::now(),
                    saved: Default::default(),
                });
            }
            Ok(Box::new(app))
        }),
    )
}

fn main() -> Result<()> {
    // SAFETY: first thing in main, before any thread exists.
    unsafe { facet_gpu::ensure_runtime_dir() };
    let Some(args) = parse()? else {
        return Ok(());
    };
    // FACET_BACKEND / FACET_ADAPTER as everywhere else; FACET_BACKEND=cpu means no GPU.
    let gpu_options = match facet_gpu::GpuOptions::from_env() {
        Ok(o) => o,
        Err(e) => {
            return run(args, eframe::Renderer::Glow, Some(e.to_string()))
                .map_err(|e| anyhow::anyhow!("the window: {e}"));
        }
    };
    match run_wgpu(args.clone(), &gpu_options) {
        Ok(()) => Ok(()),
        Err(e @ eframe::Error::Wgpu(_)) => {
            eprintln!("wgpu: {e}; opening the window on OpenGL without the preview");
            run(args, eframe::Renderer::Glow, Some(e.to_string()))
                .map_err(|e| anyhow::anyhow!("the window: {e}"))
        }
        Err(e) => Err(anyhow::anyhow!("the window: {e}")),
    }
}
