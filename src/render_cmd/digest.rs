//! The identity of a render, written into its EXRs (`facet_render::output::shard`): SHA-256 of every file
//! the scene reads and of the settings that decide its pixels, so that `facet merge` joins only
//! parts of one render. Left out: the seed (recorded and checked on its own), the sample range
//! (what a part holds), and what changes speed but not pixels (--wavefront, --bvh, --time-limit,
//! --exposure, which only the PNG sees).

use super::RenderArgs;
use anyhow::{Context, Result};
use sha2::{Digest, Sha256};
use std::path::Path;

/// The version written beside the digest: parts of different Facets do not merge.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// SHA-256 (hex) of `files` (the scene, the environment map and every file the scene read) and
/// of the image-deciding settings of `args`. Each file is digested alone and the digests sorted
/// before they are digested together: the scene lists its files in no fixed order.
pub fn digest(args: &RenderArgs, files: &[&Path]) -> Result<String> {
    let mut each = files
        .iter()
        .map(|f| {
            let bytes =
                std::fs::read(f).with_context(|| format!("{}: reading it again", f.display()))?;
            Ok(Sha256::digest(&bytes).to_vec())
        })
        .collect::<Result<Vec<_>>>()?;
    each.sort();
    let mut h = Sha256::new();
    for d in &each {
        h.update(d);
    }
    h.update(settings(args).as_bytes());
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
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
