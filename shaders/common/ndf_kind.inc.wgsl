// Include-only. Generated from facet_glint::tags (crates/glint/src/tags.rs): do not edit;
// `FACET_REGENERATE=1 cargo test -p facet-glint --test tags` rewrites it.

// facet_glint::tags::NdfTag
const NDF_KIND_GGX: u32 = 0u; // Trowbridge–Reitz (GGX)
const NDF_KIND_BECKMANN: u32 = 1u; // Beckmann
const NDF_KIND_TABULATED: u32 = 2u; // a tabulated NDF (the fit's, or any other sampled D)
