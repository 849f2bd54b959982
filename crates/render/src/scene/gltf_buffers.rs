//! The bytes of a glTF's buffers, loaded by Facet itself (not `gltf::import_buffers`, which reads
//! any path or `file:` URI with `std::fs`, FIFOs and devices included).
//!
//! Each buffer is the GLB's binary chunk (buffer 0 without a `uri`, in a `.glb`), a `data:` URI,
//! or a relative file beside the glTF ([`super::uri`]) read through
//! [`facet_brdf::io::input::read`] with [`Cap::BUFFER`]. The bytes must cover the declared
//! `byteLength` (the GLB chunk may be up to 3 bytes longer, padding; a file may be longer), and
//! only `byteLength` bytes are kept visible, so every later range check is against the declared
//! length. A file named by several buffers is read once.

use super::uri::{UriTarget, resolve, shorten};
use crate::error::RenderError;
use facet_brdf::io::input::{self, Cap};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One loaded buffer: shared bytes, of which the first `len` are the buffer.
#[derive(Clone, Debug)]
struct Loaded {
    bytes: Arc<Vec<u8>>,
    len: usize,
}

/// Every buffer of a document, by index.
#[derive(Clone, Debug, Default)]
pub struct Buffers {
    loaded: Vec<Loaded>,
}

impl Buffers {
    /// Buffer `i`'s bytes, exactly its byteLength.
    pub fn get(&self, i: usize) -> Option<&[u8]> {
        self.loaded.get(i).map(|l| &l.bytes[..l.len])
    }

    /// Buffer `i`'s byteLength.
    pub fn len_of(&self, i: usize) -> Option<u64> {
        self.loaded.get(i).map(|l| l.len as u64)
    }

    /// Loads every buffer of `doc`; `blob` is the GLB's binary chunk, if any.
    pub fn load(
        gltf_path: &Path,
        doc: &gltf::Document,
        blob: Option<Vec<u8>>,
    ) -> Result<Buffers, RenderError> {
        let mut blob = blob.map(Arc::new);
        let mut files: HashMap<PathBuf, Arc<Vec<u8>>> = HashMap::new();
        let mut loaded = Vec::with_capacity(doc.buffers().len());
        for (i, b) in doc.as_json().buffers.iter().enumerate() {
            let label = match &b.name {
                Some(n) => format!("buffer {i} `{}`", shorten(n)),
                None => format!("buffer {i}"),
            };
            let bad = |m: String| RenderError::input(gltf_path, format!("{label}: {m}"));
            let declared = b.byte_length.0;
            let (bytes, whence) = match b.uri.as_deref() {
                None if i == 0 => match blob.take() {
                    Some(bin) => (bin, "the GLB's binary chunk".to_string()),
                    None => {
                        return Err(bad(
                            "has no uri, and there is no GLB binary chunk to take it from".into(),
                        ));
                    }
                },
                None => {
                    return Err(bad(
                        "has no uri; only buffer 0 of a .glb may be its binary chunk".into(),
                    ));
                }
                Some(uri) => match resolve(gltf_path, uri).map_err(bad)? {
                    UriTarget::Data(d) => (Arc::new(d), "its data: URI".to_string()),
                    UriTarget::File(file) => {
                        let bytes = match files.get(&file) {
                            Some(b) => b.clone(),
                            None => {
                                let b = Arc::new(
                                    input::read(&file, Cap::BUFFER)
                                        .map_err(|e| bad(e.to_string()))?,
                                );
                                files.insert(file.clone(), b.clone());
                                b
                            }
                        };
                        (bytes, file.display().to_string())
                    }
                },
            };
            if (bytes.len() as u64) < declared {
                return Err(bad(format!(
                    "byteLength is {declared} but {whence} holds only {} bytes",
                    bytes.len()
                )));
            }
            loaded.push(Loaded {
                len: declared as usize,
                bytes,
            });
        }
        Ok(Buffers { loaded })
    }
}
