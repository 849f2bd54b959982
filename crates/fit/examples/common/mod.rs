//! What the examples that measure issue 48's candidates share (a module, not an example: cargo
//! builds `examples/*.rs` and `examples/*/main.rs` only). Each example uses a part of it.
#![allow(dead_code)]

use facet_fit::model::brdf::Brdf;
use facet_fit::model::rgb::Rgb;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use glam::DVec3;
use std::path::Path;

/// The proxies of the file `arg` names, or the embedded MERL-100 for none or `-`.
pub fn library(arg: Option<&String>) -> NbrdfLibrary {
    match arg.filter(|a| a.as_str() != "-") {
        Some(p) => NbrdfLibrary::open(Path::new(p)).unwrap(),
        None => NbrdfLibrary::embedded(),
    }
}

/// Channel `c` of a source, grey (the same value in R, G and B).
pub struct Channel<'a>(pub &'a dyn Brdf, pub usize);

impl Brdf for Channel<'_> {
    fn name(&self) -> &str {
        self.0.name()
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        self.0.eval(wi, wo).map(|v| [v[self.1]; 3])
    }
    fn backscatter(&self, theta: f64, phi: f64) -> Option<Rgb> {
        self.0.backscatter(theta, phi).map(|v| [v[self.1]; 3])
    }
}

/// Channel c of model c, for each c.
pub struct PerChannel<B>(pub [B; 3]);

impl<B: Brdf> Brdf for PerChannel<B> {
    fn name(&self) -> &str {
        "per channel"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        let mut out = [0.0; 3];
        for (c, m) in self.0.iter().enumerate() {
            out[c] = m.eval(wi, wo)?[c];
        }
        Some(out)
    }
}
