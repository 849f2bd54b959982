//! The identity of a render, written into its EXRs (`facet_render::output::shard`): SHA-256 of
//! every file the scene and the environment read and of the settings that decide its pixels, so
//! that `facet merge` joins only parts of one render. Left out: the seed (recorded and checked on
//! its own), the sample range (what a part holds), and what changes speed but not pixels
//! (--wavefront, --bvh, --time-limit, --exposure, which only the PNG sees).
//!
//! The files' digests are those of the bytes the loaders read, taken as they read them
//! ([`facet_fit::io::input::recording`]): no file is read again, so a file that changed or
//! went away since cannot make the digest disagree with the render. A file the scene names
//! but could not be read (a missing texture, skipped with a warning) adds nothing: the glTF's
//! own bytes name it, and once it is there its bytes are in the digest.

use super::RenderArgs;
use facet_fit::io::input::FileRead;
use sha2::{Digest, Sha256};

/// The version written beside the digest: parts of different Facets do not merge.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// SHA-256 (hex) of the files `read` (the scene, the environment map and every file the scene
/// read, each with the digest of its bytes as read) and of the image-deciding settings of
/// `args`. The files' digests are sorted before they are digested together: the scene lists its
/// files in no fixed order. A file read with the same bytes under two paths counts twice, as
/// it did when each path was read again here.
pub fn digest(args: &RenderArgs, read: &[FileRead]) -> String {
    let mut each: Vec<[u8; 32]> = read.iter().filter_map(|r| r.sha256).collect();
    each.sort();
    let mut h = Sha256::new();
    for d in &each {
        h.update(d);
    }
    h.update(settings(args).as_bytes());
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The settings that decide the pixels, as text (paths left out: a farm's machines may see one
/// file at different paths; its contents are digested).
fn settings(args: &RenderArgs) -> String {
    format!(
        "size {}x{}; max depth {}; camera {:?}; materials {:?}; env color {:?}; glint filter {}; \
         light selection {:?}",
        args.width,
        args.height,
        args.max_depth,
        args.camera,
        // The names only: the fits' contents are among the files, and a farm's machines may
        // see them at other paths.
        args.materials
            .iter()
            .map(|m| m.split_once('=').map_or(m.as_str(), |(name, _)| name))
            .collect::<Vec<_>>(),
        args.env.is_none().then_some(&args.env_color),
        !args.no_glint_filter,
        args.light_selection
    )
}
