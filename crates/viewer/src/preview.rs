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
use facet_render::scene::camera_frame::CameraFrame;
use facet_render::scene::{Camera, Environment, EnvironmentMap, Material, Scene};
use facet_render::{
    ImageConfig, Integrator, ResourceConfig, SampleConfig, SceneResources, Wavefront,
};
use glam::Vec3;
use std::sync::mpsc::{Receiver, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Index of the sphere's material in the sphere scene.
pub const SPHERE: usize = 1;
/// Index of the measurement's material in the split sphere scene (the sphere's −x half).
pub const SPLIT: usize = 2;
/// Accumulation stops here (the GPU rests until the next change).
pub const MAX_SAMPLES: u32 = 1024;
pub use facet_render::integrator::pacing::{FRAME_MS, MAX_SPP_PER_FRAME, next_batch};

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

    /// The sphere split at x = 0: its −x half the measurement (`measured`, fixed), its +x half
    /// the edited material, so that an edit is judged against the data beside it.
    pub fn sphere_split(material: Material, measured: Material) -> Self {
        let mut scene = preview_scene(material);
        scene.materials.push(measured);
        for (t, tri) in scene.indices.iter().enumerate() {
            let x: f32 = tri.iter().map(|&v| scene.positions[v as usize].x).sum();
            if scene.triangle_material[t] == SPHERE as u32 && x < 0.0 {
                scene.triangle_material[t] = SPLIT as u32;
            }
        }
        PreviewScene {
            scene,
            edited: SPHERE,
            orbit: Orbit::default(),
        }
    }

    /// A glTF scene whose first Facet material (else its first material) takes the edits.
    pub fn gltf(path: &std::path::Path, material: Material) -> Result<Self, String> {
        // A measurement named without a fit is left for the caller to fit (loading never fits):
        // the viewer's scene fit job ([`crate::app::SceneFitJob`]).
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
    let mut scene = facet_render::scene::sphere::SphereScene::PREVIEW.build(sphere);
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
    size: (u32, u32),
    rx: Receiver<Command>,
    shared: &Mutex<Shared>,
    repaint: &dyn Fn(),
) -> Result<(), String> {
    let mut w = Worker::new(gpu, preview, size, shared, repaint)?;
    loop {
        // Commands: block only when there is nothing left to render.
        let idle = w.built.wavefront.spp() >= MAX_SAMPLES;
        let Some(cmds) = receive(&rx, idle) else {
            return Ok(());
        };
        let Some(mut asked) = w.apply(cmds) else {
            return Ok(());
        };
        if let Some((generation, material, sent)) = asked.material.take() {
            if !w.edit_material(generation, *material, sent) {
                continue;
            }
            asked.restart = true;
        }
        if asked.restart {
            w.restart()?;
        }
        w.step(asked.retone)?;
    }
}

/// The commands waiting, after waiting for one when `block`; `None` once the UI is gone.
fn receive(rx: &Receiver<Command>, block: bool) -> Option<Vec<Command>> {
    let mut cmds = Vec::new();
    if block {
        cmds.push(rx.recv().ok()?);
    }
    loop {
        match rx.try_recv() {
            Ok(c) => cmds.push(c),
            Err(TryRecvError::Empty) => return Some(cmds),
            Err(TryRecvError::Disconnected) => return None,
        }
    }
}

/// What one round of commands asks for.
#[derive(Default)]
struct Asked {
    /// Start the accumulation again (another camera or scene).
    restart: bool,
    /// Tone map again (another exposure).
    retone: bool,
    /// The last material sent: its generation, the material, when it was edited.
    material: Option<(u64, Box<Material>, Instant)>,
}

/// The worker's state between batches.
struct Worker<'a> {
    gpu: Gpu,
    env: Environment,
    size: (u32, u32),
    scene: Scene,
    /// The index of the edited material in `scene`.
    edited: usize,
    orbit: Orbit,
    built: Built,
    camera: CameraFrame,
    exposure: f32,
    /// Samples per pixel of the next batch.
    batch: u32,
    /// The material generation being accumulated.
    generation: u64,
    /// When the edit being shown was made, until its first frame is published.
    pending_latency: Option<Instant>,
    /// When the current accumulation started.
    started: Instant,
    /// Frames published.
    frame: u64,
    shared: &'a Mutex<Shared>,
    repaint: &'a dyn Fn(),
}

impl<'a> Worker<'a> {
    fn new(
        gpu: Gpu,
        preview: PreviewScene,
        size: (u32, u32),
        shared: &'a Mutex<Shared>,
        repaint: &'a dyn Fn(),
    ) -> Result<Self, String> {
        let env = preview_environment();
        let PreviewScene {
            scene,
            edited,
            orbit,
        } = preview;
        let built = build(&gpu, &scene, &env, size)?;
        let camera = CameraFrame::new(&orbit.camera()).map_err(|e| e.to_string())?;
        {
            let mut s = shared.lock().unwrap();
            s.rebuilding = false;
            (s.width, s.height) = size;
        }
        Ok(Worker {
            gpu,
            env,
            size,
            scene,
            edited,
            orbit,
            built,
            camera,
            exposure: 0.0,
            batch: 1,
            generation: 0,
            pending_latency: None,
            started: Instant::now(),
            frame: 0,
            shared,
            repaint,
        })
    }

    /// Applies the scene, camera and exposure commands; the last material is left to
    /// [`Worker::edit_material`]. `None` on `Quit`.
    fn apply(&mut self, cmds: Vec<Command>) -> Option<Asked> {
        let mut asked = Asked::default();
        for c in cmds {
            match c {
                Command::Quit => return None,
                Command::Scene(p) => {
                    let b = self.rebuild(&p.scene);
                    let mut s = self.shared.lock().unwrap();
                    match b {
                        Ok(b) => {
                            self.built = b;
                            self.scene = p.scene;
                            self.edited = p.edited;
                            self.orbit = p.orbit;
                            asked.restart = true;
                        }
                        Err(e) => s.error = Some(format!("preview scene: {e}")),
                    }
                }
                Command::Camera(o) => {
                    self.orbit = o;
                    asked.restart = true;
                }
                Command::Exposure(e) => {
                    self.exposure = e;
                    asked.retone = true;
                }
                Command::Material {
                    generation,
                    material,
                    sent,
                } => asked.material = Some((generation, material, sent)),
            }
        }
        Some(asked)
    }

    /// New resources for `scene`, with `rebuilding` published while they are made.
    fn rebuild(&self, scene: &Scene) -> Result<Built, String> {
        self.shared.lock().unwrap().rebuilding = true;
        (self.repaint)();
        let b = build(&self.gpu, scene, &self.env, self.size);
        self.shared.lock().unwrap().rebuilding = false;
        b
    }

    /// The edited material becomes `material` (generation `generation`, edited at `sent`): in
    /// place where it can, else with new resources. False when those could not be made (the
    /// error is published).
    fn edit_material(&mut self, generation: u64, material: Material, sent: Instant) -> bool {
        let name = self.scene.materials[self.edited].name.clone();
        self.scene.materials[self.edited] = Material { name, ..material };
        let in_place = self
            .built
            .res
            .update_material(&self.gpu.queue, &self.scene, self.edited)
            .is_ok();
        if !in_place {
            match self.rebuild(&self.scene) {
                Ok(b) => self.built = b,
                Err(e) => {
                    self.shared.lock().unwrap().error = Some(format!("preview: {e}"));
                    (self.repaint)();
                    return false;
                }
            }
        }
        self.shared.lock().unwrap().last_rebuilt = !in_place;
        self.generation = generation;
        self.pending_latency = Some(sent);
        true
    }

    /// Starts the accumulation again, from the current orbit.
    fn restart(&mut self) -> Result<(), String> {
        self.camera = CameraFrame::new(&self.orbit.camera()).map_err(|e| e.to_string())?;
        self.built.wavefront.clear(&self.gpu);
        self.started = Instant::now();
        Ok(())
    }

    /// Renders a batch (unless the film is full), tone maps and publishes the frame; with a
    /// full film only when `retone`.
    fn step(&mut self, retone: bool) -> Result<(), String> {
        let t = Instant::now();
        let sampling = self.built.wavefront.spp() < MAX_SAMPLES;
        if sampling {
            let cfg = SampleConfig {
                spp: self.batch.min(MAX_SAMPLES - self.built.wavefront.spp()),
                spp_per_pass: MAX_SPP_PER_FRAME,
                ..SampleConfig::preview()
            };
            let Built {
                integrator,
                wavefront,
                ..
            } = &mut self.built;
            integrator
                .render_more(&self.gpu, wavefront, &self.camera, &cfg, &mut |_| {})
                .map_err(|e| format!("preview render: {e}"))?;
        } else if !retone {
            return Ok(());
        }
        let rgba = self
            .built
            .wavefront
            .tone_mapped(&self.gpu, self.exposure)
            .map_err(|e| format!("preview tone map: {e}"))?;
        self.gpu.check_lost().map_err(|e| e.to_string())?;
        let frame_ms = t.elapsed().as_secs_f64() * 1e3;
        let added = sampling.then_some(self.batch);
        if sampling {
            self.batch = next_batch(self.batch, frame_ms);
        }
        self.publish(rgba, frame_ms, added);
        Ok(())
    }

    /// Publishes a frame that took `frame_ms`, `added` samples per pixel when it sampled.
    fn publish(&mut self, rgba: Vec<[u8; 4]>, frame_ms: f64, added: Option<u32>) {
        self.frame += 1;
        let samples = self.built.wavefront.spp();
        let secs = self.started.elapsed().as_secs_f64().max(1e-9);
        let n = self.size.0 as f64 * self.size.1 as f64;
        {
            let mut s = self.shared.lock().unwrap();
            s.generation = self.generation;
            s.rgba = rgba;
            s.exposure = self.exposure;
            s.samples = samples;
            s.frame = self.frame;
            if let Some(added) = added {
                s.frame_ms = frame_ms;
                s.spp_per_frame = added;
            }
            s.spp_per_s = samples as f64 / secs;
            s.samples_per_s = samples as f64 * n / secs;
            if let Some(sent) = self.pending_latency.take() {
                s.latency_ms = Some(sent.elapsed().as_secs_f64() * 1e3);
            }
        }
        (self.repaint)();
    }
}
