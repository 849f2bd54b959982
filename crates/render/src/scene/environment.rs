//! Distant lighting: a constant colour or an equirectangular HDR map with importance sampling.
//!
//! Equirectangular convention (Y up): a unit direction d ↔ (u, v) ∈ [0, 1)² by
//! φ = atan2(d.z, d.x) wrapped to [0, 2π), u = φ / 2π, θ = acos(d.y), v = θ / π;
//! pixel (x, y) = (⌊u·w⌋, ⌊v·h⌋), row 0 is straight up (θ = 0);
//! inverse d = (sin θ cos φ, cos θ, sin θ sin φ).
//!
//! Sampling is piecewise constant per pixel (pbrt-v3 §14.2.4, "Infinite Area Lights"): pixel
//! weight w_xy = luminance(L_xy) · sin θ_y (θ_y at the row centre, luminance = 0.2126 R +
//! 0.7152 G + 0.0722 B; if every weight is 0, sin θ_y alone), a marginal CDF over rows and a
//! conditional CDF per row. A pixel is chosen with probability p_xy = w_xy / Σ w and a point is
//! uniform in its (u, v) cell, so the (u, v) density is p_xy · w · h, and with
//! dω = 2π² sin θ du dv the solid-angle density is `p_xy · w · h / (2π² sin θ)`.

use crate::error::RenderError;
use crate::scene::gltf_file::guard;
use facet_brdf::io::input::{self, Cap};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What a ray that leaves the scene sees.
#[derive(Clone, Debug)]
pub enum Environment {
    /// The same radiance from every direction.
    Constant(Vec3),
    /// An equirectangular radiance map.
    Map(Arc<EnvironmentMap>),
}

impl Environment {
    /// Radiance arriving from direction `d` (unit, pointing away from the scene).
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match self {
            Environment::Constant(c) => *c,
            Environment::Map(m) => m.lookup(d),
        }
    }
}

/// Direction → (u, v): φ = atan2(d.z, d.x) ∈ [0, 2π), u = φ / 2π, v = acos(d.y) / π.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let mut phi = d.z.atan2(d.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    // θ = acos(d.y), computed as atan2(√(x² + z²), y): acos loses precision near the poles.
    let theta = d.x.hypot(d.z).atan2(d.y);
    // atan2 can return exactly π after rounding of a tiny negative angle + 2π: keep u < 1.
    Vec2::new((phi / (2.0 * PI)).min(1.0 - f32::EPSILON / 2.0), theta / PI)
}

/// (u, v) → direction: φ = 2π u, θ = π v, d = (sin θ cos φ, cos θ, sin θ sin φ).
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (phi, theta) = (2.0 * PI * uv.x, PI * uv.y);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * cp, ct, st * sp)
}

/// The largest radiance a texel may hold: no sky comes near (the sun's disc is ~2·10⁷
/// W m⁻² sr⁻¹), and 2²⁶ texels of it still sum inside f32 (~7·10²⁷ against 3·10³⁸), so the
/// sampling tables stay finite.
pub const MAX_ENV_RADIANCE: f32 = 1e20;

/// The widest or tallest environment map read: 16384 pixels.
pub const MAX_ENV_SIDE: u64 = 16384;
/// The most pixels an environment map may have: 2²⁶ (a 11585² square, 16384 × 4096); its
/// texels and sampling tables then take about 1.3 GiB.
pub const MAX_ENV_PIXELS: u64 = 1 << 26;

/// Refuses a `width × height` map over [`MAX_ENV_SIDE`] or [`MAX_ENV_PIXELS`].
fn check_env_size(width: u64, height: u64) -> Result<(), String> {
    if width > MAX_ENV_SIDE || height > MAX_ENV_SIDE {
        return Err(format!(
            "{width} × {height} pixels: a side is over the {MAX_ENV_SIDE} an environment map may have"
        ));
    }
    if width * height > MAX_ENV_PIXELS {
        return Err(format!(
            "{width} × {height} pixels is more than the {MAX_ENV_PIXELS} an environment map may have"
        ));
    }
    Ok(())
}

/// Rec. 709 luminance ([`facet_brdf::model::rgb::LUMINANCE`]) in f32.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::from(
        facet_brdf::model::rgb::LUMINANCE.map(|w| w as f32),
    ))
}

/// An equirectangular radiance map with its sampling distribution.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    /// The file it came from (or a label).
    pub path: PathBuf,
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Linear RGB radiance, row-major, row 0 straight up.
    pub texels: Vec<Vec3>,
    /// `height + 1` entries, 0 … 1: the CDF over rows of the row sums of w_xy.
    pub marginal_cdf: Vec<f32>,
    /// `height × (width + 1)` entries; row y is `[y·(w+1) .. (y+1)·(w+1))`, 0 … 1.
    pub conditional_cdf: Vec<f32>,
    /// Σ w_xy over every pixel.
    pub total: f32,
}

impl EnvironmentMap {
    /// Reads the first RGB(A) layer of an OpenEXR file (alpha ignored). Texels that are
    /// negative or not finite become 0; the returned strings say how many. The file is read
    /// through [`facet_brdf::io::input`] ([`Cap::EXR`]), then [`Self::from_exr_bytes`].
    pub fn load(path: &Path) -> Result<(EnvironmentMap, Vec<String>), RenderError> {
        let bytes = input::read(path, Cap::EXR)?;
        Self::from_exr_bytes(path, &bytes)
    }

    /// [`Self::load`] of an OpenEXR file already in memory (`path` names it in messages).
    ///
    /// The header is read first, alone: a layer wider or taller than [`MAX_ENV_SIDE`] or with
    /// more than [`MAX_ENV_PIXELS`] pixels (data or display window), or more chunks than the
    /// file has room for in its offset tables, is refused before any pixel buffer exists. A panic of the decoder on a malformed file is caught and reported as an
    /// error naming the file.
    pub fn from_exr_bytes(
        path: &Path,
        bytes: &[u8],
    ) -> Result<(EnvironmentMap, Vec<String>), RenderError> {
        let not_exr = |e: exr::error::Error| {
            RenderError::input(path, format!("not a readable RGB OpenEXR image: {e}"))
        };
        let meta = guard(path, "the OpenEXR image", || {
            exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
                .map_err(not_exr)
        })?;
        for (i, header) in meta.headers.iter().enumerate() {
            let display = header.shared_attributes.display_window.size;
            for (window, size) in [
                ("data window", header.layer_size),
                ("display window", display),
            ] {
                check_env_size(size.0 as u64, size.1 as u64)
                    .map_err(|m| RenderError::input(path, format!("layer {i}'s {window}: {m}")))?;
            }
        }
        // Each chunk has an 8-byte entry in the offset table, which the decoder allocates from
        // the header (a 1 × 1 tiling of a large map would be millions of entries in a tiny file).
        let chunks: u64 = meta.headers.iter().map(|h| h.chunk_count as u64).sum();
        if chunks.saturating_mul(8) > bytes.len() as u64 {
            return Err(RenderError::input(
                path,
                format!(
                    "the header declares {chunks} chunks, more than the file's {} bytes can hold",
                    bytes.len()
                ),
            ));
        }
        let image = guard(path, "the OpenEXR image", || {
            use exr::prelude::{ReadChannels as _, ReadLayers as _};
            exr::prelude::read()
                .no_deep_data()
                .largest_resolution_level()
                .rgba_channels(
                    |res, _| (res.width(), vec![Vec3::ZERO; res.width() * res.height()]),
                    |(w, px): &mut (usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                        px[pos.y() * *w + pos.x()] = Vec3::new(r, g, b);
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(std::io::Cursor::new(bytes))
                .map_err(not_exr)
        })?;
        let size = image.layer_data.size;
        let (_, mut texels) = image.layer_data.channel_data.pixels;
        let mut bad = 0usize;
        for t in &mut texels {
            if !(t.is_finite() && t.min_element() >= 0.0) {
                *t = Vec3::ZERO;
                bad += 1;
            }
        }
        let warnings = if bad > 0 {
            vec![format!(
                "{}: {bad} texel(s) negative or not finite, replaced by 0",
                path.display()
            )]
        } else {
            Vec::new()
        };
        let (w, h) = (u32::try_from(size.0), u32::try_from(size.1));
        let (Ok(w), Ok(h)) = (w, h) else {
            return Err(RenderError::input(path, "image too large"));
        };
        Ok((Self::from_texels(path.to_owned(), w, h, texels)?, warnings))
    }

    /// Builds the map and its distribution. Texels must be finite and non-negative, and there
    /// must be `width × height > 0` of them.
    pub fn from_texels(
        path: PathBuf,
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
    ) -> Result<EnvironmentMap, RenderError> {
        let (w, h) = (width as usize, height as usize);
        if w == 0 || h == 0 {
            return Err(RenderError::input(
                path,
                format!("zero-sized map ({w}×{h})"),
            ));
        }
        if texels.len() != w * h {
            return Err(RenderError::input(
                path,
                format!("{} texels for a {w}×{h} map", texels.len()),
            ));
        }
        if let Some(i) = texels.iter().position(|t| {
            !(t.is_finite() && t.min_element() >= 0.0 && t.max_element() <= MAX_ENV_RADIANCE)
        }) {
            return Err(RenderError::input(
                path,
                format!(
                    "texel ({}, {}) is {} (negative, not finite, or above {MAX_ENV_RADIANCE:e})",
                    i % w,
                    i / w,
                    texels[i]
                ),
            ));
        }
        // sin θ_y at the row centre: θ_y = π (y + ½) / h.
        let sin_row: Vec<f32> = (0..h)
            .map(|y| (PI * (y as f32 + 0.5) / h as f32).sin())
            .collect();
        let mut weights: Vec<f32> = texels
            .iter()
            .enumerate()
            .map(|(i, &t)| luminance(t) * sin_row[i / w])
            .collect();
        if !weights.iter().any(|&x| x > 0.0) {
            // A black map: sample the sphere uniformly (w_xy ∝ sin θ_y).
            weights = (0..w * h).map(|i| sin_row[i / w]).collect();
        }
        let mut conditional_cdf = vec![0.0f32; h * (w + 1)];
        let mut row_sums = vec![0.0f64; h];
        for y in 0..h {
            let row = &weights[y * w..(y + 1) * w];
            let cdf = &mut conditional_cdf[y * (w + 1)..(y + 1) * (w + 1)];
            row_sums[y] = cumulative(row.iter().map(|&x| f64::from(x)), cdf);
        }
        let mut marginal_cdf = vec![0.0f32; h + 1];
        let total = cumulative(row_sums.iter().copied(), &mut marginal_cdf);
        Ok(EnvironmentMap {
            path,
            width,
            height,
            texels,
            marginal_cdf,
            conditional_cdf,
            total: total as f32,
        })
    }

    /// The pixel a direction falls in (nearest, no filtering): (⌊u·w⌋, ⌊v·h⌋), clamped.
    pub fn pixel(&self, d: Vec3) -> (usize, usize) {
        let uv = direction_to_uv(d);
        let x = ((uv.x * self.width as f32) as usize).min(self.width as usize - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height as usize - 1);
        (x, y)
    }

    /// Radiance of the pixel `d` falls in.
    pub fn lookup(&self, d: Vec3) -> Vec3 {
        let (x, y) = self.pixel(d);
        self.texels[y * self.width as usize + x]
    }

    /// Discrete probability p_xy of choosing pixel (x, y): the widths of its two CDF cells.
    pub fn pixel_probability(&self, x: usize, y: usize) -> f32 {
        let row = &self.conditional_cdf[y * (self.width as usize + 1)..];
        (self.marginal_cdf[y + 1] - self.marginal_cdf[y]) * (row[x + 1] - row[x])
    }

    /// Solid-angle density of [`Self::sample`] at `d`: `p_xy · w · h / (2π² sin θ)`
    /// (0 at the poles, where sin θ = 0).
    pub fn pdf(&self, d: Vec3) -> f32 {
        let (x, y) = self.pixel(d);
        // sin θ = √(x² + z²), accurate near the poles (unlike √(1 − y²)).
        let sin_theta = d.x.hypot(d.z);
        if !(sin_theta > 0.0) {
            return 0.0;
        }
        let p_xy = self.pixel_probability(x, y);
        p_xy * (self.width as f32 * self.height as f32) / (2.0 * PI * PI * sin_theta)
    }

    /// Importance-samples a direction from `u ∈ [0, 1)²`: returns (direction, solid-angle pdf,
    /// radiance). Row from `u.y` by the marginal CDF, column from `u.x` by that row's CDF, each
    /// with a continuous offset inside its cell.
    ///
    /// The pdf and radiance returned are `pdf(d)` and `lookup(d)` exactly, so that MIS weights
    /// agree whichever strategy produced `d`. (A point within f32 rounding of a pixel edge may
    /// land in the neighbour pixel; that pixel's values are then used, a bias of order 10⁻⁵.)
    /// A pdf of 0 (a pole, or a rounding into a zero-probability pixel) means: discard.
    pub fn sample(&self, u: Vec2) -> (Vec3, f32, Vec3) {
        let (w, h) = (self.width as usize, self.height as usize);
        let (y, fy) = sample_cdf(&self.marginal_cdf, u.y);
        let (x, fx) = sample_cdf(&self.conditional_cdf[y * (w + 1)..(y + 1) * (w + 1)], u.x);
        let d = uv_to_direction(Vec2::new(
            (x as f32 + fx) / w as f32,
            (y as f32 + fy) / h as f32,
        ));
        (d, self.pdf(d), self.lookup(d))
    }
}

/// Fills `cdf` (len n + 1) with the normalised running sum of `values`: cdf[0] = 0, cdf[n] = 1.
/// An all-zero row becomes uniform (cdf[i] = i / n). Returns the sum.
fn cumulative(values: impl Iterator<Item = f64>, cdf: &mut [f32]) -> f64 {
    let n = cdf.len() - 1;
    let mut running = Vec::with_capacity(n + 1);
    running.push(0.0f64);
    for v in values {
        running.push(running[running.len() - 1] + v);
    }
    let sum = running[n];
    for (c, r) in cdf.iter_mut().zip(&running) {
        *c = if sum > 0.0 { (r / sum) as f32 } else { 0.0 };
    }
    if !(sum > 0.0) {
        for (i, c) in cdf.iter_mut().enumerate() {
            *c = i as f32 / n as f32;
        }
    }
    cdf[n] = 1.0;
    sum
}

/// Inverts a piecewise-constant CDF: the cell i with cdf[i] ≤ u < cdf[i+1] (never an empty one)
/// and the offset (u − cdf[i]) / (cdf[i+1] − cdf[i]) ∈ [0, 1).
fn sample_cdf(cdf: &[f32], u: f32) -> (usize, f32) {
    let n = cdf.len() - 1;
    let u = u.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
    // Number of entries ≤ u is ≥ 1 (cdf[0] = 0); the last of them opens a non-empty cell.
    let i = (cdf.partition_point(|&c| c <= u) - 1).min(n - 1);
    let width = cdf[i + 1] - cdf[i];
    let f = if width > 0.0 {
        (u - cdf[i]) / width
    } else {
        0.5
    };
    (i, f.clamp(0.0, 1.0 - f32::EPSILON / 2.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uv_round_trip_and_pixel_rows() {
        for d in [
            Vec3::new(0.3, 0.5, -0.8),
            Vec3::new(-0.9, -0.1, 0.2),
            Vec3::new(0.0, 0.99, 0.1),
        ] {
            let d = d.normalize();
            assert!((uv_to_direction(direction_to_uv(d)) - d).length() < 1e-5);
        }
        // Straight up is row 0, +X is u = 0, +Z is u = ¼.
        assert!(direction_to_uv(Vec3::Y).y < 1e-6);
        assert!((direction_to_uv(Vec3::Z).x - 0.25).abs() < 1e-6);
        assert!(direction_to_uv(Vec3::X).x.abs() < 1e-6);
    }

    #[test]
    fn zero_width_cells_are_never_chosen() {
        let cdf = [0.0, 0.0, 0.5, 0.5, 1.0, 1.0];
        for k in 0..1000 {
            let (i, f) = sample_cdf(&cdf, k as f32 / 1000.0);
            assert!(i == 1 || i == 3, "u = {k}/1000 chose empty cell {i}");
            assert!((0.0..1.0).contains(&f));
        }
    }
}
