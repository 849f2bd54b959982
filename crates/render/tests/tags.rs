//! The closed sets shared with WGSL are written once (facet_render::tags): the committed
//! `shaders/render/tags.inc.wgsl` is exactly their generated text, naga reads back the values
//! Rust has, and no other WGSL file defines a constant with one of their prefixes.
//! `FACET_REGENERATE=1 cargo test -p facet-render --test tags` rewrites the file.

use std::path::Path;

const FILE: &str = "render/tags.inc.wgsl";

fn shaders_dir() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../shaders"))
}

#[test]
fn the_committed_wgsl_tags_are_the_generated_ones() {
    let path = shaders_dir().join(FILE);
    let generated = facet_render::tags::wgsl();
    if std::env::var_os("FACET_REGENERATE").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap();
    assert!(
        committed == generated,
        "{} is not what facet_render::tags generates; rerun with FACET_REGENERATE=1",
        path.display()
    );
}

/// naga's view of the constants (the file as the GPU compiles it) against the Rust values.
#[test]
fn naga_reads_the_rust_values() {
    let found = facet_gpu::tags::u32_constants(&facet_render::tags::wgsl()).unwrap();
    let mut n = 0;
    for set in facet_render::tags::all() {
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
    let prefixes: Vec<&str> = facet_render::tags::all().iter().map(|t| t.prefix).collect();
    let offenders = facet_gpu::tags::defined_elsewhere(FILE, &prefixes);
    assert!(
        offenders.is_empty(),
        "tags defined outside {FILE}:\n{}",
        offenders.join("\n")
    );
}
