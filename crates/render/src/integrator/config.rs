//! Settings of a render, in two parts: the image ([`ImageConfig`]: its size and the paths in
//! flight, fixed for the life of a [`Wavefront`](crate::Wavefront), which holds them) and the
//! sampling ([`SampleConfig`]: what each call to
//! [`Integrator::render_more`](crate::Integrator::render_more) does). A wavefront cannot be
//! asked to render another size than its own: the size is never passed again.

pub use crate::layout::tags::{NdfSampling, Sequence, Strategy};

/// The image of a [`Wavefront`](crate::Wavefront): fixed when it is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageConfig {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// Paths in flight (slots), clamped to 64 … min(pixels, 2^24); the image is rendered in
    /// tiles of this many pixels.
    pub wavefront: u32,
}

impl ImageConfig {
    /// 1280 × 720, 2^20 paths in flight.
    pub const fn standard() -> Self {
        ImageConfig {
            width: 1280,
            height: 720,
            wavefront: 1 << 20,
        }
    }

    /// 320 × 180, 2^16 paths in flight: tests and quick looks.
    pub const fn preview() -> Self {
        ImageConfig {
            width: 320,
            height: 180,
            wavefront: 1 << 16,
        }
    }
}

/// How samples are taken: the part of a render's settings that may change between calls on
/// one [`Wavefront`](crate::Wavefront).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleConfig {
    /// Samples per pixel.
    pub spp: u32,
    /// Bounces after the camera ray (1: direct lighting only).
    pub max_depth: u32,
    /// Seed of the per-pixel random numbers.
    pub seed: u32,
    /// Depth from which Russian roulette plays.
    pub rr_depth: u32,
    /// Samples per pixel taken per pass over the image (progress and time-limit granularity).
    pub spp_per_pass: u32,
    /// Stop after the pass during which this many seconds have passed.
    pub time_limit: Option<f64>,
    /// Iterations submitted between checks for completion.
    pub iterations_per_check: u32,
    /// How direct lighting is sampled.
    pub strategy: Strategy,
    /// How the normals of microfacet lobes are sampled.
    pub ndf_sampling: NdfSampling,
    /// Where the random numbers come from (independent, or stratified Sobol points).
    pub sequence: Sequence,
}

impl SampleConfig {
    /// 64 spp, depth 5.
    pub const fn standard() -> Self {
        SampleConfig {
            spp: 64,
            ..SampleConfig::preview()
        }
    }

    /// 8 spp, depth 5: tests and quick looks.
    pub const fn preview() -> Self {
        SampleConfig {
            spp: 8,
            max_depth: 5,
            seed: 0,
            rr_depth: 3,
            spp_per_pass: 4,
            time_limit: None,
            iterations_per_check: 8,
            strategy: Strategy::Mis,
            ndf_sampling: NdfSampling::Visible,
            sequence: Sequence::Random,
        }
    }
}

/// Settings of a one-shot render ([`Integrator::render`](crate::Integrator::render)): the image
/// of the wavefront it makes and the samples it takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderConfig {
    /// The image.
    pub image: ImageConfig,
    /// The samples.
    pub sampling: SampleConfig,
}

impl RenderConfig {
    /// 1280 × 720, 64 spp, depth 5.
    pub const fn standard() -> Self {
        RenderConfig {
            image: ImageConfig::standard(),
            sampling: SampleConfig::standard(),
        }
    }

    /// 320 × 180, 8 spp: tests and quick looks.
    pub const fn preview() -> Self {
        RenderConfig {
            image: ImageConfig::preview(),
            sampling: SampleConfig::preview(),
        }
    }
}
