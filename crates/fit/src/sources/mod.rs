//! Resolving an input of `facet fit` to a BRDF source.

pub mod merl;
pub mod nbrdf;
pub mod rgl;

use crate::error::FitError;
use crate::model::analytic::parse_analytic;
use crate::model::brdf::Brdf;
use crate::model::material::FittedMaterial;
use crate::sources::merl::MerlBrdf;
use crate::sources::nbrdf::NbrdfLibrary;
use crate::sources::rgl::RglBsdf;
use std::path::Path;

/// An input: `nbrdf:NAME`, `analytic:SPEC`, a fit `.json` (its tabulated model), an RGL
/// `.bsdf` or a MERL file (any other name, read into memory).
/// `nbrdf` is the network file used for `nbrdf:` inputs (`None`: the embedded MERL-100
/// proxies), opened on first use.
pub fn open_source(
    input: &str,
    nbrdf: Option<&Path>,
    library: &mut Option<NbrdfLibrary>,
) -> Result<Box<dyn Brdf>, FitError> {
    open(input, nbrdf, library, false)
}

/// [`open_source`] for a short-lived process: a MERL file is mapped ([`MerlBrdf::map`]), not
/// read, and must not be truncated in place while the source lives.
pub fn open_source_mapped(
    input: &str,
    nbrdf: Option<&Path>,
    library: &mut Option<NbrdfLibrary>,
) -> Result<Box<dyn Brdf>, FitError> {
    open(input, nbrdf, library, true)
}

fn open(
    input: &str,
    nbrdf: Option<&Path>,
    library: &mut Option<NbrdfLibrary>,
    map: bool,
) -> Result<Box<dyn Brdf>, FitError> {
    if let Some(name) = input.strip_prefix("nbrdf:") {
        if library.is_none() {
            *library = Some(NbrdfLibrary::open_or_embedded(nbrdf)?);
        }
        return Ok(Box::new(library.as_ref().unwrap().get(name)?));
    }
    if let Some(spec) = input.strip_prefix("analytic:") {
        return Ok(Box::new(parse_analytic(spec)?));
    }
    let path = Path::new(input);
    if path.extension().is_some_and(|e| e == "json") {
        return Ok(Box::new(FittedMaterial::load(path)?));
    }
    if path.extension().is_some_and(|e| e == "bsdf") {
        return Ok(Box::new(RglBsdf::open(path)?));
    }
    Ok(Box::new(match map {
        true => MerlBrdf::map(path)?,
        false => MerlBrdf::open(path)?,
    }))
}
