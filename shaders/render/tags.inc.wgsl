// Include-only. Generated from facet_render::layout::tags (crates/render/src/layout/tags.rs): do not edit;
// `FACET_REGENERATE=1 cargo test -p facet-render --test tags` rewrites it.

// facet_render::layout::tags::MaterialKind
const MAT_GLTF: u32 = 0u; // a glTF metallic-roughness material
const MAT_ANALYTIC: u32 = 1u; // a fit's GGX or Beckmann model
const MAT_TABULATED: u32 = 2u; // a fit's tabulated NDF
const MAT_MERL: u32 = 3u; // a MERL-grid measurement, sampled by its fit's tabulated model
const MAT_RGL: u32 = 4u; // an RGL `.bsdf` measurement
const MAT_GLINT: u32 = 5u; // a fit's model as glints

// facet_render::layout::tags::LightKind
const LIGHT_POINT: u32 = 0u; // KHR_lights_punctual point light
const LIGHT_SPOT: u32 = 1u; // KHR_lights_punctual spot light
const LIGHT_DIRECTIONAL: u32 = 2u; // KHR_lights_punctual directional light
const LIGHT_TRIANGLE: u32 = 3u; // an emissive triangle
const LIGHT_ENVIRONMENT: u32 = 4u; // the environment (constant or map)

// facet_render::layout::tags::EnvKind
const ENV_NONE: u32 = 0u; // black
const ENV_CONSTANT: u32 = 1u; // a constant radiance (`Frame.env_color`)
const ENV_MAP: u32 = 2u; // an equirectangular map with its sampling tables

// facet_render::layout::tags::Strategy
const STRATEGY_MIS: u32 = 0u; // light and BSDF sampling combined by the power heuristic (Veach 1997)
const STRATEGY_LIGHT: u32 = 1u; // light sampling alone: emission a BSDF ray finds counts only if light sampling cannot
const STRATEGY_BSDF: u32 = 2u; // BSDF sampling alone: only delta lights (point, spot, directional) are sampled

// facet_render::layout::tags::NdfSampling
const NDF_SAMPLING_VISIBLE: u32 = 0u; // the normals visible from ωo (Heitz 2018): the default
const NDF_SAMPLING_D_COS: u32 = 1u; // D(h) cos θh, the older choice, kept to measure against
const NDF_SAMPLING_COSINE: u32 = 2u; // the cosine lobe alone, in the microfacet and measured MERL stages: the reference

// facet_render::layout::tags::Sequence
const SEQUENCE_RANDOM: u32 = 0u; // independent numbers: a PCG hash of (pixel, sample, dimension, seed)
const SEQUENCE_SOBOL: u32 = 1u; // Owen-scrambled Sobol points, the dimensions a bounce uses together stratified

// facet_render::layout::tags::Region
const R_ORIGIN: u32 = 0u; // xyz origin, w cone width at the origin
const R_DIR: u32 = 1u; // xyz direction, w cone spread angle
const R_BETA: u32 = 2u; // rgb throughput β, w pdf of the BSDF sample that made the ray (0: no MIS)
const R_L: u32 = 3u; // rgb radiance so far
const R_HIT: u32 = 4u; // t, primitive (bits), barycentrics u, v
const R_SHADOW_O: u32 = 5u; // xyz shadow-ray origin, w tmax
const R_SHADOW_D: u32 = 6u; // xyz shadow-ray direction
const R_SHADOW_C: u32 = 7u; // rgb unoccluded contribution
const R_PREV_N: u32 = 8u; // xyz the geometric normal at the ray's origin (the light BVH's pmf for MIS)

// facet_render::layout::tags::SlotState
const SLOT_START: u32 = 0u; // nothing yet: start a path
const SLOT_FLYING: u32 = 1u; // a ray to trace
const SLOT_ENDED: u32 = 2u; // a finished path to accumulate
const SLOT_IDLE: u32 = 3u; // all its samples done
