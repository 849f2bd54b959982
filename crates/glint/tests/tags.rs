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

#[test]
fn the_committed_wgsl_tags_are_the_generated_ones() {
    let path = shaders_dir().join(FILE);
    let generated = facet_glint::tags::wgsl();
    if std::env::var_os("FACET_REGENERATE").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap();
    assert!(
        committed == generated,
        "{} is not what facet_glint::tags generates; rerun with FACET_REGENERATE=1",
        path.display()
    );
}

/// naga's view of the constants (the file as the GPU compiles it) against the Rust values.
#[test]
fn naga_reads_the_rust_values() {
    let found = facet_gpu::tags::u32_constants(&facet_glint::tags::wgsl()).unwrap();
    let mut n = 0;
    for set in facet_glint::tags::all() {
        for (name, value, _) in set.tags {
            assert_eq!(found.get(name), Some(&value), "{}: {name}", set.rust);
            n += 1;
        }
    }
    assert_eq!(
        found.len(),
        n,
        "constants in the file that no Rust tag has: {found:?}"
    );
}

/// A second definition anywhere else could drift from Rust: there is none.
#[test]
fn no_other_wgsl_file_defines_a_tag() {
    let prefixes: Vec<&str> = facet_glint::tags::all().iter().map(|t| t.prefix).collect();
    let offenders = facet_gpu::tags::defined_elsewhere(FILE, &prefixes);
    assert!(
        offenders.is_empty(),
        "tags defined outside {FILE}:\n{}",
        offenders.join("\n")
    );
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
