//! Facet's one benchmark system: the scenes, the timing (medians after a warm-up) and the JSON
//! records that `facet bench` prints and writes, one module per section, and the scene builders
//! that the criterion benches (`benches/` of facet-cli) measure on.
//!
//! Every section takes the device ([`facet_gpu::Gpu`]) and the sizes of one mode ([`Sizes`]),
//! prints its table as it goes and returns its JSON, or stops at its first failure and says why
//! ([`BenchError`]).
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
pub mod error;
pub mod measure;
pub mod record;
pub mod scenes;
pub mod section;
pub mod sizes;
pub mod timing;

pub use assets::Assets;
pub use error::{BenchError, Result};
pub use sizes::Sizes;
