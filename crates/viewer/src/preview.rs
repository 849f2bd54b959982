//! The progressive preview: a path-traced sphere on a plane under the demo sky, rendered on a
//! worker thread that shares eframe's device and queue.
//!
//! Why a thread: a render submits and then waits for the GPU. On lavapipe one sample per pixel
//! of a 256² image takes tens of milliseconds, and rebuilding the pipelines after a change of
//! material class takes about half a second; done inside `App::ui` either would freeze the
//! window. The worker keeps one [`Wavefront`] (path state, queues, film) for the scene and adds
//! samples to its film on the GPU, a batch per frame sized to take about [`FRAME_MS`]; it reads
//! back only the tone-mapped image (4 bytes a pixel), publishes it, asks for a repaint and reads
//! the UI's commands between batches, so a slider move restarts accumulation within one batch.

use facet_gpu::Gpu;
use facet_render::camera::CameraFrame;
use facet_render::scene::{Camera, Environment, EnvironmentMap, Material, Scene};
use facet_render::{ImageConfig, Integrator, ResourceConfig, SampleConfig, SceneResources, Wavefront};
use glam::Vec3;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Index of the sphere's material in the sphere scene.
pub const SPHERE: usize = 1;
/// Accumulation stops here (the GPU rests until the next change).
pub const MAX_SAMPLES: u32 = 1024;
pub use facet_render::pacing::{FRAME_MS, MAX_SPP_PER_FRAME, next_batch};

/// An orbit camera around `target`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// The point looked at.
    pub target: Vec3,
    /// Azimuth around the vertical axis, radians.
    pub yaw: f32,
    /// Elevation, radians.
    pub pitch: f32,
    /// Distance from `target`.
    pub distance: f32,
    /// Vertical field of view, radians.
    pub yfov: f32,
}

impl Default for Orbit {
    fn default() -> Self {
        Orbit {
            target: Vec3::ZERO,
            yaw: 0.0,
            pitch: 0.25,
            distance: 4.5,
            yfov: 35f32.to_radians(),
        }
    }
}

impl Orbit {
    /// The orbit through a scene's camera, around the centre of the scene's bounds.
    pub fn from_camera(camera: &Camera, bounds: (Vec3, Vec3)) -> Self {
        let target = 0.5 * (bounds.0 + bounds.1);
        let offset = camera.position - target;
        let distance = offset.length().max(1e-3);
        let d = offset / distance;
        Orbit {
            target,
            yaw: d.x.atan2(d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin(),
            distance,
            yfov: camera.yfov,
        }
    }

    /// The camera of this orbit.
    pub fn camera(&self) -> Camera {
        let pitch = self.pitch.clamp(-0.2, 1.4);
        let dir = Vec3::new(
            pitch.cos() * self.yaw.sin(),
            pitch.sin(),
            pitch.cos() * self.yaw.cos(),
        );
        let position = self.target + dir * self.distance;
        let forward = -dir;
        let up = (Vec3::Y - forward * forward.dot(Vec3::Y)).normalize();
        Camera {
            position,
            forward,
            up,
            yfov: self.yfov,
        }
    }
}

/// A scene for the preview: the scene, which material the edits go to, where the orbit starts.
#[derive(Clone, Debug)]
pub struct PreviewScene {
    /// The scene.
    pub scene: Scene,
    /// Index of the edited material.
    pub edited: usize,
    /// Where the orbit starts.
    pub orbit: Orbit,
}

impl PreviewScene {
    /// A unit sphere (the edited material) on a grey plane.
    pub fn sphere(material: Material) -> Self {
        PreviewScene {
            scene: preview_scene(material),
            edited: SPHERE,
            orbit: Orbit::default(),
        }
    }

    /// A glTF scene whose first Facet material (else its first material) takes the edits.
    pub fn gltf(path: &std::path::Path, material: Material) -> Result<Self, String> {
        let mut scene =
            facet_render::scene::load_gltf(path, &Default::default()).map_err(|e| e.to_string())?;
        let edited = scene
            .materials
            .iter()
            .position(|m| m.facet.is_some())
            .unwrap_or(0);
        if scene.materials.is_empty() {
            return Err(format!("{}: the scene has no materials", path.display()));
        }
        scene.materials[edited] = Material {
            name: scene.materials[edited].name.clone(),
            ..material
        };
        let orbit = Orbit::from_camera(&scene.camera, scene.bounds());
        Ok(PreviewScene {
            scene,
            edited,
            orbit,
        })
    }
}

/// What the UI sends.
pub enum Command {
    /// A new sphere material; `sent` is when the edit happened (latency is measured from it).
    Material {
        /// The generation it belongs to ([`crate::ViewerApp::generation`]).
        generation: u64,
        /// The material.
        material: Box<Material>,
        /// When the edit happened.
        sent: Instant,
    },
    /// Another camera (the accumulation restarts).
    Camera(Orbit),
    /// Tone map the image at this exposure (stops) from now on.
    Exposure(f32),
    /// Another scene (resources and pipelines are rebuilt).
    Scene(Box<PreviewScene>),
    /// Stop the worker.
    Quit,
}

/// What the worker publishes.
#[derive(Clone, Debug, Default)]
pub struct Shared {
    /// The material generation the accumulated image shows.
    pub generation: u64,
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The image so far, tone mapped on the GPU (RGBA8, alpha 255).
    pub rgba: Vec<[u8; 4]>,
    /// The exposure `rgba` was tone mapped with.
    pub exposure: f32,
    /// Samples per pixel accumulated.
    pub samples: u32,
    /// Samples per pixel the last batch added.
    pub spp_per_frame: u32,
    /// Bumped on every published frame.
    pub frame: u64,
    /// Wall time of the last batch (render + tone map + read-back), ms.
    pub frame_ms: f64,
    /// Samples per pixel per second over the current accumulation.
    pub spp_per_s: f64,
    /// Pixel samples per second over the current accumulation.
    pub samples_per_s: f64,
    /// From the last material edit to its first published frame, ms.
    pub latency_ms: Option<f64>,
    /// Whether the last material change needed new resources (pipelines) rather than an
    /// in-place buffer write.
    pub last_rebuilt: bool,
    /// Whether resources are being rebuilt now.
    pub rebuilding: bool,
    /// The worker's last error.
    pub error: Option<String>,
    /// The adapter's description.
    pub adapter: String,
}

/// The UI's handle on the worker.
pub struct Preview {
    tx: Sender<Command>,
    /// What the worker publishes, read by the UI.
    pub shared: Arc<Mutex<Shared>>,
    /// The device's uncaptured errors (wgpu would panic on them): shown in the window.
    pub gpu_error: Arc<Mutex<Option<String>>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Preview {
    fn drop(&mut self) {
        let _ = self.tx.send(Command::Quit);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The preview scene: a unit sphere (material [`SPHERE`]) on a grey plane, seen by the default
/// orbit.
pub fn preview_scene(sphere: Material) -> Scene {
    let mut scene = facet_render::scene::shapes::preview_scene(sphere);
    scene.camera = Orbit::default().camera();
    scene
}

/// The demo sky, or a constant grey when it cannot be read.
pub fn preview_environment() -> Environment {
    match EnvironmentMap::load(&crate::demo_dir().join("sky.exr")) {
        Ok((map, _)) => Environment::Map(Arc::new(map)),
        Err(_) => Environment::Constant(Vec3::splat(0.8)),
    }
}

impl Preview {
    /// Starts the worker on `gpu` (eframe's device) with a scene.
    pub fn start(
        gpu: Gpu,
        scene: PreviewScene,
        size: (u32, u32),
        repaint: impl Fn() + Send + 'static,
    ) -> Self {
        let (tx, rx) = std::sync::mpsc::channel();
        let shared = Arc::new(Mutex::new(Shared {
            adapter: gpu.describe(),
            rebuilding: true,
            ..Default::default()
        }));
        let gpu_error = Arc::new(Mutex::new(None));
        let slot = gpu_error.clone();
        // Its own lock: wgpu calls the handler inside whichever call failed.
        gpu.device
            .on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
                *slot.lock().unwrap() = Some(e.to_string());
            }));
        let sh = shared.clone();
        let thread = std::thread::Builder::new()
            .name("facet-preview".into())
            .spawn(move || {
                if let Err(e) = worker(gpu, scene, size, rx, &sh, &repaint) {
                    sh.lock().unwrap().error = Some(e);
                    repaint();
                }
            })
            .expect("spawn the preview thread");
        Preview {
            tx,
            shared,
            gpu_error,
            thread: Some(thread),
        }
    }

    /// Sends a command to the worker (ignored once it has stopped).
    pub fn send(&self, cmd: Command) {
        let _ = self.tx.send(cmd);
    }
}

struct Built {
    res: SceneResources,
    integrator: Integrator,
    wavefront: Wavefront,
}

fn build(gpu: &Gpu, scene: &Scene, env: &Environment, size: (u32, u32)) -> Result<Built, String> {
    let res = SceneResources::new(gpu, scene, Some(env), ResourceConfig::standard())
        .map_err(|e| e.to_string())?;
    let integrator = Integrator::new(&gpu.device, &res).map_err(|e| e.to_string())?;
    let image = ImageConfig {
        width: size.0,
        height: size.1,
        wavefront: size.0 * size.1,
    };
    let wavefront = integrator
        .wavefront(gpu, &res, image)
        .map_err(|e| e.to_string())?;
    Ok(Built {
        res,
        integrator,
        wavefront,
    })
}

fn worker(
    gpu: Gpu,
    preview: PreviewScene,
    (width, height): (u32, u32),
    rx: Receiver<Command>,
    shared: &Mutex<Shared>,
    repaint: &dyn Fn(),
) -> Result<(), String> {
    let env = preview_environment();
    let PreviewScene {
        mut scene,
        mut edited,
        orbit,
    } = preview;
    let mut orbit = orbit;
    let size = (width, height);
    let mut built = build(&gpu, &scene, &env, size)?;
    let mut camera = CameraFrame::new(&orbit.camera()).map_err(|e| e.to_string())?;
    let n = (width * height) as usize;
    let mut exposure = 0f32;
    let mut batch = 1u32;
    let mut generation = 0u64;
    let mut pending_latency: Option<Instant> = None;
    let mut started = Instant::now();
    let mut frame = 0u64;
    {
        let mut s = shared.lock().unwrap();
        s.rebuilding = false;
        s.width = width;
        s.height = height;
    }
    loop {
        // Commands: block only when there is nothing left to render.
        let mut cmds = Vec::new();
        if built.wavefront.spp() >= MAX_SAMPLES {
            match rx.recv() {
                Ok(c) => cmds.push(c),
                Err(_) => return Ok(()),
            }
        }
        loop {
            match rx.try_recv() {
                Ok(c) => cmds.push(c),
                Err(TryRecvError::Empty) => break,
                Err(TryRecvError::Disconnected) => return Ok(()),
            }
        }
        let mut restart = false;
        let mut retone = false;
        let mut new_material = None;
        for c in cmds {
            match c {
                Command::Quit => return Ok(()),
                Command::Scene(p) => {
                    shared.lock().unwrap().rebuilding = true;
                    repaint();
                    let b = build(&gpu, &p.scene, &env, size);
                    let mut s = shared.lock().unwrap();
                    s.rebuilding = false;
                    match b {
                        Ok(b) => {
                            built = b;
                            scene = p.scene;
                            edited = p.edited;
                            orbit = p.orbit;
                            restart = true;
                        }
                        Err(e) => s.error = Some(format!("preview scene: {e}")),
                    }
                }
                Command::Camera(o) => {
                    orbit = o;
                    restart = true;
                }
                Command::Exposure(e) => {
                    exposure = e;
                    retone = true;
                }
                Command::Material {
                    generation: g,
                    material,
                    sent,
                } => new_material = Some((g, material, sent)),
            }
        }
        if let Some((g, material, sent)) = new_material {
            let name = scene.materials[edited].name.clone();
            scene.materials[edited] = Material { name, ..*material };
            let in_place = built
                .res
                .update_material(&gpu.queue, &scene, edited)
                .is_ok();
            if !in_place {
                shared.lock().unwrap().rebuilding = true;
                repaint();
                let b = build(&gpu, &scene, &env, size);
                let mut s = shared.lock().unwrap();
                s.rebuilding = false;
                match b {
                    Ok(b) => built = b,
                    Err(e) => {
                        s.error = Some(format!("preview: {e}"));
                        drop(s);
                        repaint();
                        continue;
                    }
                }
            }
            shared.lock().unwrap().last_rebuilt = !in_place;
            generation = g;
            pending_latency = Some(sent);
            restart = true;
        }
        if restart {
            camera = CameraFrame::new(&orbit.camera()).map_err(|e| e.to_string())?;
            built.wavefront.clear(&gpu);
            started = Instant::now();
        }
        let t = Instant::now();
        let sampling = built.wavefront.spp() < MAX_SAMPLES;
        if sampling {
            let cfg = SampleConfig {
                spp: batch.min(MAX_SAMPLES - built.wavefront.spp()),
                spp_per_pass: MAX_SPP_PER_FRAME,
                ..SampleConfig::preview()
            };
            let Built {
                integrator,
                wavefront,
                ..
            } = &mut built;
            integrator
                .render_more(&gpu, wavefront, &camera, &cfg, &mut |_| {})
                .map_err(|e| format!("preview render: {e}"))?;
        } else if !retone {
            continue;
        }
        let rgba = built
            .wavefront
            .tone_mapped(&gpu, exposure)
            .map_err(|e| format!("preview tone map: {e}"))?;
        gpu.check_lost().map_err(|e| e.to_string())?;
        let frame_ms = t.elapsed().as_secs_f64() * 1e3;
        let added = if sampling { batch } else { 0 };
        if sampling {
            batch = next_batch(batch, frame_ms);
        }
        frame += 1;
        let samples = built.wavefront.spp();
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        {
            let mut s = shared.lock().unwrap();
            s.generation = generation;
            s.rgba = rgba;
            s.exposure = exposure;
            s.samples = samples;
            s.frame = frame;
            if sampling {
                s.frame_ms = frame_ms;
                s.spp_per_frame = added;
            }
            s.spp_per_s = samples as f64 / secs;
            s.samples_per_s = samples as f64 * n as f64 / secs;
            if let Some(sent) = pending_latency.take() {
                s.latency_ms = Some(sent.elapsed().as_secs_f64() * 1e3);
            }
        }
        repaint();
    }
}
