//! Helpers of the render crate's tests: a tiny glTF writer (one embedded base64 buffer),
//! loading a glTF or its error, temp folders and a small fit; `demo`: the demo scene;
//! `renders`: the scenes and settings of the GPU render tests.
#![allow(dead_code)]

pub mod demo;
pub mod renders;

use facet_render::scene::data_uri::encode_base64;
use facet_render::scene::{LoadOptions, Scene, load_gltf};
use glam::Vec3;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The glTF at `path`, loaded with the default options; panics with the error.
pub fn load(path: &Path) -> Scene {
    load_gltf(path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The error message of loading the glTF at `path`; panics when it loads.
pub fn load_err(path: &Path, options: &LoadOptions) -> String {
    match load_gltf(path, options) {
        Ok(_) => panic!("{} loaded but should not", path.display()),
        Err(e) => e.to_string(),
    }
}

/// Equal positions, to 1e-5.
pub fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

/// A fresh, empty folder for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("facet-render-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Builds a glTF JSON document with a single buffer embedded as a data URI.
#[derive(Default)]
pub struct GltfBuilder {
    pub bin: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
    pub meshes: Vec<Value>,
    pub nodes: Vec<Value>,
    pub materials: Vec<Value>,
    pub cameras: Vec<Value>,
    pub lights: Vec<Value>,
    pub images: Vec<Value>,
    pub textures: Vec<Value>,
    pub extensions_used: Vec<&'static str>,
}

impl GltfBuilder {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// A float accessor of `kind` ("VEC2", "VEC3", "VEC4"), with min/max (glTF wants them on
    /// POSITION).
    pub fn floats(&mut self, data: &[f32], kind: &str) -> usize {
        let n = match kind {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            _ => panic!("accessor kind {kind}"),
        };
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let (mut lo, mut hi) = (vec![f32::INFINITY; n], vec![f32::NEG_INFINITY; n]);
        for c in data.chunks(n) {
            for k in 0..n {
                // NaN positions (a bad-input test) must not poison min/max: JSON has no NaN.
                if c[k].is_finite() {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
        }
        let fix = |v: Vec<f32>| {
            v.into_iter()
                .map(|x| if x.is_finite() { x } else { 0.0 })
                .collect::<Vec<_>>()
        };
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5126, "count": data.len() / n, "type": kind,
            "min": fix(lo), "max": fix(hi)
        }));
        self.accessors.len() - 1
    }

    pub fn vec3s(&mut self, v: &[[f32; 3]]) -> usize {
        self.floats(&v.concat(), "VEC3")
    }

    pub fn indices(&mut self, idx: &[u32]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": idx.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// A mesh of one triangle primitive; `attributes` like `{"POSITION": 0}`.
    pub fn mesh(
        &mut self,
        name: &str,
        attributes: Value,
        indices: Option<usize>,
        material: Option<usize>,
    ) -> usize {
        let mut prim = json!({"attributes": attributes});
        if let Some(i) = indices {
            prim["indices"] = json!(i);
        }
        if let Some(m) = material {
            prim["material"] = json!(m);
        }
        self.meshes
            .push(json!({"name": name, "primitives": [prim]}));
        self.meshes.len() - 1
    }

    pub fn node(&mut self, node: Value) -> usize {
        self.nodes.push(node);
        self.nodes.len() - 1
    }

    pub fn material(&mut self, m: Value) -> usize {
        self.materials.push(m);
        self.materials.len() - 1
    }

    /// The document with `roots` as its only scene.
    pub fn finish(&self, roots: &[usize]) -> Value {
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "facet-render tests"},
            "scene": 0,
            "scenes": [{"nodes": roots}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{
                "byteLength": self.bin.len(),
                "uri": format!("data:application/octet-stream;base64,{}", encode_base64(&self.bin))
            }],
        });
        for (key, list) in [
            ("materials", &self.materials),
            ("cameras", &self.cameras),
            ("images", &self.images),
            ("textures", &self.textures),
        ] {
            if !list.is_empty() {
                doc[key] = json!(list);
            }
        }
        if !self.lights.is_empty() {
            doc["extensions"] = json!({"KHR_lights_punctual": {"lights": self.lights}});
        }
        if !self.extensions_used.is_empty() {
            doc["extensionsUsed"] = json!(self.extensions_used);
        }
        doc
    }

    pub fn write(&self, roots: &[usize], path: &Path) {
        std::fs::write(
            path,
            serde_json::to_string_pretty(&self.finish(roots)).unwrap(),
        )
        .unwrap();
    }

    /// One triangle in the XY plane facing +Z: accessors (positions, normals, indices).
    pub fn triangle(&mut self) -> (usize, usize, usize) {
        let p = self.vec3s(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let n = self.vec3s(&[[0.0, 0.0, 1.0]; 3]);
        let i = self.indices(&[0, 1, 2]);
        (p, n, i)
    }
}

/// A small fit (GGX α = 0.3 source; tabulated and GGX models, no Beckmann) saved once per test
/// process; returns its path.
pub fn small_fit() -> &'static Path {
    static FIT: OnceLock<PathBuf> = OnceLock::new();
    FIT.get_or_init(|| {
        use facet_fit::fitting::{FitConfig, Models, fit_material};
        let src = facet_fit::model::analytic::parse_analytic("ggx?alpha=0.3&f0=0.04").unwrap();
        let mut cfg = FitConfig::isotropic();
        cfg.extract.resolution = 32;
        cfg.models = Models {
            tabulated: true,
            ggx: true,
            beckmann: false,
        };
        let fit = fit_material(&src, "test ggx 0.3", &cfg).unwrap();
        let path = temp_dir("fit").join("small_fit.json");
        fit.save(&path).unwrap();
        path
    })
}

/// Every float of the scene is finite.
pub fn assert_all_finite(s: &facet_render::scene::Scene) {
    assert!(s.positions.iter().all(|p| p.is_finite()), "positions");
    assert!(s.normals.iter().all(|p| p.is_finite()), "normals");
    assert!(s.uvs.iter().all(|p| p.is_finite()), "uvs");
    assert!(s.tangents.iter().all(|p| p.is_finite()), "tangents");
    let n = s.positions.len();
    assert_eq!(s.normals.len(), n);
    assert_eq!(s.uvs.len(), n);
    assert_eq!(s.tangents.len(), n);
    assert_eq!(s.triangle_material.len(), s.indices.len());
    assert!(s.indices.iter().flatten().all(|&i| (i as usize) < n));
    assert!(
        s.triangle_material
            .iter()
            .all(|&m| (m as usize) < s.materials.len())
    );
}

/// Runs a probe `pipeline` (of workgroup size `wg`) over `n` queries: its bindings are
/// `bindings` and then an output of one vec4 a query, read back.
pub fn probe(
    gpu: &facet_gpu::Gpu,
    pipeline: &wgpu::ComputePipeline,
    label: &str,
    bindings: &[wgpu::BindingResource],
    n: u32,
    wg: u32,
) -> Vec<[f32; 4]> {
    let out = facet_gpu::buffer::storage_zeroed(&gpu.device, "probe out", u64::from(n) * 16);
    let mut all = bindings.to_vec();
    all.push(out.as_entire_binding());
    facet_gpu::dispatch::run(&gpu.device, &gpu.queue, pipeline, label, &all, n, wg);
    facet_gpu::buffer::read(&gpu.device, &gpu.queue, &out, n as usize).unwrap()
}
