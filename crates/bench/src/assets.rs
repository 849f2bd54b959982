//! Where the benchmarks' files are: the demo scene, its sky and fit, the many-light rooms.

use std::path::PathBuf;

/// The `assets/` folder of the repository (or of facet-cli's package, which carries it).
#[derive(Clone, Debug)]
pub struct Assets {
    /// The folder holding `demo/` and `many_lights/`.
    pub root: PathBuf,
}

impl Assets {
    /// The assets under `root`.
    pub fn new(root: impl Into<PathBuf>) -> Self {
        Assets { root: root.into() }
    }

    /// The demo scene's glTF.
    pub fn demo_gltf(&self) -> PathBuf {
        self.root.join("demo/demo.gltf")
    }

    /// The demo's sky.
    pub fn sky(&self) -> PathBuf {
        self.root.join("demo/sky.exr")
    }

    /// The demo's fit (the default material fitted).
    pub fn demo_fit(&self) -> PathBuf {
        self.root.join("demo/default_fit.json")
    }

    /// A many-light room of `many_lights/`.
    pub fn room(&self, file: &str) -> PathBuf {
        self.root.join("many_lights").join(file)
    }
}
