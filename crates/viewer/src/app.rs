//! The UI state: the edited material, the open/save fields, errors, the fit job. GPU objects
//! live in [`crate::preview`]'s worker; this holds only its handle. The window drawn over this
//! state (`ViewerApp::show`, the eframe app) is in `panels`.

use crate::material::{EditedMaterial, MaterialKey, Shown};
use crate::preview::{Command, Orbit, Preview, PreviewScene};
use facet_fit::fitting::{FitConfig, fit_material};
use facet_fit::model::material::FittedMaterial;
use facet_render::scene::Measurement;
use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;
use std::time::Instant;

/// A fit running on a background thread.
pub struct FitJob {
    /// What is being fitted.
    pub label: String,
    /// When the fit started.
    pub started: Instant,
    /// The phase the fit is in, for the status line.
    pub stage: std::sync::Arc<std::sync::Mutex<String>>,
    rx: Receiver<Result<Fitted, String>>,
}

/// A glTF scene's measurements named without a fit, their sampling NDFs being fitted on a
/// background thread before the scene goes to the preview.
pub struct SceneFitJob {
    /// What is being fitted: the measurements, by name.
    pub label: String,
    /// When the fit started.
    pub started: Instant,
    path: PathBuf,
    rx: Receiver<Result<PreviewScene, String>>,
}

/// A fit job's answer: the fit, and the measurement it was made from (`None` where the source
/// has no MERL table: an anisotropic one).
type Fitted = (FittedMaterial, Option<Measurement>);

/// What a screenshot run (`--screenshot PATH --frames N`) does.
#[derive(Clone, Debug)]
pub struct ScreenshotPlan {
    /// Where the PNG goes (PATH.json beside it).
    pub path: PathBuf,
    /// Preview frames to accumulate before the shot.
    pub frames: u32,
    /// Stage: 0 waiting for frames/2, 1 nudged αx and waiting, 2 shot requested, 3 saved.
    pub stage: u32,
    /// When the run started.
    pub started: Instant,
    /// Set once the PNG is written.
    pub saved: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

/// The UI state of the viewer window (GPU work lives in [`Preview`]).
pub struct ViewerApp {
    /// The material being edited.
    pub material: EditedMaterial,
    /// Bumped whenever the material the renderer sees changes (the preview restarts).
    pub generation: u64,
    /// The key of the material last sent to the renderer.
    pub sent_key: Option<MaterialKey>,
    /// When the last edit happened (for the edit-to-frame latency).
    pub edited_at: Option<Instant>,
    /// Exposure of the preview, stops.
    pub exposure: f32,
    /// The preview camera.
    pub orbit: Orbit,
    /// The open field: a path, `nbrdf:NAME` or `analytic:SPEC`.
    pub open_text: String,
    /// The save field: the path of the fit JSON to write.
    pub save_text: String,
    /// The last error, shown until the next action.
    pub error: Option<String>,
    /// The status line.
    pub status: String,
    /// A fit running in the background.
    pub fit_job: Option<FitJob>,
    /// The fit of a glTF scene's measurements, while it runs.
    pub scene_fit: Option<SceneFitJob>,
    /// The live preview; `None` without a GPU (then `preview_error` says why).
    pub preview: Option<Preview>,
    /// Why there is no preview, or why it stopped.
    pub preview_error: Option<String>,
    /// The preview image on egui's side.
    pub texture: Option<egui::TextureHandle>,
    /// The preview frame the texture shows.
    pub shown_frame: u64,
    /// The exposure last sent to the preview worker (which tone maps).
    pub sent_exposure: f32,
    /// Where the preview image was drawn last (points).
    pub preview_rect: Option<egui::Rect>,
    /// The network file for `nbrdf:` inputs (`FACET_NBRDF`), `None`: the embedded proxies.
    pub nbrdf: Option<PathBuf>,
    /// The neural proxies' names, read when the list is first opened.
    pub proxy_names: Option<Result<Vec<String>, String>>,
    /// The screenshot run, under `--screenshot`.
    pub screenshot: Option<ScreenshotPlan>,
    /// Show the measurement on the sphere's −x half beside the edited model.
    pub split: bool,
    /// The split last sent to the preview: the measurement's address when split, else `None`.
    pub sent_split: Option<usize>,
    /// The glTF scene in the preview (the split applies to the sphere only).
    pub gltf: Option<PathBuf>,
    /// The model asked for (`--shown`, or picked while a fit runs), shown once the fit in
    /// progress arrives where it has that model.
    pub wanted: Option<Shown>,
}

impl ViewerApp {
    /// The app on a material, without a preview (tests, no GPU).
    pub fn new(material: EditedMaterial) -> Self {
        ViewerApp {
            save_text: "edited_fit.json".into(),
            open_text: material.source.clone(),
            material,
            generation: 0,
            sent_key: None,
            edited_at: None,
            exposure: 0.0,
            orbit: Orbit::default(),
            error: None,
            status: String::new(),
            fit_job: None,
            scene_fit: None,
            preview: None,
            preview_error: None,
            texture: None,
            shown_frame: 0,
            sent_exposure: 0.0,
            preview_rect: None,
            nbrdf: facet_fit::sources::nbrdf::NbrdfLibrary::override_path(None),
            proxy_names: None,
            screenshot: None,
            split: false,
            sent_split: None,
            gltf: None,
            wanted: None,
        }
    }

    /// The app on the demo's default fit.
    pub fn with_default_material() -> Result<Self, String> {
        let path = crate::demo_dir().join("default_fit.json");
        let fit = FittedMaterial::load(&path).map_err(|e| e.to_string())?;
        Ok(Self::new(EditedMaterial::new(
            fit,
            path.display().to_string(),
        )))
    }

    /// Samples accumulated for the current material (0 without a preview, or right after a
    /// change).
    pub fn samples(&self) -> u32 {
        match &self.preview {
            Some(p) => {
                let s = p.shared.lock().unwrap();
                if s.generation == self.generation {
                    s.samples
                } else {
                    0
                }
            }
            None => 0,
        }
    }

    /// Opens a fit JSON directly, or fits a MERL file / `nbrdf:NAME` / `analytic:SPEC` on a
    /// background thread. A failure leaves the current material as it is.
    pub fn open(&mut self, spec: &str) {
        let spec = spec.trim().to_string();
        if spec.is_empty() {
            return;
        }
        self.error = None;
        let ext = Path::new(&spec)
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if matches!(ext.as_deref(), Some("gltf" | "glb")) {
            self.open_scene(Path::new(&spec));
            return;
        }
        let input = facet_fit::sources::InputSpec::parse(&spec);
        if let facet_fit::sources::InputSpec::Fit(path) = &input {
            match FittedMaterial::load(path) {
                Ok(fit) => {
                    self.set_material(EditedMaterial::new(fit, spec.clone()));
                    self.status = format!("opened {spec}");
                }
                Err(e) => self.error = Some(format!("cannot open {spec}: {e}")),
            }
            return;
        }
        if let Some(path) = input.path()
            && let Err(e) = std::fs::metadata(path)
        {
            self.error = Some(format!("cannot open {spec}: {e}"));
            return;
        }
        let (tx, rx) = std::sync::mpsc::channel();
        let stage = std::sync::Arc::new(std::sync::Mutex::new("opening".to_string()));
        let st = stage.clone();
        let nbrdf = self.nbrdf.clone();
        let label = spec.clone();
        std::thread::spawn(move || {
            let r = (|| {
                let mut lib = None;
                let src = input
                    .open(
                        nbrdf.as_deref(),
                        &mut lib,
                        facet_fit::sources::Residence::Read,
                    )
                    .map_err(|e| e.to_string())?;
                *st.lock().unwrap() = "extracting the NDF and fitting".into();
                let fit = fit_material(&*src, &spec, &FitConfig::isotropic())
                    .map_err(|e| e.to_string())?;
                *st.lock().unwrap() = "tabulating the measurement".into();
                Ok((fit, Measurement::of(&input, &*src).ok()))
            })();
            let _ = tx.send(r);
        });
        self.fit_job = Some(FitJob {
            label,
            started: Instant::now(),
            stage,
            rx,
        });
    }

    /// The preview scene for a glTF file (else the sphere, split when asked) with the current
    /// material.
    pub fn preview_scene(&self, gltf: Option<&Path>) -> Result<PreviewScene, String> {
        let material = self.material.render_material()?;
        match (gltf, self.split_measurement()) {
            (Some(p), _) => PreviewScene::gltf(p, material),
            (None, Some(measured)) => Ok(PreviewScene::sphere_split(material, measured)),
            (None, None) => Ok(PreviewScene::sphere(material)),
        }
    }

    /// The measurement's material when the split is on and can be shown: a measurement, the
    /// sphere (not a glTF scene) and a model (not the measurement itself) on the other half.
    fn split_measurement(&self) -> Option<facet_render::scene::Material> {
        let shows_model = self.material.shown != Shown::Measured;
        (self.split && self.gltf.is_none() && shows_model)
            .then(|| self.material.measured_material())
            .flatten()
    }

    /// Rebuilds the sphere scene when the split (or the measurement it shows) changed; true if
    /// it did.
    pub fn sync_split(&mut self) -> bool {
        let key = self
            .split_measurement()
            .and(self.material.measurement.as_ref())
            .map(|m| std::sync::Arc::as_ptr(m) as usize);
        if key == self.sent_split || self.gltf.is_some() {
            return false;
        }
        self.sent_split = key;
        match self.preview_scene(None) {
            Ok(mut ps) => {
                ps.orbit = self.orbit;
                if let Some(p) = &self.preview {
                    p.send(Command::Scene(Box::new(ps)));
                }
                true
            }
            Err(e) => {
                self.error = Some(format!("the split preview: {e}"));
                false
            }
        }
    }

    /// Loads a glTF scene into the preview; its first Facet material takes the edits. A scene
    /// whose measurements need a fit goes to the preview once the fit job has made it.
    pub fn open_scene(&mut self, path: &Path) {
        match self.preview_scene(Some(path)) {
            Ok(ps) if !ps.scene.unfitted_measurements().is_empty() => self.fit_scene(path, ps),
            Ok(ps) => self.show_scene(path, ps),
            Err(e) => self.error = Some(format!("cannot open {}: {e}", path.display())),
        }
    }

    /// Sends glTF scene `ps` (of `path`) to the preview.
    fn show_scene(&mut self, path: &Path, ps: PreviewScene) {
        self.gltf = Some(path.to_owned());
        self.orbit = ps.orbit;
        self.status = format!(
            "scene {}: material {:?} is edited",
            path.display(),
            ps.scene.materials[ps.edited].name
        );
        match &self.preview {
            Some(p) => p.send(Command::Scene(Box::new(ps))),
            None => self.status += " (no preview without a GPU)",
        }
    }

    /// Fits the sampling NDFs of `ps`'s measurements named without a fit on a background
    /// thread, shown as a job; the scene goes to the preview when they arrive
    /// ([`poll_scene_fit`](Self::poll_scene_fit)).
    pub fn fit_scene(&mut self, path: &Path, mut ps: PreviewScene) {
        let label = ps.scene.unfitted_measurements().join(", ");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let fitted = ps
                .scene
                .fit_measured(|source, brdf| fit_material(brdf, source, &FitConfig::SINGLE_LAYER))
                .map(|_| ps)
                .map_err(|e| e.to_string());
            let _ = tx.send(fitted);
        });
        self.scene_fit = Some(SceneFitJob {
            label,
            started: Instant::now(),
            path: path.to_owned(),
            rx,
        });
    }

    /// Polls the scene's fit job; true while one runs.
    pub fn poll_scene_fit(&mut self) -> bool {
        let Some(job) = &self.scene_fit else {
            return false;
        };
        let answer = match job.rx.try_recv() {
            Err(std::sync::mpsc::TryRecvError::Empty) => return true,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => Err("the fit stopped".into()),
            Ok(r) => r,
        };
        let job = self.scene_fit.take().expect("polled above");
        match answer {
            Ok(ps) => {
                self.show_scene(&job.path, ps);
                self.status += &format!(
                    "; fitted the sampling NDF of {} in {:.1} s",
                    job.label,
                    job.started.elapsed().as_secs_f64()
                );
            }
            Err(e) => {
                let path = job.path.display();
                self.error = Some(format!(
                    "{path}: fitting the sampling NDF of {}: {e}",
                    job.label
                ));
            }
        }
        false
    }

    /// Shows the model `s` asked for (`--shown`): now, where the material shown has it, and,
    /// while a fit runs in the background (an INPUT being fitted), once the fit arrives, which
    /// would otherwise open on its default (GGX).
    pub fn ask_shown(&mut self, s: Shown) {
        if self.material.available(s) {
            self.material.shown = s;
        }
        if self.fit_job.is_some() {
            self.wanted = Some(s);
        } else if !self.material.available(s) {
            self.status = format!(
                "{} asked for, which {} has not; {} shown",
                s.label(),
                self.material.source,
                self.material.shown.label()
            );
        }
    }

    /// The neural proxies' names (the network file is read once).
    pub fn proxies(&mut self) -> &Result<Vec<String>, String> {
        let path = self.nbrdf.clone();
        self.proxy_names.get_or_insert_with(|| {
            facet_fit::sources::nbrdf::NbrdfLibrary::open_or_embedded(path.as_deref())
                .map(|lib| lib.names().map(str::to_owned).collect())
                .map_err(|e| e.to_string())
        })
    }

    fn set_material(&mut self, m: EditedMaterial) {
        self.material = m;
        self.open_text = self.material.source.clone();
    }

    /// Polls the fit job; true while one runs.
    pub fn poll_fit(&mut self) -> bool {
        let Some(job) = &self.fit_job else {
            return false;
        };
        match job.rx.try_recv() {
            Ok(Ok((fit, measurement))) => {
                let label = job.label.clone();
                let secs = job.started.elapsed().as_secs_f64();
                self.fit_job = None;
                self.set_material(match measurement {
                    Some(m) => EditedMaterial::with_measurement(fit, label.clone(), m),
                    None => EditedMaterial::new(fit, label.clone()),
                });
                self.status = format!("fitted {label} in {secs:.1} s");
                match self.wanted.take() {
                    Some(s) if self.material.available(s) => self.material.shown = s,
                    Some(s) => {
                        self.status += &format!(
                            " ({} asked for, which it has not; {} shown)",
                            s.label(),
                            self.material.shown.label()
                        )
                    }
                    None => {}
                }
                false
            }
            Ok(Err(e)) => {
                self.error = Some(format!("cannot open {}: {e}", job.label));
                self.fit_job = None;
                false
            }
            Err(std::sync::mpsc::TryRecvError::Empty) => true,
            Err(std::sync::mpsc::TryRecvError::Disconnected) => {
                self.error = Some(format!("the fit of {} stopped", job.label));
                self.fit_job = None;
                false
            }
        }
    }

    /// Writes the edited material as a fit JSON that `facet render` reads.
    pub fn save(&mut self, path: &Path) {
        let r = FittedMaterial::from_record(self.material.edited_record())
            .map_err(|e| e.to_string())
            .and_then(|m| m.save(path).map_err(|e| e.to_string()));
        match r {
            Ok(()) => {
                self.status = format!("saved {}", path.display());
                self.error = None;
            }
            Err(e) => self.error = Some(format!("cannot save {}: {e}", path.display())),
        }
    }

    /// Sends the material to the renderer if it changed since the last call; true if it did.
    pub fn sync_material(&mut self) -> bool {
        let key = self.material.key();
        if self.sent_key.as_ref() == Some(&key) {
            return false;
        }
        match self.material.render_material() {
            Ok(m) => {
                self.generation += 1;
                self.sent_key = Some(key);
                let sent = self.edited_at.take().unwrap_or_else(Instant::now);
                if let Some(p) = &self.preview {
                    p.send(Command::Material {
                        generation: self.generation,
                        material: Box::new(m),
                        sent,
                    });
                }
                true
            }
            Err(e) => {
                self.error = Some(format!("invalid material: {e}"));
                self.sent_key = Some(key);
                false
            }
        }
    }

    /// Files dropped on the window are opened.
    pub fn handle_drops(&mut self, ctx: &egui::Context) {
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_owned())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        for p in dropped {
            self.open(&p.display().to_string());
        }
    }
}
