//! The environment of the environment renders, and how the page names it.

use facet_render::scene::EnvironmentMap;
use std::sync::Arc;

/// An equirectangular environment map (Y up) and its name on the page.
#[derive(Clone)]
pub struct Sky {
    /// The map the environment renders are lit by.
    pub map: Arc<EnvironmentMap>,
    /// How the page names it: a file's path, or "the demo's sky".
    pub name: String,
}
