//! The NDF kind shared with WGSL is written once (facet_glint::tags): the committed
//! `shaders/common/ndf_kind.inc.wgsl` is exactly its generated text, naga reads back the values
//! Rust has, and no other WGSL file defines a constant with its prefix.
//! `FACET_REGENERATE=1 cargo test -p facet-glint --test tags` rewrites the file.

use facet_fit::model::microfacet::{AnalyticNdf, Ndf, NdfKind};
use facet_glint::tags::NdfTag;
use std::path::Path;

const FILE: &str = "common/ndf_kind.inc.wgsl";

fn shaders_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shaders"))
}

/// The committed file is the generated text, naga reads back the Rust values and nothing else,
/// and no other shader file defines one of its constants (`facet_gpu::tags::check_generated`).
#[test]
fn the_generated_wgsl_holds_the_rust_tags() {
    let problems = facet_gpu::tags::check_generated(
        shaders_dir(),
        FILE,
        &facet_glint::tags::wgsl(),
        &facet_glint::tags::all(),
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// facet-fit's analytic kinds map to their tags, a table to `Tabulated`.
#[test]
fn every_ndf_has_its_tag() {
    let tag = |kind| NdfTag::of(&Ndf::Analytic(AnalyticNdf::isotropic(kind, 0.2)));
    assert_eq!(tag(NdfKind::Ggx), NdfTag::Ggx);
    assert_eq!(tag(NdfKind::Beckmann), NdfTag::Beckmann);
    assert_eq!(
        NdfKind::ALL.map(|k| NdfTag::from(k) as u32),
        [0, 1],
        "the WGSL's analytic kinds"
    );
    assert_eq!(NdfTag::Tabulated as u32, 2);
}
