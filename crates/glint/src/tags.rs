//! The NDF kind the WGSL stages branch on (`AnalyticNdf.kind`, the glint passes'
//! `ndf_kind` and the renderer's `Material.ndf_kind`), written once, here. [`wgsl`] renders it
//! as WGSL constants; the committed `shaders/common/ndf_kind.inc.wgsl` is its output
//! (`cargo test -p facet-glint --test tags` fails when the two differ; `FACET_REGENERATE=1`
//! rewrites the file) and no other WGSL file may define a constant with its prefix.
//!
//! facet-fit's [`NdfKind`] names the analytic kinds; it builds without wgpu, so the GPU's set,
//! which adds the tabulated NDF, is declared here, where both GPU users (this crate and
//! facet-render) see it.

use facet_brdf::model::microfacet::{Ndf, NdfKind};
use facet_gpu::tags;
pub use facet_gpu::tags::TagSet;

tags!(
    /// How a shader reads an NDF: an analytic kind, or a table uploaded beside it.
    NdfTag, "NDF_KIND_" {
        /// Trowbridge–Reitz (GGX)
        Ggx = 0 => "GGX",
        /// Beckmann
        Beckmann = 1 => "BECKMANN",
        /// a tabulated NDF (the fit's, or any other sampled D)
        Tabulated = 2 => "TABULATED",
    }
);

impl From<NdfKind> for NdfTag {
    fn from(kind: NdfKind) -> Self {
        match kind {
            NdfKind::Ggx => NdfTag::Ggx,
            NdfKind::Beckmann => NdfTag::Beckmann,
        }
    }
}

impl NdfTag {
    /// The tag of `ndf`: its analytic kind, or [`NdfTag::Tabulated`].
    pub fn of(ndf: &Ndf) -> Self {
        match ndf {
            Ndf::Analytic(a) => a.kind.into(),
            Ndf::Tabulated(_) => NdfTag::Tabulated,
        }
    }
}

/// Every tag set.
pub fn all() -> Vec<TagSet> {
    vec![NdfTag::tag_set()]
}

/// The committed `shaders/common/ndf_kind.inc.wgsl`, generated.
pub fn wgsl() -> String {
    tags::wgsl(
        "facet_glint::tags",
        "crates/glint/src/tags.rs",
        "facet-glint",
        &all(),
    )
}
