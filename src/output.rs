//! Output folders: made when missing, refused with the flag named when the path is a file.

use anyhow::{Result, bail};
use std::path::Path;

/// Creates `dir` (and its parents) for the outputs of `flag`.
pub fn folder(dir: &Path, flag: &str) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{flag} {}: is a file, not a folder", dir.display());
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        anyhow::anyhow!(
            "{flag} {}: cannot create the folder: {}",
            dir.display(),
            facet_fit::io::input::io_problem(&e)
        )
    })
}
