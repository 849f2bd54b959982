//! A file's bytes mapped read-only into memory (Unix), for a short-lived process reading one
//! large file once: the MERL table of `facet fit`.
//!
//! Read into memory, a 35 MB MERL file costs a fresh buffer whose every page the kernel clears
//! and then a copy into it; mapped, the process reads the page cache's pages themselves. On
//! the five timing files that is 7 ms for mapping and validating against 30–70 ms for reading
//! and validating. The price: the mapping shows the file as it is, so a file truncated in place
//! while mapped makes a later read of the lost part fault (SIGBUS). Writers that replace a file
//! by renaming a new one into place (as [`crate::model::merl_grid::MerlTable::write`] does) are safe; the
//! viewer and other long-lived users read the file into memory instead.

use std::fs::File;

/// A whole file mapped read-only and private; unmapped on drop.
pub(crate) struct MappedFile {
    ptr: *const u8,
    len: usize,
}

// SAFETY: the mapping is read-only and owned by this value; &[u8] views of it are shared as
// any immutable buffer's.
unsafe impl Send for MappedFile {}
// SAFETY: as above: nothing writes through the mapping.
unsafe impl Sync for MappedFile {}

impl MappedFile {
    /// Maps the first `len` bytes of `file` (its length as checked by the caller); `None`
    /// where mapping is not available (not Unix, an empty file, a failed `mmap`), for the
    /// caller to read the file instead.
    pub fn map(file: &File, len: usize) -> Option<Self> {
        #[cfg(unix)]
        {
            use std::os::fd::AsRawFd;
            if len == 0 {
                return None;
            }
            // Linux: fault the whole file in with the call rather than page by page.
            #[cfg(target_os = "linux")]
            let flags = libc::MAP_PRIVATE | libc::MAP_POPULATE;
            #[cfg(not(target_os = "linux"))]
            let flags = libc::MAP_PRIVATE;
            // SAFETY: a fresh read-only private mapping of an open file descriptor; the kernel
            // picks the address. Failure is reported as MAP_FAILED and handled.
            let ptr = unsafe {
                libc::mmap(
                    std::ptr::null_mut(),
                    len,
                    libc::PROT_READ,
                    flags,
                    file.as_raw_fd(),
                    0,
                )
            };
            if ptr == libc::MAP_FAILED {
                return None;
            }
            Some(MappedFile {
                ptr: ptr as *const u8,
                len,
            })
        }
        #[cfg(not(unix))]
        {
            let _ = (file, len);
            None
        }
    }

    /// The mapped bytes.
    pub fn bytes(&self) -> &[u8] {
        // SAFETY: `ptr` maps `len` readable bytes for as long as `self` lives.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl Drop for MappedFile {
    fn drop(&mut self) {
        #[cfg(unix)]
        // SAFETY: the mapping made in `map`, unmapped once; no view of it outlives `self`.
        unsafe {
            libc::munmap(self.ptr as *mut libc::c_void, self.len);
        }
    }
}
