//! The fitter on the GPU: the power iteration's kernel–vector product, its normalisation and
//! the D / G1 table integrals (`shaders/fit/kernel.wgsl`, `normalise_reduce.wgsl`, `normalise_rescale.wgsl`), and the passes over
//! the whole MERL grid, its samples uploaded once per source: the Fresnel average
//! (`shaders/fit/fresnel.wgsl`) and the error metric (`shaders/fit/error.wgsl`). f32
//! throughout; the CPU f64 path is the reference the tests compare against.

mod error_metric;
mod fresnel_average;
mod grid;
mod power_iteration;

pub use error_metric::ErrorMetric;
pub use fresnel_average::FresnelAverage;
pub use grid::{GpuGrid, GpuSamples};
pub use power_iteration::PowerIteration;

use crate::error::FitError;
use crate::metric::grid::GridSamples;
use bytemuck::{Pod, Zeroable};
use facet_gpu::{Gpu, GpuError};
use std::sync::OnceLock;

/// A node or query of the power iteration (WGSL `Node` in `fit/node.inc.wgsl`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuNode {
    pub x: f32,
    pub y: f32,
    pub z: f32,
    pub row_scale: f32,
    pub col_weight: f32,
    pub norm_weight: f32,
    pub pad0: f32,
    pub pad1: f32,
}

/// Iteration state (WGSL `State`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuState {
    pub iteration: u32,
    pub lambda: f32,
    pub pad0: u32,
    pub pad1: u32,
}

/// The GPU pipelines of the fitter, built once and reused for every material.
pub struct GpuFitter<'g> {
    /// The GPU the pipelines were built on.
    pub gpu: &'g Gpu,
    /// The power iteration and the table integrals.
    pub power: PowerIteration,
    /// The Fresnel average.
    pub fresnel: FresnelAverage,
    /// The error metric.
    pub error: ErrorMetric,
    /// The MERL grid's geometry, uploaded on the first isotropic fit.
    grid: OnceLock<GpuGrid>,
}

impl<'g> GpuFitter<'g> {
    /// Builds every pipeline of the fitter on `gpu`.
    pub fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let (power, fresnel, error) = gpu.scoped(|| {
            Ok::<_, GpuError>((
                PowerIteration::new(&gpu.device)?,
                FresnelAverage::new(&gpu.device)?,
                ErrorMetric::new(&gpu.device)?,
            ))
        })??;
        Ok(GpuFitter {
            gpu,
            power,
            fresnel,
            error,
            grid: OnceLock::new(),
        })
    }

    /// Uploads an isotropic source's samples for the passes over the grid, and the grid's
    /// geometry with the first.
    pub fn upload(&self, set: &GridSamples) -> Result<GpuSamples, GpuError> {
        let grid = match self.grid.get() {
            Some(g) => g,
            None => {
                let g = GpuGrid::new(self.gpu)?;
                self.grid.get_or_init(|| g)
            }
        };
        GpuSamples::upload(self.gpu, grid, set)
    }
}

pub(crate) fn gpu_error(name: &str, e: GpuError) -> FitError {
    FitError::Gpu {
        name: name.to_owned(),
        source: Box::new(e),
    }
}
