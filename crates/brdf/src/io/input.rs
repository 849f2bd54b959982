//! Reading input files, the one door every loader of Facet goes through.
//!
//! Only regular files are read: a directory, a FIFO, a socket or a device is refused before it
//! is opened (a FIFO would block the reader, a device never end), and the opened handle is
//! checked again. Every read is bounded by a cap the caller names ([`Cap`]): a file larger than
//! its kind can be is refused by its size, before a byte is read.
//!
//! What a load read can be recorded ([`recording`]): each file with the SHA-256 of the very
//! bytes the reader got, hashed as they are read, so that whoever identifies the load by its
//! files (a render shard's digest) sees what the loader saw and never reads a file again.

use sha2::{Digest, Sha256};
use std::cell::RefCell;
use std::collections::HashSet;
use std::io::Read;
use std::path::{Path, PathBuf};

/// A file that cannot be read as an input, with the reason in words.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct InputError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub problem: String,
}

impl InputError {
    /// An error about `path`.
    pub fn new(path: impl Into<PathBuf>, problem: impl std::fmt::Display) -> Self {
        InputError {
            path: path.into(),
            problem: problem.to_string(),
        }
    }
}

/// The largest file of each kind Facet reads; documented in docs/fitting.md.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cap {
    /// What the file is, for the message ("fit JSON", "glTF buffer").
    pub kind: &'static str,
    /// The largest size read, in bytes.
    pub bytes: u64,
}

const MIB: u64 = 1 << 20;

impl Cap {
    /// A fit JSON: tables of at most a few million entries.
    pub const FIT_JSON: Cap = Cap::new("fit JSON", 256 * MIB);
    /// A neural-proxy library (the MERL-100 file is 1.4 MiB).
    pub const NBRDF: Cap = Cap::new("neural BRDF file", 256 * MIB);
    /// A MERL `.binary` (exactly 12 + 3 · 8 · 1 458 000 bytes when valid).
    pub const MERL: Cap = Cap::new("MERL file", 64 * MIB);
    /// An RGL `.bsdf` tensor file (the database's spectral files are tens of MiB).
    pub const BSDF: Cap = Cap::new("RGL .bsdf file", 1024 * MIB);
    /// A glTF JSON or a whole `.glb`.
    pub const GLTF: Cap = Cap::new("glTF file", 4096 * MIB);
    /// A glTF `.bin` buffer.
    pub const BUFFER: Cap = Cap::new("glTF buffer", 4096 * MIB);
    /// A PNG or JPEG texture.
    pub const TEXTURE: Cap = Cap::new("texture", 512 * MIB);
    /// An OpenEXR environment map.
    pub const EXR: Cap = Cap::new("OpenEXR image", 2048 * MIB);

    /// A cap of `bytes` for files of `kind`.
    pub const fn new(kind: &'static str, bytes: u64) -> Self {
        Cap { kind, bytes }
    }
}

/// The metadata of `path` when it is a regular file (symbolic links followed); an error naming
/// what it is otherwise.
pub fn regular_file(path: &Path) -> Result<std::fs::Metadata, InputError> {
    let meta = std::fs::metadata(path).map_err(|e| InputError::new(path, io_problem(&e)))?;
    check_type(path, &meta)?;
    Ok(meta)
}

fn check_type(path: &Path, meta: &std::fs::Metadata) -> Result<(), InputError> {
    let t = meta.file_type();
    if t.is_file() {
        return Ok(());
    }
    let what = if t.is_dir() {
        "a directory"
    } else {
        special_kind(&t)
    };
    Err(InputError::new(
        path,
        format!("is {what}, not a regular file"),
    ))
}

#[cfg(unix)]
fn special_kind(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_fifo() {
        "a FIFO"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_block_device() || t.is_char_device() {
        "a device"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn special_kind(_: &std::fs::FileType) -> &'static str {
    "a special file"
}

/// An I/O error in words, without the `(os error N)` tail.
pub fn io_problem(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".into(),
        std::io::ErrorKind::PermissionDenied => "permission denied".into(),
        _ => {
            let s = e.to_string();
            match s.find(" (os error") {
                Some(i) => s[..i].to_owned(),
                None => s,
            }
        }
    }
}

/// Opens a regular file for reading (never blocking on a FIFO swapped in after the check) and
/// returns it with its length, refused when longer than `cap`.
pub fn open(path: &Path, cap: Cap) -> Result<(std::fs::File, u64), InputError> {
    regular_file(path)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options
        .open(path)
        .map_err(|e| InputError::new(path, io_problem(&e)))?;
    let meta = file
        .metadata()
        .map_err(|e| InputError::new(path, io_problem(&e)))?;
    check_type(path, &meta)?;
    let len = meta.len();
    if len > cap.bytes {
        return Err(InputError::new(
            path,
            format!(
                "{len} bytes is more than a {} may hold ({} MiB)",
                cap.kind,
                cap.bytes / MIB
            ),
        ));
    }
    Ok((file, len))
}

/// The whole of a regular file of at most `cap` bytes. Seen by [`recording`]: with the bytes'
/// SHA-256, or without one when the file could not be read.
pub fn read(path: &Path, cap: Cap) -> Result<Vec<u8>, InputError> {
    let bytes = read_unrecorded(path, cap);
    if is_recording() {
        push(FileRead {
            path: path.to_owned(),
            sha256: bytes.as_ref().ok().map(|b| sha256(&[b])),
        });
    }
    bytes
}

fn read_unrecorded(path: &Path, cap: Cap) -> Result<Vec<u8>, InputError> {
    let (file, len) = open(path, cap)?;
    let mut bytes = Vec::with_capacity(len as usize);
    // `take` keeps a file that grows while being read inside the cap.
    file.take(cap.bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| InputError::new(path, io_problem(&e)))?;
    if bytes.len() as u64 > cap.bytes {
        return Err(InputError::new(
            path,
            format!(
                "grew past the {} MiB a {} may hold",
                cap.bytes / MIB,
                cap.kind
            ),
        ));
    }
    Ok(bytes)
}

/// The whole of a regular UTF-8 text file of at most `cap` bytes.
pub fn read_to_string(path: &Path, cap: Cap) -> Result<String, InputError> {
    String::from_utf8(read(path, cap)?).map_err(|e| {
        InputError::new(
            path,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// A file read while [`recording`]: the path as the reader named it and the SHA-256 of the
/// bytes it got.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct FileRead {
    /// The file.
    pub path: PathBuf,
    /// SHA-256 of the bytes read; `None` for a file that could not be read (missing, not a
    /// regular file, over its cap), which the loader either failed on or went on without (a
    /// glTF's missing texture: a warning, and the factor alone).
    pub sha256: Option<[u8; 32]>,
}

/// The reads seen so far by the innermost [`recording`] of a thread, each (path, bytes) once.
#[derive(Default)]
struct Recorder {
    reads: Vec<FileRead>,
    seen: HashSet<FileRead>,
}

thread_local! {
    static RECORDER: RefCell<Option<Recorder>> = const { RefCell::new(None) };
}

fn is_recording() -> bool {
    RECORDER.with(|r| r.borrow().is_some())
}

fn push(read: FileRead) {
    RECORDER.with(|r| {
        if let Some(rec) = r.borrow_mut().as_mut()
            && rec.seen.insert(read.clone())
        {
            rec.reads.push(read);
        }
    });
}

fn sha256(parts: &[&[u8]]) -> [u8; 32] {
    let mut h = Sha256::new();
    for p in parts {
        h.update(p);
    }
    h.finalize().into()
}

/// Runs `f` and returns, with its result, the files read on this thread meanwhile through
/// [`read`] and [`read_to_string`] (and by readers that stream or map a file and say so with
/// [`note_read`]), in the order first read: each file once per content (a file read twice
/// with the same bytes is one entry), a file that could not be read with no digest. A
/// recording inside another is seen by both. Reads on other threads are not seen: a loader
/// that reads files in parallel would have to record them itself.
pub fn recording<T>(f: impl FnOnce() -> T) -> (T, Vec<FileRead>) {
    /// Puts the enclosing recording (if any) back, also when `f` panics.
    struct Enclosing(Option<Option<Recorder>>);
    impl Drop for Enclosing {
        fn drop(&mut self) {
            if let Some(outer) = self.0.take() {
                RECORDER.with(|r| *r.borrow_mut() = outer);
            }
        }
    }
    let outer = RECORDER.with(|r| r.borrow_mut().replace(Recorder::default()));
    let mut enclosing = Enclosing(Some(outer));
    let value = f();
    let outer = enclosing.0.take().expect("taken once");
    let reads = RECORDER
        .with(|r| std::mem::replace(&mut *r.borrow_mut(), outer))
        .map(|rec| rec.reads)
        .unwrap_or_default();
    for read in &reads {
        push(read.clone());
    }
    (value, reads)
}

/// Tells [`recording`] that `path` was read without [`read`] (streamed into a table, or
/// mapped): its bytes are `parts`, one after the other. Hashes them only while recording.
pub fn note_read(path: &Path, parts: &[&[u8]]) {
    if is_recording() {
        push(FileRead {
            path: path.to_owned(),
            sha256: Some(sha256(parts)),
        });
    }
}

/// `path` made absolute and free of symbolic links, for comparing inputs with outputs; a path
/// that does not exist yet is its parent's canonical form joined with its name.
pub fn canonical(path: &Path) -> Option<PathBuf> {
    if let Ok(p) = path.canonicalize() {
        return Some(p);
    }
    let name = path.file_name()?;
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    };
    Some(canonical(&parent)?.join(name))
}

/// Whether two paths name one file, by canonical path (either may not exist yet).
pub fn same_file(a: &Path, b: &Path) -> bool {
    matches!((canonical(a), canonical(b)), (Some(x), Some(y)) if x == y)
}

/// A name taken from data (a record's `name`, an nbrdf key) as a safe file stem: no separators,
/// no `..`, not absolute, not hidden, not empty, at most 100 bytes; other characters than
/// ASCII letters, digits, `-`, `_` and `.` become `_`.
pub fn safe_file_stem(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    // A leading dot would hide the file (and `..` would climb): replace every leading dot.
    let dots = s.len() - s.trim_start_matches('.').len();
    s.replace_range(..dots, &"_".repeat(dots));
    s.truncate(100);
    if s.is_empty() { "unnamed".into() } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every read seen, with the SHA-256 of the bytes read; a file read twice with the same
    /// bytes is one entry, with other bytes two; a missing file has no digest; an inner
    /// recording is seen by the outer one too; nothing is seen outside a recording, and a panic
    /// inside one ends it.
    #[test]
    fn recording_sees_each_read_with_its_digest() {
        let dir = std::env::temp_dir().join(format!("facet-input-rec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (a, b, gone) = (dir.join("a"), dir.join("b"), dir.join("gone"));
        std::fs::write(&a, b"first").unwrap();
        std::fs::write(&b, b"bee").unwrap();
        let cap = Cap::new("test file", 1 << 10);
        let digest = |bytes: &[u8]| Some(<[u8; 32]>::from(Sha256::digest(bytes)));
        let ((), outer) = recording(|| {
            read(&a, cap).unwrap();
            read(&a, cap).unwrap();
            assert!(read(&gone, cap).is_err());
            let ((), inner) = recording(|| {
                read_to_string(&b, cap).unwrap();
            });
            assert_eq!(inner.len(), 1);
            std::fs::write(&a, b"second").unwrap();
            read(&a, cap).unwrap();
            note_read(&dir.join("streamed"), &[b"str", b"eamed"]);
        });
        let seen: Vec<(PathBuf, Option<[u8; 32]>)> =
            outer.into_iter().map(|r| (r.path, r.sha256)).collect();
        assert_eq!(
            seen,
            vec![
                (a.clone(), digest(b"first")),
                (gone.clone(), None),
                (b.clone(), digest(b"bee")),
                (a.clone(), digest(b"second")),
                (dir.join("streamed"), digest(b"streamed")),
            ]
        );
        read(&a, cap).unwrap();
        assert!(!is_recording());
        let caught = std::panic::catch_unwind(|| {
            recording(|| {
                read(&a, cap).unwrap();
                panic!("a loader's bug");
            })
        });
        assert!(caught.is_err() && !is_recording());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn stems_are_safe() {
        for (name, want) in [
            ("gold", "gold"),
            ("../../etc/passwd", "___.._etc_passwd"),
            ("/abs", "_abs"),
            ("..", "__"),
            (".hidden", "_hidden"),
            ("", "unnamed"),
            ("a\\b:c", "a_b_c"),
            ("métal", "m_tal"),
        ] {
            assert_eq!(safe_file_stem(name), want, "{name:?}");
        }
        assert_eq!(safe_file_stem(&"x".repeat(300)).len(), 100);
    }
}
