//! `facet-viewer [INPUT] [--shown MODEL] [--scene PATH.gltf] [--screenshot PATH.png --frames N]`
//!
//! Opens the window on eframe's wgpu backend with the device the renderer needs (the
//! adapter's own limits); the preview shares that device. Where wgpu finds no adapter or
//! cannot start, the window opens on the glow (OpenGL) backend instead and says so, with the
//! preview off: the material panel, plots, fitting and saving still work.

use anyhow::Result;
use clap::Parser;
use facet_viewer::ViewerApp;
use facet_viewer::app::ScreenshotPlan;
use facet_viewer::material::Shown;
use facet_viewer::preview::Preview;
use std::path::PathBuf;

/// Preview resolution (the image is scaled to the panel).
const PREVIEW: (u32, u32) = (256, 256);

/// Facet's material viewer: a measured or fitted material on a live path-traced preview, its
/// fit edited with sliders (α, rotation, ρd, Fresnel tint, glints) and saved for `facet render`.
/// FACET_BACKEND and FACET_ADAPTER choose the adapter, as for `facet`.
#[derive(Parser, Clone, Debug)]
#[command(name = "facet-viewer", version)]
struct Args {
    /// The material to open, as `facet fit` takes it: a MERL .binary, an RGL .bsdf,
    /// `nbrdf:NAME`, `analytic:ggx?alpha=0.2&f0=0.04` or a fit .json (default: the embedded
    /// gold GGX, fitted at start).
    #[arg(value_name = "INPUT", conflicts_with = "material")]
    input: Option<String>,
    /// The same as INPUT.
    #[arg(long, value_name = "SPEC")]
    material: Option<String>,
    /// The model shown first: measured (the measurement itself, for a measured INPUT),
    /// tabulated, ggx, beckmann or glint (default: GGX where the material has one); for an
    /// INPUT fitted in the background, once its fit arrives.
    #[arg(long, value_name = "MODEL", value_parser = parse_shown)]
    shown: Option<Shown>,
    /// Split the sphere: the measurement on its left half, the edited model on its right (a
    /// measured INPUT; not with --scene).
    #[arg(long, conflicts_with = "scene")]
    split: bool,
    /// A glTF scene for the preview, its materials replaced by the edited one (default: a
    /// sphere under the demo's sky).
    #[arg(long, value_name = "PATH.gltf")]
    scene: Option<PathBuf>,
    /// Save a screenshot of the window as PNG after --frames frames, then exit (the docs'
    /// picture and the window test).
    #[arg(long, value_name = "PATH.png")]
    screenshot: Option<PathBuf>,
    /// Frames of the preview before the screenshot.
    #[arg(long, value_name = "N", default_value_t = 16, requires = "screenshot")]
    frames: u32,
}

impl Args {
    /// INPUT as a glTF scene goes to --scene; a file INPUT (or --material) that cannot be read
    /// is refused here, naming it, before a window opens.
    fn checked(mut self) -> Result<Self> {
        let is_scene = |s: &str| {
            let ext = std::path::Path::new(s)
                .extension()
                .map(|e| e.to_ascii_lowercase());
            matches!(ext.as_ref().and_then(|e| e.to_str()), Some("gltf" | "glb"))
        };
        if let Some(input) = self.input.take_if(|i| is_scene(i)) {
            if self.scene.is_some() {
                anyhow::bail!("{input}: a scene, and --scene gives another");
            }
            self.scene = Some(PathBuf::from(input));
        }
        let spec = self.input.as_ref().or(self.material.as_ref());
        if let Some(spec) = spec
            && let Some(path) = facet_fit::sources::InputSpec::parse(spec).path()
        {
            readable(path, "")?;
        }
        if let Some(scene) = &self.scene {
            readable(scene, "--scene ")?;
        }
        Ok(self)
    }
}

/// `Err` naming `flag` and `path` when the file cannot be read.
fn readable(path: &std::path::Path, flag: &str) -> Result<()> {
    std::fs::metadata(path).map(|_| ()).map_err(|e| {
        let problem = facet_fit::io::input::io_problem(&e);
        anyhow::anyhow!("{flag}{}: {problem}", path.display())
    })
}

/// A `--shown` value: a model's label or its name, any case.
fn parse_shown(name: &str) -> Result<Shown, String> {
    Shown::ALL
        .into_iter()
        .find(|s| {
            s.label().eq_ignore_ascii_case(name) || format!("{s:?}").eq_ignore_ascii_case(name)
        })
        .ok_or_else(|| format!("{name}: measured, tabulated, ggx, beckmann or glint"))
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
            if let Some(spec) = args.input.as_ref().or(args.material.as_ref()) {
                app.open(spec);
            }
            app.split = args.split;
            if let Some(s) = args.shown {
                app.ask_shown(s);
            }
            match (&cc.wgpu_render_state, no_gpu) {
                (Some(rs), _) => {
                    let gpu = facet_gpu::Gpu::from_parts(
                        rs.adapter.clone(),
                        rs.device.clone(),
                        rs.queue.clone(),
                    );
                    let scene = match (
                        args.scene.as_deref(),
                        app.preview_scene(args.scene.as_deref()),
                    ) {
                        (Some(_), Err(e)) => {
                            app.error = Some(format!("the scene: {e}"));
                            app.preview_scene(None)
                        }
                        // The sphere until the scene's measurements are fitted.
                        (Some(path), Ok(ps)) if !ps.scene.unfitted_measurements().is_empty() => {
                            app.fit_scene(path, ps);
                            app.preview_scene(None)
                        }
                        (_, r) => r,
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
    let args = match Args::parse().checked() {
        Ok(args) => args,
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::exit(2);
        }
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
