//! URIs of glTF buffers and images: what each may be and where it leads.
//!
//! A URI is either a `data:` URI (base64 payload, [`super::data_uri`]) or a *relative* reference
//! to a file beside the glTF: percent-decoded (RFC 3986), then joined to the glTF's folder.
//! Anything else is refused with a message saying why: an absolute path (`/x.bin`, `C:\x.bin`,
//! `\\server\x`), a scheme (`file:`, `http:`, …), a query or fragment, an empty URI. A relative
//! path may still climb out of the folder with `..`; that is allowed (glTF files do it), and the
//! file read is still a regular file under its cap ([`facet_brdf::io::input`]).

use super::data_uri::decode_data_uri;
use std::path::{Path, PathBuf};

/// Where a glTF URI points.
#[derive(Debug, PartialEq, Eq)]
pub enum UriTarget {
    /// The bytes of a `data:` URI.
    Data(Vec<u8>),
    /// A file, already joined to the glTF's folder.
    File(PathBuf),
}

/// Resolves `uri` against the folder of `gltf_path`; `Err` says in words why it is refused.
pub fn resolve(gltf_path: &Path, uri: &str) -> Result<UriTarget, String> {
    if let Some(decoded) = decode_data_uri(uri) {
        return decoded.map(UriTarget::Data);
    }
    let shown = shorten(uri);
    if uri.is_empty() {
        return Err("the URI is empty".into());
    }
    if let Some(scheme) = scheme(uri) {
        return Err(format!(
            "URI `{shown}` has the scheme `{scheme}:`; only relative file paths and data: URIs are read"
        ));
    }
    if uri.contains(['?', '#']) {
        return Err(format!(
            "URI `{shown}` has a query or fragment; only relative file paths are read"
        ));
    }
    let decoded = percent_decode(uri)
        .ok_or_else(|| format!("URI `{shown}` is not valid UTF-8 once percent-decoded"))?;
    if decoded.contains('\0') {
        return Err(format!("URI `{shown}` contains a NUL byte"));
    }
    let absolute = decoded.starts_with('/')
        || decoded.starts_with('\\')
        || Path::new(&decoded).is_absolute()
        || Path::new(&decoded).has_root();
    if absolute {
        return Err(format!(
            "URI `{shown}` is an absolute path; glTF file URIs must be relative to the glTF"
        ));
    }
    let base = gltf_path.parent().unwrap_or(Path::new(""));
    Ok(UriTarget::File(base.join(decoded)))
}

/// The scheme of `uri` (RFC 3986: a letter, then letters, digits, `+`, `-`, `.`, then `:`).
/// A single letter before `:` is a Windows drive (`C:/x`), reported as a scheme too since it is
/// not relative either.
fn scheme(uri: &str) -> Option<&str> {
    let colon = uri.find(':')?;
    let s = &uri[..colon];
    let mut chars = s.chars();
    let first = chars.next()?;
    (first.is_ascii_alphabetic()
        && chars.all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.')))
    .then_some(s)
}

/// `%XX` escapes → bytes, as UTF-8; a `%` not followed by two hex digits is kept as written.
/// `None` when the result is not UTF-8.
pub fn percent_decode(uri: &str) -> Option<String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match (
            b[i],
            b.get(i + 1).and_then(|&c| hex(c)),
            b.get(i + 2).and_then(|&c| hex(c)),
        ) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

/// At most 80 characters of `s` for a message (a URI can be megabytes of base64).
pub fn shorten(s: &str) -> String {
    match s.char_indices().nth(80) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_data_and_refused() {
        let g = Path::new("/scenes/a.gltf");
        assert_eq!(
            resolve(g, "tex%20ture.png"),
            Ok(UriTarget::File("/scenes/tex ture.png".into()))
        );
        assert_eq!(
            resolve(g, "sub/../b.bin"),
            Ok(UriTarget::File("/scenes/sub/../b.bin".into()))
        );
        assert_eq!(
            resolve(g, "data:application/octet-stream;base64,Zm9v"),
            Ok(UriTarget::Data(b"foo".to_vec()))
        );
        for (uri, word) in [
            ("/etc/passwd", "absolute"),
            ("%2Fetc%2Fpasswd", "absolute"),
            ("\\\\server\\share", "absolute"),
            ("file:///etc/passwd", "scheme `file:`"),
            ("http://example.com/a.bin", "scheme `http:`"),
            ("C:/x.bin", "scheme `C:`"),
            ("a.bin?x=1", "query"),
            ("", "empty"),
            ("data:text/plain,hello", "base64"),
            ("a%00.bin", "NUL"),
        ] {
            let e = resolve(g, uri).unwrap_err();
            assert!(e.contains(word), "{uri}: {e}");
        }
    }
}
