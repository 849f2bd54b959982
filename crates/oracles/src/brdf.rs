//! Oracles of the fitter's loaders: a BRDF evaluated at a few direction pairs, a fit JSON's
//! models, a neural BRDF library's networks, a MERL table as read, and an error's message.

use facet_fit::Brdf;
use facet_fit::model::material::{FittedMaterial, ModelChoice};
use facet_fit::model::merl_grid::{
    MAX_STORED, MerlTable, PHI_D_RES, SAMPLES, SCALE, THETA_D_RES, THETA_H_RES,
};
use facet_fit::sources::merl::MerlBrdf;
use facet_fit::sources::nbrdf::NbrdfLibrary;
use glam::DVec3;
use std::path::Path;

/// `Ok` when the error's message names `path` (every loader's errors do), else what is wrong.
pub fn names_path(path: &Path, e: impl std::fmt::Display) -> Result<(), String> {
    let message = e.to_string();
    if message.contains(&path.display().to_string()) {
        Ok(())
    } else {
        Err(format!(
            "the error does not name {}: {message}",
            path.display()
        ))
    }
}

/// Direction pairs (wi, wo) a BRDF is evaluated at: normal, mid, grazing, retro, forward.
pub fn direction_pairs() -> [(DVec3, DVec3); 6] {
    let d = |theta: f64, phi: f64| {
        DVec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    };
    [
        (d(0.0, 0.0), d(0.0, 0.0)),
        (d(0.3, 0.0), d(0.5, 3.1)),
        (d(1.2, 0.4), d(0.7, 2.0)),
        (d(1.56, 0.0), d(1.56, std::f64::consts::PI)),
        (d(0.8, 1.0), d(0.8, 1.0)),
        (d(1.5, -2.0), d(0.1, 3.0)),
    ]
}

/// Every value the BRDF gives at [`direction_pairs`] is finite and non-negative (`what` names
/// the BRDF in the message).
pub fn brdf_sane(what: &str, brdf: &dyn Brdf) -> Result<(), String> {
    for (wi, wo) in direction_pairs() {
        if let Some(v) = brdf.eval(wi, wo)
            && !v.iter().all(|x| x.is_finite() && *x >= 0.0)
        {
            return Err(format!("accepted, but {what}: f_r({wi}, {wo}) = {v:?}"));
        }
    }
    Ok(())
}

/// Every model of an accepted fit JSON (tabulated, GGX, Beckmann) passes [`brdf_sane`].
pub fn fit_sane(fit: &FittedMaterial) -> Result<(), String> {
    for choice in [
        ModelChoice::Tabulated,
        ModelChoice::Ggx,
        ModelChoice::Beckmann,
    ] {
        if let Some(model) = fit.model(choice) {
            brdf_sane(&format!("its {choice:?} model"), model)?;
        }
    }
    Ok(())
}

/// Every network of an accepted neural BRDF library (read from `path`) either builds and
/// passes [`brdf_sane`] or is refused with an error naming `path`. `Ok(true)` when at least one
/// network was built.
pub fn nbrdf_sane(path: &Path, library: &NbrdfLibrary) -> Result<bool, String> {
    let mut any = false;
    for name in library.names() {
        match library.get(name) {
            Ok(brdf) => {
                brdf_sane(&format!("network `{name}`"), &brdf)?;
                any = true;
            }
            Err(e) => names_path(path, e)?,
        }
    }
    Ok(any)
}

/// Whether `bytes` are a MERL file of the standard layout: the 90×90×180 header and exactly
/// the values it announces. The reader accepts nothing else.
pub fn merl_standard_layout(bytes: &[u8]) -> bool {
    let header: Vec<u8> = [THETA_H_RES, THETA_D_RES, PHI_D_RES]
        .iter()
        .flat_map(|&d| (d as i32).to_le_bytes())
        .collect();
    bytes.len() == 12 + 3 * 8 * SAMPLES && bytes[..12] == header[..]
}

/// A MERL table the reader accepted from `bytes`: the file is of the standard layout
/// ([`merl_standard_layout`]); each value a caller wrote into the file, `written` as (flat
/// channel-major index, value) with the last write of an index last, is neither NaN nor above
/// `MAX_STORED` and reads back scaled (unless missing); every sample read is finite and
/// non-negative; the table as a source passes [`brdf_sane`].
pub fn merl_sane(bytes: &[u8], table: MerlTable, written: &[(usize, f64)]) -> Result<(), String> {
    if !merl_standard_layout(bytes) {
        return Err(format!(
            "accepted a file that is not the 90×90×180 layout ({} bytes, header {:?})",
            bytes.len(),
            &bytes[..bytes.len().min(12)]
        ));
    }
    for &(index, v) in written {
        if v.is_nan() || v > MAX_STORED {
            return Err(format!("accepted a table whose value {index} is {v:e}"));
        }
        let (c, s) = (index / SAMPLES, index % SAMPLES);
        if let Some(rgb) = table.value_at(s)
            && (v < 0.0 || rgb[c] != v * SCALE[c])
        {
            return Err(format!("value {index} = {v:e} reads back as {:e}", rgb[c]));
        }
    }
    if let Some(s) = (0..SAMPLES).find(|&s| {
        table
            .value_at(s)
            .is_some_and(|v| !v.iter().all(|x| x.is_finite() && *x >= 0.0))
    }) {
        return Err(format!("sample {s} is {:?}", table.value_at(s)));
    }
    if let Ok(brdf) = MerlBrdf::from_table("accepted", table) {
        brdf_sane("the table as a BRDF", &brdf)?;
    }
    Ok(())
}
