//! The closed sets the Rust side and the WGSL stages share — material and light kinds, the
//! environment's kind, the sampling strategy and sequence, the path-state regions and the slot
//! states — written once, here. [`wgsl`] renders them as WGSL constants; the committed
//! `shaders/render/tags.inc.wgsl` is its output (`cargo test -p facet-render --test tags`
//! fails when the two differ; `FACET_REGENERATE=1` rewrites the file) and no other WGSL file
//! may define a constant with one of the prefixes. The `tags!` macro is facet-gpu's
//! ([`facet_gpu::tags`](mod@facet_gpu::tags)).

use facet_gpu::tags;
pub use facet_gpu::tags::TagSet;

tags!(
    /// The material classes (`crate::materials`, one file each), in the order of their
    /// shading queues; glints last, whose materials have a queue each.
    MaterialKind, "MAT_" {
        /// a glTF metallic-roughness material
        Gltf = 0 => "GLTF",
        /// a fit's GGX or Beckmann model
        Analytic = 1 => "ANALYTIC",
        /// a fit's tabulated NDF
        Tabulated = 2 => "TABULATED",
        /// a MERL-grid measurement, sampled by its fit's tabulated model
        Merl = 3 => "MERL",
        /// an RGL `.bsdf` measurement
        Rgl = 4 => "RGL",
        /// a fit's model as glints
        Glint = 5 => "GLINT",
    }
);

tags!(
    /// Light kinds (`Light.kind`).
    LightKind, "LIGHT_" {
        /// KHR_lights_punctual point light
        Point = 0 => "POINT",
        /// KHR_lights_punctual spot light
        Spot = 1 => "SPOT",
        /// KHR_lights_punctual directional light
        Directional = 2 => "DIRECTIONAL",
        /// an emissive triangle
        Triangle = 3 => "TRIANGLE",
        /// the environment (constant or map)
        Environment = 4 => "ENVIRONMENT",
    }
);

tags!(
    /// What a ray that leaves the scene sees (`Frame.env_kind`).
    EnvKind, "ENV_" {
        /// black
        None = 0 => "NONE",
        /// a constant radiance (`Frame.env_color`)
        Constant = 1 => "CONSTANT",
        /// an equirectangular map with its sampling tables
        Map = 2 => "MAP",
    }
);

tags!(
    /// How direct light is estimated (`Frame.strategy`). Every choice converges to the same
    /// image; [`Strategy::Mis`] has the least noise, the others are for checking it.
    Strategy, "STRATEGY_" {
        /// light and BSDF sampling combined by the power heuristic (Veach 1997)
        Mis = 0 => "MIS",
        /// light sampling alone: emission a BSDF ray finds counts only if light sampling cannot
        Light = 1 => "LIGHT",
        /// BSDF sampling alone: only delta lights (point, spot, directional) are sampled
        Bsdf = 2 => "BSDF",
    }
);

// By hand: `tags!` takes doc attributes only on variants.
#[allow(clippy::derivable_impls)]
impl Default for Strategy {
    fn default() -> Self {
        Strategy::Mis
    }
}

tags!(
    /// How microfacet lobes pick their normals (`Frame.ndf_sampling`).
    NdfSampling, "NDF_SAMPLING_" {
        /// the normals visible from ωo (Heitz 2018): the default
        Visible = 0 => "VISIBLE",
        /// D(h) cos θh, the older choice, kept to measure against
        DCos = 1 => "D_COS",
        /// the cosine lobe alone, in the microfacet and measured MERL stages: the reference
        /// that tests compare an importance sampling against
        Cosine = 2 => "COSINE",
    }
);

// By hand: `tags!` takes doc attributes only on variants.
#[allow(clippy::derivable_impls)]
impl Default for NdfSampling {
    fn default() -> Self {
        NdfSampling::Visible
    }
}

tags!(
    /// Where a path's random numbers come from (`Frame.sequence`). Both are unbiased; the
    /// Sobol points stratify each pair of dimensions a bounce uses together, so an image at a
    /// power-of-two spp has less noise.
    Sequence, "SEQUENCE_" {
        /// independent numbers: a PCG hash of (pixel, sample, dimension, seed)
        Random = 0 => "RANDOM",
        /// Owen-scrambled Sobol points, the dimensions a bounce uses together stratified
        /// (Burley 2020): per pixel, the pixel position, the light sample's point and the BSDF
        /// sample's direction each a (0, 2)-sequence, shuffled and scrambled per pixel, seed
        /// and dimension pair; the single dimensions scrambled van der Corput
        Sobol = 1 => "SOBOL",
    }
);

// By hand: `tags!` takes doc attributes only on variants.
#[allow(clippy::derivable_impls)]
impl Default for Sequence {
    fn default() -> Self {
        Sequence::Random
    }
}

tags!(
    /// Regions of the path state: one vec4 per slot each, region r of slot s at
    /// `paths[r · wavefront + s]`.
    Region, "R_" {
        /// xyz origin, w cone width at the origin
        Origin = 0 => "ORIGIN",
        /// xyz direction, w cone spread angle
        Dir = 1 => "DIR",
        /// rgb throughput β, w pdf of the BSDF sample that made the ray (0: no MIS)
        Beta = 2 => "BETA",
        /// rgb radiance so far
        L = 3 => "L",
        /// t, primitive (bits), barycentrics u, v
        Hit = 4 => "HIT",
        /// xyz shadow-ray origin, w tmax
        ShadowOrigin = 5 => "SHADOW_O",
        /// xyz shadow-ray direction
        ShadowDir = 6 => "SHADOW_D",
        /// rgb unoccluded contribution
        ShadowContribution = 7 => "SHADOW_C",
        /// xyz the geometric normal at the ray's origin (the light BVH's pmf for MIS)
        PrevNormal = 8 => "PREV_N",
    }
);

tags!(
    /// What a slot holds (`info.x`).
    SlotState, "SLOT_" {
        /// nothing yet: start a path
        Start = 0 => "START",
        /// a ray to trace
        Flying = 1 => "FLYING",
        /// a finished path to accumulate
        Ended = 2 => "ENDED",
        /// all its samples done
        Idle = 3 => "IDLE",
    }
);

/// Every tag set.
pub fn all() -> Vec<TagSet> {
    vec![
        MaterialKind::tag_set(),
        LightKind::tag_set(),
        EnvKind::tag_set(),
        Strategy::tag_set(),
        NdfSampling::tag_set(),
        Sequence::tag_set(),
        Region::tag_set(),
        SlotState::tag_set(),
    ]
}

/// The committed `shaders/render/tags.inc.wgsl`, generated.
pub fn wgsl() -> String {
    tags::wgsl(
        "facet_render::layout::tags",
        "crates/render/src/layout/tags.rs",
        "facet-render",
        &all(),
    )
}
