//! RGL `.bsdf` materials (Dupuy & Jakob 2018, "An Adaptive Parameterization for Efficient
//! Material Acquisition and Rendering"): reading them as a [`Brdf`] source and writing any
//! isotropic [`Brdf`] as one.
//!
//! A `.bsdf` is a [tensor file](crate::sources::rgl::tensor_file) with the fields that rgl-epfl/brdf-loader
//! (`powitacq_rgb.inl`) and Mitsuba 3's `measured` plugin (`src/bsdfs/measured.cpp`) read:
//!
//! | field | shape | meaning |
//! |---|---|---|
//! | `theta_i`, `phi_i` | `[nθ]`, `[nφ]` | incident directions of the slices (radians) |
//! | `ndf` | `[rows, cols]` | D(m) on u = (√(θ / (π/2)), (φ + π) / 2π) |
//! | `sigma` | `[rows, cols]` | projected area σ(ωi) = ∫ D(m) ⟨ωi, m⟩₊ dm on the same u |
//! | `vndf` | `[nφ, nθ, rows, cols]` | the visible-normal density per slice, over u of m |
//! | `luminance` | `[nφ, nθ, n, n]` | the density of the sample space, for importance sampling |
//! | `rgb` or `spectra` + `wavelengths` | `[nφ, nθ, 3 or nλ, n, n]` | the data on the sample space |
//! | `jacobian` | `[1]` (u8) | whether the data is f cos θo · 4σ / D (1) or f cos θo (0) |
//! | `description` | `[len]` (u8) | text |
//!
//! Evaluating f(ωi, ωo): m = (ωi + ωo)/|…|, u(m) with φm taken relative to φi when isotropic
//! (`phi_i` has at most 2 entries), the sample-space point s = vndf⁻¹(u(m) | φi, θi), then
//! f cos θo = data(s | φi, θi) · D(u(m)) / (4 σ(u(ωi))) when `jacobian` is set (the readers'
//! `eval` returns f cos θo, Mitsuba's convention; [`Brdf::eval`] divides by cos θo). Anisotropic files
//! whose `phi_i` spans 2π / k (k = 2 or 4) are folded by the symmetry the format's readers
//! apply. Spectral files are converted to linear Rec.709 as they are read ([`crate::sources::rgl::cie`]),
//! which commutes with the interpolation; negative (out-of-gamut) values are clipped at zero
//! when evaluated, as brdf-loader does with `POWITACQ_CLIP_RGB`.
//!
//! Writing (`write_rgl`) samples the source where the format stores it: the VNDF of a given
//! NDF at each θi node, the sample-space grid warped through it, the source's f cos θo there
//! times 4σ / D with σ and D exactly as the reader interpolates them, so that the file
//! reproduces the source at every node; `luminance` is Y(data), the density that makes the
//! sampling proportional to f cos θo.

pub mod cie;
mod sample;
pub mod tensor_file;
pub mod warp2d;

use crate::error::BrdfError;
use crate::model::brdf::Brdf;
use crate::model::merl_grid::MAX_X;
use crate::model::rgb::Rgb;
use crate::sources::rgl::cie::SpectrumToRgb;
use crate::sources::rgl::tensor_file::TensorFile;
use crate::sources::rgl::warp2d::Warp2D;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// A `.bsdf` material.
pub struct RglBsdf {
    name: String,
    description: String,
    isotropic: bool,
    jacobian: bool,
    /// 2 or 4 for anisotropic files folded by symmetry, else 1.
    reduction: i32,
    ndf: Warp2D,
    sigma: Warp2D,
    pub(crate) vndf: Warp2D,
    luminance: Warp2D,
    rgb: [Warp2D; 3],
    spectral: bool,
}

/// θ to the format's u = √(θ / (π/2)).
pub fn theta2u(theta: f64) -> f64 {
    (theta / FRAC_PI_2).max(0.0).sqrt()
}

/// u to θ = u² π/2.
pub fn u2theta(u: f64) -> f64 {
    u * u * FRAC_PI_2
}

/// φ ∈ [−π, π] to u = (φ + π) / 2π.
pub fn phi2u(phi: f64) -> f64 {
    (phi + PI) / (2.0 * PI)
}

/// u to φ = (2u − 1) π.
pub fn u2phi(u: f64) -> f64 {
    (2.0 * u - 1.0) * PI
}

/// The polar angle, robust near the pole: 2 asin(|d − z| / 2).
pub(crate) fn elevation(d: DVec3) -> f64 {
    2.0 * (0.5 * (d - DVec3::Z).length()).clamp(-1.0, 1.0).asin()
}

/// a with the sign flipped unless b < 0 (drjit's `mulsign_neg`).
fn mulsign_neg(a: f64, b: f64) -> f64 {
    if b >= 0.0 { -a } else { a }
}

/// `d` with its x and y signs flipped as the fold of `wi` flips them (an involution: the same
/// call undoes it).
fn fold_like(d: DVec3, wi: DVec3, reduction: i32) -> DVec3 {
    if reduction < 2 {
        return d;
    }
    let sy = wi.y;
    let sx = if reduction == 4 { wi.x } else { sy };
    DVec3::new(mulsign_neg(d.x, sx), mulsign_neg(d.y, sy), d.z)
}

impl RglBsdf {
    /// Reads a `.bsdf` file.
    pub fn open(path: &Path) -> Result<Self, BrdfError> {
        Self::from_bytes(
            path,
            crate::io::input::read(path, crate::io::input::Cap::BSDF)?,
        )
    }

    /// Parses the bytes of the `.bsdf` file at `path` (named in errors; its stem names the
    /// material).
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, BrdfError> {
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Self::parse(&name, bytes).map_err(|problem| BrdfError::Bsdf {
            path: path.to_owned(),
            problem,
        })
    }

    /// Parses the bytes of a `.bsdf` file; `name` names the material.
    pub fn parse(name: &str, bytes: Vec<u8>) -> Result<Self, String> {
        let tf = TensorFile::parse(bytes)?;
        let vector = |field: &str| -> Result<Vec<f64>, String> {
            let (v, shape) = tf.floats(field)?;
            if shape.len() != 1 || v.is_empty() {
                return Err(format!("`{field}` has shape {shape:?}, not [n]"));
            }
            Ok(v)
        };
        let theta_i = vector("theta_i")?;
        let phi_i = vector("phi_i")?;
        let (nphi, ntheta) = (phi_i.len(), theta_i.len());
        let params = vec![phi_i.clone(), theta_i.clone()];
        let grid = |field: &str| -> Result<Warp2D, String> {
            let (v, shape) = tf.floats(field)?;
            if shape.len() != 2 {
                return Err(format!(
                    "`{field}` has shape {shape:?}, not [rows, columns]"
                ));
            }
            Warp2D::interpolant([shape[1], shape[0]], &v, vec![])
                .map_err(|e| format!("`{field}`: {e}"))
        };
        let ndf = grid("ndf")?;
        let sigma = grid("sigma")?;
        let sliced = |field: &str, v: &[f64], shape: &[usize]| -> Result<Warp2D, String> {
            if shape.len() != 4 || shape[0] != nphi || shape[1] != ntheta {
                return Err(format!(
                    "`{field}` has shape {shape:?}, not [{nphi}, {ntheta}, rows, columns]"
                ));
            }
            Warp2D::distribution([shape[3], shape[2]], v, params.clone())
                .map_err(|e| format!("`{field}`: {e}"))
        };
        let (v, shape) = tf.floats("vndf")?;
        let vndf = sliced("vndf", &v, shape)?;
        let (v, shape) = tf.floats("luminance")?;
        let luminance = sliced("luminance", &v, shape)?;
        let [n1, n0] = luminance.size();
        if n0 != n1 {
            return Err(format!("`luminance` is {n0} × {n1}, not square"));
        }
        // The data, as three RGB planes per slice.
        let spectral = tf.field("rgb").is_none();
        let (data, shape, to_rgb) = if spectral {
            let wavelengths = vector("wavelengths").map_err(|e| {
                if tf.field("wavelengths").is_none() && tf.field("spectra").is_none() {
                    "neither `rgb` nor `spectra` + `wavelengths`".to_string()
                } else {
                    e
                }
            })?;
            let m = SpectrumToRgb::new(&wavelengths).map_err(|e| format!("`wavelengths`: {e}"))?;
            let (v, shape) = tf.floats("spectra")?;
            (v, shape.to_vec(), Some(m))
        } else {
            let (v, shape) = tf.floats("rgb")?;
            (v, shape.to_vec(), None)
        };
        let field = if spectral { "spectra" } else { "rgb" };
        let channels = to_rgb.as_ref().map_or(3, SpectrumToRgb::len);
        if shape.len() != 5 || shape[..3] != [nphi, ntheta, channels] || shape[3..] != [n0, n0] {
            return Err(format!(
                "`{field}` has shape {shape:?}, not [{nphi}, {ntheta}, {channels}, {n0}, {n0}] \
                 like `luminance`"
            ));
        }
        let plane = n0 * n0;
        let rgb_planes: [Vec<f64>; 3] = std::array::from_fn(|c| {
            let mut out = Vec::with_capacity(nphi * ntheta * plane);
            for slice in 0..nphi * ntheta {
                let base = slice * channels * plane;
                for p in 0..plane {
                    out.push(match &to_rgb {
                        Some(m) => m.rgb(|k| data[base + k * plane + p])[c],
                        None => data[base + c * plane + p],
                    });
                }
            }
            out
        });
        let mut rgb = Vec::with_capacity(3);
        for plane in &rgb_planes {
            rgb.push(
                Warp2D::interpolant([n0, n0], plane, params.clone())
                    .map_err(|e| format!("`{field}`: {e}"))?,
            );
        }
        let jacobian = tf.u8s("jacobian")?;
        if jacobian.len() != 1 {
            return Err(format!("`jacobian` holds {} bytes, not 1", jacobian.len()));
        }
        check_values(&tf, field, &data, jacobian[0] != 0)?;
        let description = String::from_utf8_lossy(tf.u8s("description")?).into_owned();
        let isotropic = nphi <= 2;
        let reduction = if isotropic {
            1
        } else {
            let span = phi_i[nphi - 1] - phi_i[0];
            let k = (2.0 * PI / span).round();
            if ![1.0, 2.0, 4.0].contains(&k) {
                return Err(format!("`phi_i` spans {span} rad, not 2π, π or π/2"));
            }
            k as i32
        };
        Ok(RglBsdf {
            name: name.to_owned(),
            description,
            isotropic,
            jacobian: jacobian[0] != 0,
            reduction,
            ndf,
            sigma,
            vndf,
            luminance,
            rgb: rgb.try_into().unwrap(),
            spectral,
        })
    }

    /// The file's description text.
    pub fn description(&self) -> &str {
        &self.description
    }

    /// Whether the file held spectra (converted to RGB as read).
    pub fn is_spectral(&self) -> bool {
        self.spectral
    }

    /// Whether the data holds f cos θo · 4σ / D (the `jacobian` field) rather than f cos θo.
    pub fn has_jacobian(&self) -> bool {
        self.jacobian
    }

    /// The symmetry fold of an anisotropic file whose `phi_i` spans 2π / k: k = 2 or 4, else 1.
    pub fn reduction(&self) -> i32 {
        self.reduction
    }

    /// D(m) on u = (√(θ / (π/2)), (φ + π) / 2π): an interpolant without parameters.
    pub fn ndf(&self) -> &Warp2D {
        &self.ndf
    }

    /// The projected area σ(ωi) on the same u as [`RglBsdf::ndf`]: an interpolant.
    pub fn sigma(&self) -> &Warp2D {
        &self.sigma
    }

    /// The visible normals over u(m), a distribution with parameters (φi, θi).
    pub fn vndf(&self) -> &Warp2D {
        &self.vndf
    }

    /// The sampling density over the sample space, a distribution with parameters (φi, θi).
    pub fn luminance(&self) -> &Warp2D {
        &self.luminance
    }

    /// The red, green and blue data over the sample space, interpolants with parameters
    /// (φi, θi) (already Rec.709 when the file was spectral).
    pub fn rgb(&self) -> &[Warp2D; 3] {
        &self.rgb
    }

    /// The density of the format's importance sampling at (ωi, ωo), solid-angle measure:
    /// luminance(s) · vndf(u(m)) / (2π² u sin θm · 4 ⟨ωi, m⟩), as the format's readers compute
    /// it (`pdf()` of measured.cpp). Zero below the horizon.
    pub fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let q = self.query(wi, wo);
        let (sample, vndf_pdf) = self.vndf.invert(q.u_m, &q.params);
        let lum = self.luminance.eval(sample, &q.params);
        let jacobian =
            (2.0 * PI * PI * q.u_m[0] * q.m.truncate().length()).max(1e-6) * 4.0 * q.wi.dot(q.m);
        vndf_pdf * lum / jacobian
    }

    /// The folded directions and the coordinates every lookup of (ωi, ωo) takes.
    fn query(&self, wi: DVec3, wo: DVec3) -> Query {
        // Both folded by wi's signs: wi lands in the quadrant (or half) the file holds.
        let (wi, wo) = (
            fold_like(wi, wi, self.reduction),
            fold_like(wo, wi, self.reduction),
        );
        let m = (wi + wo).normalize();
        let (theta_i, phi_i) = (elevation(wi), wi.y.atan2(wi.x));
        let (theta_m, phi_m) = (elevation(m), m.y.atan2(m.x));
        let phi = if self.isotropic { phi_m - phi_i } else { phi_m };
        let mut u_m = [theta2u(theta_m), phi2u(phi)];
        u_m[1] -= u_m[1].floor();
        Query {
            wi,
            m,
            u_wi: [theta2u(theta_i), phi2u(phi_i)],
            u_m,
            params: [phi_i, theta_i],
        }
    }
}

/// Refuses the values that pass the shapes and finiteness checks of [`RglBsdf::parse`] but
/// make no material: data (`rgb` or `spectra`) with no positive mass, a negated or zero table
/// that reads as black or as nothing; with the Jacobian (f cos θo = data · D / 4σ), an `ndf`
/// with no positive mass, or a projected area `sigma` that is not positive somewhere, where
/// f cos θo would be infinite (and is missing in [`RglBsdf::eval`]). A measured file's few
/// negative values (noise, colours out of gamut) are kept: evaluation clips them at zero, as
/// brdf-loader does with `POWITACQ_CLIP_RGB`; Mitsuba 3's `measured` plugin reads any values.
fn check_values(tf: &TensorFile, field: &str, data: &[f64], jacobian: bool) -> Result<(), String> {
    // f cos θo is data (times D / 4σ): no value past what the fit's grid takes ([`MAX_X`]),
    // which the renderer, reading the file without the fit's grid, would turn into infinities.
    let bounded = |field: &str, v: &[f64]| match v.iter().position(|x| x.abs() > f64::from(MAX_X)) {
        None => Ok(()),
        Some(i) => Err(format!(
            "`{field}` holds {:.3e} at {i}: past {MAX_X:e}, the largest f cos θ a source may give",
            v[i]
        )),
    };
    bounded(field, data)?;
    let mass = |field: &str, v: &[f64]| {
        let sum: f64 = v.iter().sum();
        if sum > 0.0 {
            return Ok(());
        }
        let negative = v.iter().filter(|&&x| x < 0.0).count();
        Err(format!(
            "`{field}` has no positive mass: its {} values sum to {sum:e} ({negative} negative)",
            v.len()
        ))
    };
    mass(field, data)?;
    if !jacobian {
        return Ok(());
    }
    let ndf = tf.floats("ndf")?.0;
    bounded("ndf", &ndf)?;
    mass("ndf", &ndf)?;
    let (sigma, shape) = tf.floats("sigma")?;
    match sigma.iter().position(|&v| !(v > 0.0)) {
        None => Ok(()),
        Some(at) => Err(format!(
            "`sigma` is {:e} at row {}, column {}: a projected area is positive (the data's \
             Jacobian D / 4σ divides by it)",
            sigma[at],
            at / shape[1],
            at % shape[1]
        )),
    }
}

/// One evaluation's coordinates.
struct Query {
    wi: DVec3,
    m: DVec3,
    u_wi: [f64; 2],
    u_m: [f64; 2],
    params: [f64; 2],
}

impl Brdf for RglBsdf {
    fn name(&self) -> &str {
        &self.name
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Option<Rgb> {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        let q = self.query(wi, wo);
        let (sample, _) = self.vndf.invert(q.u_m, &q.params);
        // The data holds f cos θo (times 4σ / D with the Jacobian); the fold keeps θo.
        let scale = if self.jacobian {
            let sigma = self.sigma.eval(q.u_wi, &[]);
            if !(sigma > 0.0) {
                return None;
            }
            self.ndf.eval(q.u_m, &[]) / (4.0 * sigma)
        } else {
            1.0
        } / wo.z;
        Some(std::array::from_fn(|c| {
            (self.rgb[c].eval(sample, &q.params) * scale).max(0.0)
        }))
    }

    fn is_isotropic(&self) -> bool {
        self.isotropic
    }
}
