//! Parsing a glTF or GLB file and loading its buffers, refusing first what makes the `gltf`
//! crate panic.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use ::gltf::{Document, Gltf, Semantic};

use crate::error::{Error, Result, printable};

/// Parses a glTF or GLB file and loads its buffers, refusing first the inputs that make the
/// `gltf` crate panic. Arguments as for [`read`].
pub(super) fn open(bytes: &[u8], origin: &str, base: Option<&Path>, binary: bool) -> Result<(Document, Vec<Vec<u8>>)> {
    let fail = |problem: String| Error::input(origin, problem);
    // A UTF-8 byte-order mark before the JSON: the spec forbids it, readers may ignore it. It is
    // skipped before anything looks at the bytes, so a GLB header behind one is checked too.
    let bytes = if binary { bytes } else { bytes.strip_prefix(crate::mesh::BOM).unwrap_or(bytes) };
    if binary || bytes.starts_with(b"glTF") {
        check_glb_header(bytes).map_err(fail)?;
    } else if bytes.is_empty() {
        return Err(fail("not a glTF file: the file is empty".into()));
    }
    let gltf = Gltf::from_slice_without_validation(bytes).map_err(|e| fail(format!("not a valid glTF file: {e}")))?;
    let blob = gltf.blob;
    check_position_indices(&gltf.document).map_err(fail)?;
    let document = Document::from_json(gltf.document.into_json()).map_err(|e| fail(e.to_string()))?;
    let buffers = load_buffers(&document, base, blob).map_err(fail)?;
    Ok((document, buffers))
}

/// Checks the 12-byte GLB header the `gltf` crate trusts (a length field below 12 underflows
/// its arithmetic), and that its total length is the file's: a header that says otherwise
/// describes another file.
fn check_glb_header(bytes: &[u8]) -> std::result::Result<(), String> {
    let word = |at: usize| bytes.get(at..at + 4).and_then(|b| b.try_into().ok()).map(u32::from_le_bytes);
    if bytes.is_empty() {
        return Err("not a GLB file: the file is empty".into());
    }
    if !bytes.starts_with(b"glTF") {
        return Err("not a GLB file: it does not start with the GLB magic \"glTF\"".into());
    }
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(format!("not a GLB file: {} bytes, shorter than the 12-byte GLB header", bytes.len()));
    };
    if version != 2 {
        return Err(format!("GLB version {version} is not supported (expected 2)"));
    }
    if length < 20 {
        return Err(format!("GLB header: declared length {length} bytes, less than a header and one chunk (20)"));
    }
    if length as usize != bytes.len() {
        return Err(format!(
            "GLB header: declared length {length} bytes, but the file has {} (truncated or with bytes appended)",
            bytes.len()
        ));
    }
    Ok(())
}

/// The `gltf` validator looks up each primitive's `POSITION` accessor without a bounds check.
fn check_position_indices(document: &Document) -> std::result::Result<(), String> {
    let json = document.as_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = primitive.attributes.get(&::gltf::json::validation::Checked::Valid(Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= json.accessors.len()) {
                return Err(format!(
                    "mesh {m} primitive {p}: POSITION refers to accessor {}, but the file has {} accessors",
                    index.value(),
                    json.accessors.len()
                ));
            }
        }
    }
    Ok(())
}

/// Whether buffer URIs may name files outside the model's folder (`--allow-outside-uris`): off
/// unless the user turns it on, for the whole process, since assets come from anywhere.
static ALLOW_OUTSIDE_URIS: AtomicBool = AtomicBool::new(false);

/// Lets buffer URIs name any regular file (absolute paths, `file:` URIs, `..` out of the
/// model's folder). Off by default; the CLI's `--allow-outside-uris` turns it on.
pub fn allow_outside_uris(allow: bool) {
    ALLOW_OUTSIDE_URIS.store(allow, Ordering::Relaxed);
}

/// How a refusal tells the user to allow what it refused.
const HOW_TO_ALLOW: &str = "pass --allow-outside-uris to read it anyway";

/// Each buffer's bytes, loaded one by one so an error can name the buffer. An external buffer
/// is read from the model's folder (`base`) only, unless [`allow_outside_uris`]; never more than
/// its declared `byteLength`. No error quotes the bytes read.
fn load_buffers(
    document: &Document,
    base: Option<&Path>,
    blob: Option<Vec<u8>>,
) -> std::result::Result<Vec<Vec<u8>>, String> {
    let mut blob = blob;
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            ::gltf::buffer::Source::Bin => {
                blob.take().ok_or_else(|| format!("buffer {i}: the GLB has no BIN chunk to hold it"))?
            }
            ::gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                ::gltf::buffer::Data::from_source_and_blob(buffer.source(), None, &mut None)
                    .map_err(|e| format!("buffer {i}: bad data URI: {e}"))?
                    .0
            }
            ::gltf::buffer::Source::Uri(uri) => {
                let path = resolve(uri, base).map_err(|why| format!("buffer {i}: URI '{}' {why}", printable(uri)))?;
                read_regular(&path, buffer.length())
                    .map_err(|why| format!("buffer {i}: '{}' {why}", printable(&path.display().to_string())))?
            }
        };
        if data.len() < buffer.length() {
            return Err(format!("buffer {i}: declares {} bytes, but only {} were found", buffer.length(), data.len()));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The file a buffer URI names: a relative reference, percent-decoded, inside `base` after
/// every `..` and symbolic link is resolved. Anything else (an absolute path, a `file:` URI,
/// a way out of the folder) is refused unless [`allow_outside_uris`]; other schemes always are.
fn resolve(uri: &str, base: Option<&Path>) -> std::result::Result<PathBuf, String> {
    let allowed = ALLOW_OUTSIDE_URIS.load(Ordering::Relaxed);
    let (scheme, rest) = match uri.split_once(':') {
        // A colon before any slash is a scheme (RFC 3986); `C:` on Windows is one too.
        Some((scheme, rest)) if !scheme.contains('/') => (Some(scheme.to_ascii_lowercase()), rest),
        _ => (None, uri),
    };
    let decoded = percent_decode(rest).ok_or("has percent-escapes that are not UTF-8")?;
    if decoded.contains('\0') {
        return Err("contains a NUL byte".into());
    }
    let path = match scheme.as_deref() {
        None => PathBuf::from(&decoded),
        Some("file") if allowed => PathBuf::from(file_uri_path(&decoded)?),
        Some("file") => return Err(format!("is a file: URI, which can name any file on disk; {HOW_TO_ALLOW}")),
        Some(other) => return Err(format!("has the scheme '{other}:'; only files beside the model are read")),
    };
    if path.is_absolute() {
        return if allowed {
            Ok(path)
        } else {
            Err(format!("is an absolute path, outside the model's folder; {HOW_TO_ALLOW}"))
        };
    }
    let Some(base) = base else {
        return Err("names an external file, but the model has no folder to read it from".into());
    };
    // A model named without a folder (`model.gltf`) lives in the current one.
    let base = if base.as_os_str().is_empty() { Path::new(".") } else { base };
    let joined = base.join(&path);
    if allowed {
        return Ok(joined);
    }
    let folder = base.canonicalize().map_err(|e| format!("cannot be resolved: the model's folder: {e}"))?;
    let target = joined.canonicalize().map_err(|e| format!("cannot be read ({}): {e}", joined.display()))?;
    if !target.starts_with(&folder) {
        return Err(format!("leads outside the model's folder (to {}); {HOW_TO_ALLOW}", target.display()));
    }
    Ok(target)
}

/// The path of a `file:` URI after the scheme: `///p` and `//localhost/p` name `/p`, as `/p`
/// does; another host cannot be read.
fn file_uri_path(rest: &str) -> std::result::Result<&str, String> {
    let Some(authority_and_path) = rest.strip_prefix("//") else {
        return Ok(rest);
    };
    let (host, path) = authority_and_path.split_at(authority_and_path.find('/').unwrap_or(authority_and_path.len()));
    if host.is_empty() || host.eq_ignore_ascii_case("localhost") {
        Ok(path)
    } else {
        Err(format!("names the host '{}'; only local files are read", printable(host)))
    }
}

/// At most `length` bytes of the regular file at `path`: devices, pipes and folders are
/// refused (a pipe would block forever, `/dev/zero` never ends), and a file shorter than
/// `length` is an error.
fn read_regular(path: &Path, length: usize) -> std::result::Result<Vec<u8>, String> {
    const NOT_A_FILE: &str = "is not a regular file (a device, a pipe or a folder); only files are read";
    let metadata = std::fs::metadata(path).map_err(|e| format!("cannot be read: {e}"))?;
    if !metadata.is_file() {
        return Err(NOT_A_FILE.into());
    }
    let file = std::fs::File::open(path).map_err(|e| format!("cannot be read: {e}"))?;
    // Checked again on what was opened, in case the name changed hands in between.
    if !file.metadata().is_ok_and(|m| m.is_file()) {
        return Err(NOT_A_FILE.into());
    }
    let mut data = Vec::with_capacity(length.min(metadata.len() as usize));
    file.take(length as u64).read_to_end(&mut data).map_err(|e| format!("cannot be read: {e}"))?;
    if data.len() < length {
        return Err(format!("holds {} bytes, but the buffer declares {length}", data.len()));
    }
    Ok(data)
}

/// `text` with its `%XX` escapes decoded, if the result is UTF-8.
fn percent_decode(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut decoded = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let escaped = bytes
            .get(i + 1..i + 3)
            .filter(|_| bytes[i] == b'%')
            .and_then(|hex| std::str::from_utf8(hex).ok())
            .and_then(|hex| u8::from_str_radix(hex, 16).ok());
        match escaped {
            Some(byte) => {
                decoded.push(byte);
                i += 3;
            }
            None => {
                decoded.push(bytes[i]);
                i += 1;
            }
        }
    }
    String::from_utf8(decoded).ok()
}
