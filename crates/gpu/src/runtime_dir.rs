//! A private `XDG_RUNTIME_DIR` for processes started without one.
//!
//! Probing adapters loads Mesa's drivers and the Wayland client library, which print
//! `error: XDG_RUNTIME_DIR is invalid or not set` on every start when the variable is unset (a
//! container, `sudo`, a CI job). A binary calls [`ensure_runtime_dir`] first thing in `main`:
//! an unset or unusable variable is pointed at `$TMPDIR/facet-runtime-<uid>` (mode 0700, owned
//! by the user), which holds no display socket, so nothing connects and nothing complains.

use std::path::{Path, PathBuf};

/// Points `XDG_RUNTIME_DIR` at a private folder when it is unset or not a folder; returns the
/// folder set, `None` when the variable was fine or no private folder could be made.
///
/// # Safety
/// Changes the process environment: call it before any other thread exists (first thing in
/// `main`), as `std::env::set_var` requires.
pub unsafe fn ensure_runtime_dir() -> Option<PathBuf> {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir()) {
        return None;
    }
    let dir = private_dir()?;
    // SAFETY: the caller guarantees no other thread reads or writes the environment.
    unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    Some(dir)
}

#[cfg(unix)]
fn private_dir() -> Option<PathBuf> {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    // SAFETY: getuid has no preconditions and cannot fail.
    let uid = unsafe { libc::getuid() };
    let dir = std::env::temp_dir().join(format!("facet-runtime-{uid}"));
    let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
    // Only a real folder of ours that nobody else can enter (not a link planted by another user).
    let meta = std::fs::symlink_metadata(&dir).ok()?;
    let private = meta.is_dir() && meta.uid() == uid && meta.permissions().mode() & 0o077 == 0;
    private.then_some(dir)
}

#[cfg(not(unix))]
fn private_dir() -> Option<PathBuf> {
    None
}
