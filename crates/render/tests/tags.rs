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

/// The class blocks' WGSL (`facet_render::materials::record`) is generated too: the committed
/// `shaders/render/materials/blocks.inc.wgsl` is exactly the text the Rust blocks give, and
/// each block fits the record's class block.
#[test]
fn the_generated_wgsl_holds_the_class_blocks() {
    use facet_render::materials::record::BLOCK_WORDS;
    let path = shaders_dir().join("render/materials/blocks.inc.wgsl");
    let generated = facet_render::materials::wgsl();
    if std::env::var_os("FACET_REGENERATE").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap();
    assert!(
        committed == generated,
        "{} is not the generated text; rerun with FACET_REGENERATE=1",
        path.display()
    );
    for block in facet_render::materials::class_blocks() {
        assert!(block.words() <= BLOCK_WORDS, "{} overflows", block.wgsl);
    }
    // The MERL class places its block after its lobe's.
    let merl = facet_render::materials::merl::MERL_AT + 1;
    assert!(merl <= BLOCK_WORDS);
}
