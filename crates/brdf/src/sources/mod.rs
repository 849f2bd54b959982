//! The measured sources — MERL files, the neural proxies, RGL `.bsdf` files — and an input
//! named on a command line resolved to one ([`InputSpec`]).

pub mod merl;
pub mod nbrdf;
pub mod rgl;

use crate::error::BrdfError;
use crate::model::analytic::parse_analytic;
use crate::model::brdf::Brdf;
use crate::model::material::FittedMaterial;
use crate::sources::merl::MerlBrdf;
use crate::sources::nbrdf::NbrdfLibrary;
use crate::sources::rgl::RglBsdf;
use std::path::{Path, PathBuf};

/// An input as a user names it (`facet fit INPUT`, `facet convert INPUT`, the viewer's open
/// box), parsed once into what it names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum InputSpec {
    /// `nbrdf:NAME`: one of the neural proxies.
    Nbrdf(String),
    /// `analytic:SPEC`: an analytic model ([`parse_analytic`]).
    Analytic(String),
    /// A fit `.json`: its tabulated model (under its coat when it kept one).
    Fit(PathBuf),
    /// An RGL `.bsdf`.
    Rgl(PathBuf),
    /// A MERL `.binary` file (any other name).
    Merl(PathBuf),
}

/// How a MERL file is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Residence {
    /// Read into memory.
    Read,
    /// Mapped ([`MerlBrdf::map`]): the fast way for a short-lived process; the file must not
    /// be truncated in place while the source lives.
    Mapped,
}

impl InputSpec {
    /// What `input` names: by its `nbrdf:` or `analytic:` prefix, else by its extension (any
    /// case).
    pub fn parse(input: &str) -> Self {
        if let Some(name) = input.strip_prefix("nbrdf:") {
            return InputSpec::Nbrdf(name.to_owned());
        }
        if let Some(spec) = input.strip_prefix("analytic:") {
            return InputSpec::Analytic(spec.to_owned());
        }
        let path = PathBuf::from(input);
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("json") => InputSpec::Fit(path),
            Some("bsdf") => InputSpec::Rgl(path),
            _ => InputSpec::Merl(path),
        }
    }

    /// The file the input reads, if it names one (not the neural proxies' file, which
    /// `nbrdf:` inputs share).
    pub fn path(&self) -> Option<&Path> {
        match self {
            InputSpec::Nbrdf(_) | InputSpec::Analytic(_) => None,
            InputSpec::Fit(p) | InputSpec::Rgl(p) | InputSpec::Merl(p) => Some(p),
        }
    }

    /// The source. `nbrdf` is the network file of `nbrdf:` inputs (`None`: the embedded
    /// MERL-100 proxies), opened into `library` on first use.
    pub fn open(
        &self,
        nbrdf: Option<&Path>,
        library: &mut Option<NbrdfLibrary>,
        merl: Residence,
    ) -> Result<Box<dyn Brdf + Send>, BrdfError> {
        Ok(match self {
            InputSpec::Nbrdf(name) => {
                if library.is_none() {
                    *library = Some(NbrdfLibrary::open_or_embedded(nbrdf)?);
                }
                Box::new(library.as_ref().unwrap().get(name)?)
            }
            InputSpec::Analytic(spec) => Box::new(parse_analytic(spec)?),
            InputSpec::Fit(path) => Box::new(FittedMaterial::load(path)?),
            InputSpec::Rgl(path) => Box::new(RglBsdf::open(path)?),
            InputSpec::Merl(path) => Box::new(match merl {
                Residence::Read => MerlBrdf::open(path)?,
                Residence::Mapped => MerlBrdf::map(path)?,
            }),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_is_named_by_its_prefix_or_its_extension() {
        let path = |s: &str| PathBuf::from(s);
        assert_eq!(
            InputSpec::parse("nbrdf:gold-paint"),
            InputSpec::Nbrdf("gold-paint".into())
        );
        assert_eq!(
            InputSpec::parse("analytic:ggx?alpha=0.2"),
            InputSpec::Analytic("ggx?alpha=0.2".into())
        );
        assert_eq!(
            InputSpec::parse("a/fit.json"),
            InputSpec::Fit(path("a/fit.json"))
        );
        assert_eq!(
            InputSpec::parse("FIT.JSON"),
            InputSpec::Fit(path("FIT.JSON"))
        );
        assert_eq!(
            InputSpec::parse("paint.bsdf"),
            InputSpec::Rgl(path("paint.bsdf"))
        );
        assert_eq!(
            InputSpec::parse("gold.binary"),
            InputSpec::Merl(path("gold.binary"))
        );
        assert_eq!(
            InputSpec::parse("no-extension"),
            InputSpec::Merl(path("no-extension"))
        );
        // A prefix is a prefix only at the start; the files a run reads are the named ones.
        assert_eq!(
            InputSpec::parse("x/nbrdf:a"),
            InputSpec::Merl(path("x/nbrdf:a"))
        );
        assert_eq!(InputSpec::parse("nbrdf:x").path(), None);
        assert_eq!(
            InputSpec::parse("m.binary").path(),
            Some(Path::new("m.binary"))
        );
    }
}
