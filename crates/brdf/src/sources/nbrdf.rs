//! Neural BRDF proxies of the MERL materials (Sztrajman, Rainer, Ritschel, Weyrich 2021):
//! a 6-21-21-3 MLP per material, `f_r = exp(relu(relu(x W1 + b1) W2 + b2) W3 + b3) − 1`,
//! x = (h, d) of the Rusinkiewicz parameterisation with φh = 0.

use crate::error::BrdfError;
use crate::model::brdf::Brdf;
use crate::model::geometry::{spherical, to_half_diff};
use crate::model::rgb::Rgb;
use glam::DVec3;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

#[derive(Deserialize)]
struct RawWeights {
    #[serde(rename = "W1")]
    w1: Vec<Vec<f64>>,
    b1: Vec<f64>,
    #[serde(rename = "W2")]
    w2: Vec<Vec<f64>>,
    b2: Vec<f64>,
    #[serde(rename = "W3")]
    w3: Vec<Vec<f64>>,
    b3: Vec<f64>,
}

/// A dense layer `y = x W + b`, W stored row-major (inputs × outputs).
#[derive(Clone, Debug)]
struct Layer {
    inputs: usize,
    outputs: usize,
    w: Vec<f64>,
    b: Vec<f64>,
}

impl Layer {
    fn new(w: &[Vec<f64>], b: &[f64], inputs: usize, which: &str) -> Result<Self, String> {
        let outputs = b.len();
        if w.len() != inputs || w.iter().any(|r| r.len() != outputs) || outputs == 0 {
            return Err(format!(
                "{which} must be {inputs}×{outputs} to match its bias"
            ));
        }
        let w: Vec<f64> = w.iter().flatten().copied().collect();
        if w.iter().chain(b).any(|v| !v.is_finite()) {
            return Err(format!("{which} holds a non-finite weight"));
        }
        Ok(Layer {
            inputs,
            outputs,
            w,
            b: b.to_vec(),
        })
    }

    fn apply(&self, x: &[f64], out: &mut [f64]) {
        out[..self.outputs].copy_from_slice(&self.b);
        for (i, &xi) in x[..self.inputs].iter().enumerate() {
            let row = &self.w[i * self.outputs..(i + 1) * self.outputs];
            out[..self.outputs]
                .iter_mut()
                .zip(row)
                .for_each(|(o, w)| *o += xi * w);
        }
    }
}

/// One material's network.
#[derive(Clone, Debug)]
pub struct NeuralBrdf {
    name: String,
    layers: [Layer; 3],
}

/// The largest pre-activation y of the last layer a network may reach, so that exp(y) − 1 is a
/// finite f64 (exp(709) ≈ 8·10³⁰⁷); the 100 MERL networks stay below 40.
pub const MAX_OUTPUT: f64 = 700.0;

impl NeuralBrdf {
    /// An upper bound of the last layer's output over every input the network is evaluated at,
    /// by interval arithmetic: h = (sin θh, 0, cos θh) and d = (sin θd cos φd, sin θd sin φd,
    /// cos θd) with θ ∈ [0, π/2], φd ∈ [0, π), so x ∈ [0,1]×{0}×[0,1]×[−1,1]×[0,1]×[0,1].
    fn output_bound(&self) -> f64 {
        let mut lo = vec![0.0, 0.0, 0.0, -1.0, 0.0, 0.0];
        let mut hi = vec![1.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        for (n, layer) in self.layers.iter().enumerate() {
            // y_j ∈ [b_j + Σ min(w lo, w hi), b_j + Σ max(w lo, w hi)]; ReLU between layers.
            let (mut l, mut h) = (layer.b.clone(), layer.b.clone());
            for i in 0..layer.inputs {
                let row = &layer.w[i * layer.outputs..(i + 1) * layer.outputs];
                for (j, &w) in row.iter().enumerate() {
                    let (a, b) = (w * lo[i], w * hi[i]);
                    l[j] += a.min(b);
                    h[j] += a.max(b);
                }
            }
            if n < 2 {
                l.iter_mut()
                    .chain(h.iter_mut())
                    .for_each(|v| *v = v.max(0.0));
            }
            (lo, hi) = (l, h);
        }
        hi.into_iter().fold(f64::NEG_INFINITY, f64::max)
    }

    /// f_r from the network inputs x = (h, d).
    fn forward(&self, x: [f64; 6]) -> Rgb {
        let mut a = [0.0; 64];
        let mut b = [0.0; 64];
        self.layers[0].apply(&x, &mut a);
        a.iter_mut().for_each(|v| *v = v.max(0.0));
        self.layers[1].apply(&a, &mut b);
        b.iter_mut().for_each(|v| *v = v.max(0.0));
        self.layers[2].apply(&b, &mut a);
        // exp(y) − 1 can dip below 0 by a hair where the fit undershoots; f_r ≥ 0.
        [
            a[0].exp_m1().max(0.0),
            a[1].exp_m1().max(0.0),
            a[2].exp_m1().max(0.0),
        ]
    }
}

impl Brdf for NeuralBrdf {
    fn name(&self) -> &str {
        &self.name
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let c = to_half_diff(wi, wo);
        let h = spherical(c.theta_h, 0.0);
        let d = spherical(c.theta_d, c.phi_d.rem_euclid(PI)); // φd on MERL's [0, π)
        Some(self.forward([h.x, h.y, h.z, d.x, d.y, d.z]))
    }
}

/// The MERL-100 networks shipped inside the crate.
const EMBEDDED: &str = include_str!("../../data/nbrdf/merl100.json");
/// How the embedded file is named in messages.
pub const EMBEDDED_LABEL: &str = "merl100.json (embedded in facet-fit)";

/// The file of networks, `name -> weights`.
pub struct NbrdfLibrary {
    path: PathBuf,
    entries: BTreeMap<String, serde_json::Value>,
}

impl NbrdfLibrary {
    /// The neural proxies of the 100 MERL materials, embedded in the library
    /// (`crates/brdf/data/nbrdf/`, MIT licence, see its README). Parsed on each call: keep it.
    pub fn embedded() -> Self {
        Self::parse(Path::new(EMBEDDED_LABEL), EMBEDDED)
            .expect("the embedded MERL-100 file is valid JSON of networks")
    }

    /// The file to read instead of the embedded one: `arg` (`--nbrdf`), else `$FACET_NBRDF`;
    /// `None` means [`NbrdfLibrary::embedded`].
    pub fn override_path(arg: Option<&Path>) -> Option<PathBuf> {
        arg.map(Path::to_owned)
            .or_else(|| std::env::var_os("FACET_NBRDF").map(PathBuf::from))
    }

    /// The library `nbrdf:` names resolve in, the same in every command: `path` (`--nbrdf`)
    /// when given, else `$FACET_NBRDF`, else the embedded library.
    pub fn open_or_embedded(path: Option<&Path>) -> Result<Self, BrdfError> {
        match Self::override_path(path).as_deref() {
            Some(p) => Self::open(p),
            None => Ok(Self::embedded()),
        }
    }

    /// Reads a file of proxies in the format of the embedded one.
    pub fn open(path: &Path) -> Result<Self, BrdfError> {
        Self::parse(
            path,
            &crate::io::input::read_to_string(path, crate::io::input::Cap::NBRDF)?,
        )
    }

    /// A library from the text of its JSON; `path` names it in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Self, BrdfError> {
        let bad = |problem: String| BrdfError::Nbrdf {
            path: path.to_owned(),
            problem,
        };
        let entries: BTreeMap<String, serde_json::Value> = serde_json::from_str(text)
            .map_err(|e| bad(format!("not a JSON object of networks: {e}")))?;
        if entries.is_empty() {
            return Err(bad("holds no material".into()));
        }
        Ok(NbrdfLibrary {
            path: path.to_owned(),
            entries,
        })
    }

    /// The names of the materials held.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.entries.keys().map(String::as_str)
    }

    /// The proxy of material `name`; an unknown name is an error that lists near names.
    pub fn get(&self, name: &str) -> Result<NeuralBrdf, BrdfError> {
        let bad = |problem: String| BrdfError::Nbrdf {
            path: self.path.clone(),
            problem,
        };
        let value = self.entries.get(name).ok_or_else(|| {
            let near: Vec<&str> = self
                .names()
                .filter(|n| n.contains(name) || name.contains(*n))
                .take(5)
                .collect();
            // Escaped: a name from a command line or a scene may hold terminal escapes.
            bad(format!(
                "no material named `{}`{}",
                name.escape_debug(),
                if near.is_empty() {
                    String::new()
                } else {
                    let near: Vec<String> =
                        near.iter().map(|n| n.escape_debug().to_string()).collect();
                    format!(" (did you mean {}?)", near.join(", "))
                }
            ))
        })?;
        let name = name.escape_debug().to_string();
        let raw: RawWeights = serde_json::from_value(value.clone())
            .map_err(|e| bad(format!("material `{name}`: {e}")))?;
        let l1 = Layer::new(&raw.w1, &raw.b1, 6, "W1")
            .map_err(|p| bad(format!("material `{name}`: {p}")))?;
        let l2 = Layer::new(&raw.w2, &raw.b2, l1.outputs, "W2")
            .map_err(|p| bad(format!("material `{name}`: {p}")))?;
        let l3 = Layer::new(&raw.w3, &raw.b3, l2.outputs, "W3")
            .map_err(|p| bad(format!("material `{name}`: {p}")))?;
        if l3.outputs != 3 || l1.outputs > 64 || l2.outputs > 64 {
            return Err(bad(format!(
                "material `{name}`: layer sizes must be 6-H-H-3 with H ≤ 64"
            )));
        }
        let net = NeuralBrdf {
            name: name.to_owned(),
            layers: [l1, l2, l3],
        };
        let bound = net.output_bound();
        if !(bound <= MAX_OUTPUT) {
            return Err(bad(format!(
                "material `{name}`: the network's output can reach {bound:e} before exp (at most {MAX_OUTPUT}), so f_r = exp(y) − 1 could overflow"
            )));
        }
        Ok(net)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_output_bound_holds_and_admits_every_merl_network() {
        let lib = NbrdfLibrary::embedded();
        let mut worst = 0.0f64;
        for name in lib.names() {
            let net = lib.get(name).unwrap();
            let bound = net.output_bound();
            worst = worst.max(bound);
            // The bound is an upper bound: no input of the domain exceeds it.
            for k in 0..=20 {
                let (t, p) = (k as f64 / 20.0 * PI / 2.0, k as f64 / 21.0 * PI);
                let x = [t.sin(), 0.0, t.cos(), p.cos() * 0.7, p.sin() * 0.7, 0.714];
                let mut a = [0.0; 64];
                let mut b = [0.0; 64];
                net.layers[0].apply(&x, &mut a);
                a.iter_mut().for_each(|v| *v = v.max(0.0));
                net.layers[1].apply(&a, &mut b);
                b.iter_mut().for_each(|v| *v = v.max(0.0));
                net.layers[2].apply(&b, &mut a);
                assert!(
                    a[..3].iter().all(|&y| y <= bound),
                    "{name}: {a:?} > {bound}"
                );
            }
        }
        assert!(
            worst < 50.0,
            "the MERL networks are bounded by 40; got {worst}"
        );
        // A bias of 710 passes every finiteness check but would make exp overflow.
        let text = r#"{"m":{"W1":[[0],[0],[0],[0],[0],[0]],"b1":[0],"W2":[[0]],"b2":[0],"W3":[[0,0,0]],"b3":[710,0,0]}}"#;
        let err = NbrdfLibrary::parse(Path::new("big.json"), text)
            .unwrap()
            .get("m")
            .unwrap_err()
            .to_string();
        assert!(err.contains("big.json") && err.contains("7.1e2"), "{err}");
    }
}
