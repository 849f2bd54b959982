//! Facet's one benchmark system: the scenes, the timing (medians after a warm-up) and the JSON
//! records that `facet bench` prints and writes, one module per section, and the scene builders
//! that the criterion benches (`benches/` of facet-cli) measure on.
//!
//! Every section takes the device ([`facet_gpu::Gpu`]) and the sizes of one mode ([`Sizes`]),
//! prints its table as it goes and returns its JSON. A section is a measurement that stops at
//! its first failure and says why: its errors are `anyhow` errors with context, for the binary
//! that called it to print, not to be matched on.
//!
//! ```
//! use facet_bench::Sizes;
//! use facet_bench::timing::median_ms;
//!
//! let sizes = Sizes::SMOKE;
//! let ms = median_ms(sizes.runs, || Ok(())).unwrap();
//! assert!(ms >= 0.0);
//! ```

pub mod assets;
pub mod measure;
pub mod record;
pub mod scenes;
pub mod section;
pub mod sizes;
pub mod timing;

pub use assets::Assets;
pub use sizes::Sizes;
