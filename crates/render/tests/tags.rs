//! The closed sets shared with WGSL are written once (facet_render::layout::tags): the committed
//! `shaders/render/tags.inc.wgsl` is exactly their generated text, naga reads back the values
//! Rust has, and no other WGSL file defines a constant with one of their prefixes.
//! `FACET_REGENERATE=1 cargo test -p facet-render --test tags` rewrites the file.

use std::path::Path;

const FILE: &str = "render/tags.inc.wgsl";

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
        &facet_render::layout::tags::wgsl(),
        &facet_render::layout::tags::all(),
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
