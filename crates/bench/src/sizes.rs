//! The sizes of one benchmark mode: how many runs, how large the scenes and images.

/// What one mode of `facet bench` measures on; plain data with a `const` preset per mode.
#[derive(Clone, Copy, Debug)]
pub struct Sizes {
    /// Timed runs after one warm-up (1: no warm-up).
    pub runs: usize,
    /// The same for the anisotropic extraction, whose default size is the slowest case.
    pub aniso_runs: usize,
    /// The isotropic fits' extraction resolution.
    pub fit_resolution: usize,
    /// The anisotropic extraction's θ × φ resolution.
    pub aniso: (usize, usize),
    /// The procedural scenes' triangle counts (trace section).
    pub triangles: &'static [usize],
    /// Rays a dispatch (trace section).
    pub rays: u32,
    /// Width, height and spp of the integrator's demo renders.
    pub render: (u32, u32, u32),
    /// Iterations before the per-stage profile.
    pub stage_warm: u32,
    /// Side and frames of the viewer's preview path.
    pub viewer: (u32, u32),
    /// Side and spp of the noise renders.
    pub noise: (u32, u32),
    /// The shard processes' size (None: the demo's) and samples per shard.
    pub shard: (Option<(u32, u32)>, &'static [u32]),
    /// Side and spp of the light-selection renders, and emissive triangles of the tree builds.
    pub lights: (u32, u32, &'static [usize]),
    /// The DPF pyramids at the preview's size rather than the standard one.
    pub dpf_preview: bool,
}

impl Sizes {
    /// Tiny sizes: what the test suite runs.
    pub const SMOKE: Sizes = Sizes {
        runs: 1,
        aniso_runs: 1,
        fit_resolution: 24,
        aniso: (8, 16),
        triangles: &[1_000],
        rays: 1 << 12,
        render: (64, 36, 1),
        stage_warm: 2,
        viewer: (64, 3),
        noise: (32, 2),
        shard: (Some((64, 36)), &[1, 2]),
        lights: (32, 2, &[1_000]),
        dpf_preview: true,
    };

    /// Within 5 minutes on lavapipe.
    pub const QUICK: Sizes = Sizes {
        runs: 5,
        aniso_runs: 3,
        fit_resolution: 90,
        aniso: (32, 64),
        triangles: &[10_000, 100_000, 1_000_000],
        rays: 1 << 17,
        render: (480, 270, 2),
        stage_warm: 4,
        viewer: (512, 5),
        noise: (128, 16),
        shard: (None, &[1, 4, 16]),
        lights: (128, 16, &[10_000, 1_000_000]),
        dpf_preview: false,
    };

    /// The full sizes, for a GPU.
    pub const DEFAULT: Sizes = Sizes {
        runs: 5,
        aniso_runs: 3,
        fit_resolution: 90,
        aniso: (128, 256),
        triangles: &[10_000, 100_000, 1_000_000],
        rays: 1 << 21,
        render: (1920, 1080, 8),
        stage_warm: 6,
        viewer: (512, 60),
        noise: (256, 64),
        shard: (None, &[1, 16, 64, 256]),
        lights: (256, 64, &[10_000, 1_000_000]),
        dpf_preview: false,
    };

    /// The full sizes and 10^7 triangles.
    pub const FULL: Sizes = Sizes {
        triangles: &[10_000, 100_000, 1_000_000, 10_000_000],
        ..Sizes::DEFAULT
    };

    /// Every preset, smallest first.
    pub const ALL: [Sizes; 4] = [Sizes::SMOKE, Sizes::QUICK, Sizes::DEFAULT, Sizes::FULL];
}

/// Triangle counts from the environment variable `var` (`1e4,1e5`), or `default`: the criterion
/// benches' scene sizes.
pub fn triangles_from_env(var: &str, default: &[usize]) -> Vec<usize> {
    std::env::var(var)
        .ok()
        .map(|s| {
            s.split(',')
                .map(|x| {
                    x.trim()
                        .parse::<f64>()
                        .unwrap_or_else(|_| panic!("{var}: e.g. 1e4,1e5, not {s}"))
                        as usize
                })
                .collect()
        })
        .unwrap_or_else(|| default.to_vec())
}
