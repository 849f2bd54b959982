//! `facet report`'s work: one HTML page, for a paper's supplement, comparing measured materials
//! with their fits — per material, spheres of the measurement and of each model under a point
//! light and an environment, their ΔE2000 images and mean ΔE2000 and ΔE_ITP, NDF and Fresnel
//! plots, errors and times; a database summary (sortable table, mean ΔE per model, mean ΔE
//! images over the set); run time against error over N = 32, 64, 90, 128 ([`sweep`]).
//!
//! [`report`] takes the inputs, an output folder (with its [`IMG`] subfolder made), the device
//! ([`facet_gpu::Gpu`]), the environment ([`Sky`]) and the settings ([`ReportConfig`]), tells
//! its progress through a callback ([`Progress`]) and stops at the first failure that is not a
//! single material's ([`ReportError`]).
//!
//! ```
//! use facet_report::ReportConfig;
//! use facet_report::delta_e::ciede2000;
//! use palette::Lab;
//!
//! let config = ReportConfig { sweep: 0, ..ReportConfig::DEFAULT };
//! assert_eq!(config.fit_config().extract.resolution, 90);
//! let grey = Lab::new(50.0, 0.0, 0.0);
//! assert_eq!(ciede2000(grey, grey), 0.0);
//! ```

pub mod config;
pub mod delta_e;
pub mod error;
pub mod false_colour;
pub mod html;
pub mod material;
pub mod plots;
pub mod progress;
pub mod run;
pub mod scenes;
pub mod sky;
pub mod subject;
pub mod sweep;

pub use config::ReportConfig;
pub use error::{ReportError, Result};
pub use material::MaterialReport;
pub use progress::Progress;
pub use run::{Outcome, means_lines, report};
pub use sky::Sky;

/// Subfolder of the report's images, in the output folder.
pub const IMG: &str = "img";
