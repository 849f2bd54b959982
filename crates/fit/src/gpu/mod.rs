//! The fitter on the GPU: the power iteration's kernel–vector product, its normalisation and
//! the D / G1 table integrals (`shaders/fit/kernel.wgsl`, `normalise.wgsl`), and the Fresnel
//! average over the MERL grid (`shaders/fit/fresnel.wgsl`). f32 throughout; the CPU f64 path is
//! the reference the tests compare against.

mod fresnel_average;
mod power_iteration;

pub use fresnel_average::{FresnelAverage, GpuSamples};
pub use power_iteration::PowerIteration;

use crate::error::FitError;
use bytemuck::{Pod, Zeroable};
use facet_gpu::{Gpu, GpuError};

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

/// One MERL-grid sample for the Fresnel average (WGSL `Sample` in `fit/fresnel.wgsl`).
#[allow(missing_docs)] // fields: those of the WGSL struct it mirrors, by name and in order
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuSample {
    pub i: u32,
    pub gi: f32,
    pub go: f32,
    pub inv_cos_i: f32,
    pub inv_cos_o: f32,
    pub corr: f32,
    pub pad: [f32; 2],
}

/// The GPU pipelines of the fitter, built once and reused for every material.
pub struct GpuFitter<'g> {
    /// The GPU the pipelines were built on.
    pub gpu: &'g Gpu,
    /// The power iteration and the table integrals.
    pub power: PowerIteration,
    /// The Fresnel average.
    pub fresnel: FresnelAverage,
}

impl<'g> GpuFitter<'g> {
    /// Builds every pipeline of the fitter on `gpu`.
    pub fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let (power, fresnel) = gpu.scoped(|| {
            Ok::<_, GpuError>((
                PowerIteration::new(&gpu.device)?,
                FresnelAverage::new(&gpu.device)?,
            ))
        })??;
        Ok(GpuFitter {
            gpu,
            power,
            fresnel,
        })
    }
}

pub(crate) fn gpu_error(name: &str, e: GpuError) -> FitError {
    FitError::Gpu {
        name: name.to_owned(),
        source: e,
    }
}
