//! Outputs written so that a failed write never leaves a truncated file where a good one was.

use std::path::{Path, PathBuf};

/// The temporary file an output is written to before it is renamed into place: hidden, beside
/// it, with its extension kept (`out/.demo.partial.png` for `out/demo.png`) so that a writer
/// that picks its format by extension still can.
pub fn partial_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let name = match path.extension() {
        Some(ext) => format!(".{stem}.partial.{}", ext.to_string_lossy()),
        None => format!(".{stem}.partial"),
    };
    path.with_file_name(name)
}

/// Writes `path` by `write` into [`partial_path`] and renames it into place; on failure the
/// temporary file is removed and `path` is as it was.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let tmp = partial_path(path);
    write(&tmp)
        .and_then(|_| std::fs::rename(&tmp, path))
        .inspect_err(|_| {
            let _ = std::fs::remove_file(&tmp);
        })
}

/// [`write_atomically`] of the bytes `contents`.
pub fn write_bytes_atomically(path: &Path, contents: impl AsRef<[u8]>) -> std::io::Result<()> {
    write_atomically(path, |tmp| std::fs::write(tmp, contents))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_partial_one() {
        let dir = std::env::temp_dir().join(format!("facet-output-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("fit.json");
        write_bytes_atomically(&path, "old").unwrap();
        let failed = write_atomically(&path, |tmp| {
            std::fs::write(tmp, "half")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(failed.is_err());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert!(!partial_path(&path).exists());
        assert_eq!(partial_path(&path), dir.join(".fit.partial.json"));
        write_bytes_atomically(&path, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
