//! # facet-viewer: interactive roughness and stretch on a live path-traced preview
//!
//! [`app::ViewerApp`] is the UI state (material, edits, errors); [`preview`] owns the GPU work
//! on a worker thread that shares eframe's device; `plots` draws the NDF slice, the Fresnel
//! curves and the fit errors with egui's painter; `panels` lays the window out (both internal).
//!
//! ```no_run
//! use facet_viewer::{ViewerApp, material::Shown};
//! let mut app = ViewerApp::with_default_material()?;
//! app.material.shown = Shown::Tabulated;
//! app.material.set_alpha(0.5, 1.5, 0.0); // stretch the tabulated NDF
//! let _sphere = app.material.render_material()?; // what the preview renders
//! app.save("edited.json".as_ref()); // a fit JSON that `facet render` reads
//! # Ok::<(), String>(())
//! ```

#![warn(missing_docs)]

pub mod app;
pub mod material;
pub(crate) mod panels;
pub(crate) mod plots;
pub mod preview;

pub use app::ViewerApp;

/// `assets/demo` of the workspace: the crate's `demo/`, a link to it in the repository that
/// `cargo package` turns into a copy, so a packaged viewer finds its default fit and sky; the
/// workspace folder itself where the link did not survive a checkout (a text file on Windows
/// without `core.symlinks`).
pub fn demo_dir() -> std::path::PathBuf {
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let linked = manifest.join("demo");
    let dir = if linked.is_dir() {
        linked
    } else {
        manifest.join("../../assets/demo")
    };
    dir.canonicalize().unwrap_or(dir)
}
