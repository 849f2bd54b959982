//! Where a fit's extraction and its passes over the whole grid run: the f64 CPU reference, or a
//! GPU fitter with the source's samples uploaded once for every model of the fit.
//!
//! The parameter searches, the F and ρd solves and the refinement run on subsets of the grid
//! and always on the CPU; only what [`Evaluator`] offers moves to the GPU.

use crate::error::FitError;
use crate::extract::{CpuSolver, ExtractConfig, Extraction, Solver, extract_with};
#[cfg(feature = "gpu")]
use crate::gpu::{GpuFitter, GpuSamples, gpu_error};
use crate::metric::grid::{GridModel, GridSamples};
use crate::model::brdf::Brdf;
use crate::model::rgb::Rgb;

/// Where a fit runs, as the caller chooses it. (With the `gpu` feature only.)
#[cfg(feature = "gpu")]
#[derive(Clone, Copy)]
pub enum Backend<'a, 'g> {
    /// The f64 reference path.
    Cpu,
    /// WGSL compute passes on the fitter's adapter (f32).
    Gpu(&'a GpuFitter<'g>),
}

/// The backend of one fit: the CPU, or the GPU fitter with the source's samples once they are
/// uploaded ([`Evaluator::upload`]).
pub(crate) enum Evaluator<'a> {
    /// The f64 reference path.
    Cpu,
    /// WGSL compute passes; `samples` is `None` until uploaded, and stays `None` for a set the
    /// GPU passes do not take (an anisotropic source).
    #[cfg(feature = "gpu")]
    Gpu {
        /// The fitter's pipelines.
        fitter: &'a GpuFitter<'a>,
        /// The source's samples on the GPU.
        samples: Option<GpuSamples>,
    },
    /// Keeps the lifetime without the `gpu` feature.
    #[cfg(not(feature = "gpu"))]
    #[allow(dead_code)]
    Never(std::convert::Infallible, std::marker::PhantomData<&'a ()>),
}

impl<'a> Evaluator<'a> {
    /// The evaluator of a backend, before any upload.
    #[cfg(feature = "gpu")]
    pub(crate) fn new(backend: Backend<'a, '_>) -> Self {
        match backend {
            Backend::Cpu => Evaluator::Cpu,
            Backend::Gpu(fitter) => Evaluator::Gpu {
                fitter,
                samples: None,
            },
        }
    }

    /// Whether the passes over the grid run on the GPU.
    pub(crate) fn is_gpu(&self) -> bool {
        !matches!(self, Evaluator::Cpu)
    }

    /// The power iteration's solver.
    fn solver(&self) -> &dyn Solver {
        match self {
            Evaluator::Cpu => &CpuSolver,
            #[cfg(feature = "gpu")]
            Evaluator::Gpu { fitter, .. } => *fitter,
            #[cfg(not(feature = "gpu"))]
            Evaluator::Never(never, _) => match *never {},
        }
    }

    /// The backend's name, recorded in the fit JSON.
    pub(crate) fn name(&self) -> String {
        self.solver().name()
    }

    /// The power iteration on `src`'s backscattering slice.
    pub(crate) fn extract(
        &self,
        src: &dyn Brdf,
        cfg: &ExtractConfig,
        anisotropic: bool,
    ) -> Result<Extraction, FitError> {
        extract_with(src, cfg, anisotropic, self.solver())
    }

    /// Uploads the samples of an isotropic set (one azimuth rotation) for the passes over the
    /// whole grid; other sets stay on the CPU. Nothing to do on the CPU.
    pub(crate) fn upload(&mut self, set: &GridSamples, name: &str) -> Result<(), FitError> {
        #[cfg(feature = "gpu")]
        if let Evaluator::Gpu { fitter, samples } = self
            && set.rotations.len() == 1
        {
            *samples = Some(fitter.upload(set).map_err(|e| gpu_error(name, e))?);
        }
        let _ = (set, name);
        Ok(())
    }

    /// F per θd bin averaged over `set` for `m`'s D and G ([`GridModel::fresnel_average`]);
    /// on the GPU when `set`'s samples are uploaded and `m` is isotropic. `set` must be the
    /// uploaded set.
    pub(crate) fn average(
        &self,
        m: &GridModel,
        set: &GridSamples,
        name: &str,
    ) -> Result<Vec<Rgb>, FitError> {
        #[cfg(feature = "gpu")]
        if let (
            Evaluator::Gpu {
                fitter,
                samples: Some(samples),
            },
            Some(tables),
        ) = (self, &m.tables)
        {
            return fitter
                .fresnel
                .average(fitter.gpu, samples, set, tables)
                .map_err(|e| gpu_error(name, e));
        }
        let _ = name;
        Ok(m.fresnel_average(set))
    }

    /// The error metric of `m` on `set` ([`GridModel::error`]), on the GPU as
    /// [`Evaluator::average`] is.
    pub(crate) fn error(
        &self,
        m: &GridModel,
        set: &GridSamples,
        name: &str,
    ) -> Result<f64, FitError> {
        #[cfg(feature = "gpu")]
        if let (
            Evaluator::Gpu {
                fitter,
                samples: Some(samples),
            },
            Some(tables),
        ) = (self, &m.tables)
        {
            return fitter
                .error
                .mean(fitter.gpu, samples, tables)
                .map_err(|e| gpu_error(name, e));
        }
        let _ = name;
        Ok(m.error(set))
    }
}
