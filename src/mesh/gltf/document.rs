//! Parsing a glTF or GLB file and loading its buffers, refusing first what makes the `gltf`
//! crate panic.

use std::path::Path;

use ::gltf::{Document, Gltf, Semantic};

use crate::error::{Error, Result};

/// Parses a glTF or GLB file and loads its buffers, refusing first the inputs that make the
/// `gltf` crate panic. Arguments as for [`read`].
pub(super) fn open(bytes: &[u8], origin: &str, base: Option<&Path>, binary: bool) -> Result<(Document, Vec<Vec<u8>>)> {
    let fail = |problem: String| Error::input(origin, problem);
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
/// its arithmetic).
fn check_glb_header(bytes: &[u8]) -> std::result::Result<(), String> {
    let word = |at: usize| bytes.get(at..at + 4).and_then(|b| b.try_into().ok()).map(u32::from_le_bytes);
    if bytes.is_empty() {
        return Err("not a GLB file: the file is empty".into());
    }
    let magic = bytes.get(..4).unwrap_or(bytes);
    if magic != b"glTF" {
        return Err(format!("not a GLB file: bad magic {:?} (expected \"glTF\")", String::from_utf8_lossy(magic)));
    }
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(format!("not a GLB file: {} bytes, shorter than the 12-byte GLB header", bytes.len()));
    };
    if version != 2 {
        return Err(format!("GLB version {version} is not supported (expected 2)"));
    }
    if (length as usize) < 20 || length as usize > bytes.len() {
        return Err(format!("GLB header: declared length {length} bytes, but the file has {} bytes", bytes.len()));
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

/// Each buffer's bytes, loaded one by one so an error can name the buffer.
fn load_buffers(
    document: &Document,
    base: Option<&Path>,
    blob: Option<Vec<u8>>,
) -> std::result::Result<Vec<Vec<u8>>, String> {
    let mut blob = blob;
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let i = buffer.index();
        if let ::gltf::buffer::Source::Uri(uri) = buffer.source()
            && !uri.contains(':')
            && !percent_decodes_to_utf8(uri)
        {
            return Err(format!("buffer {i}: URI '{uri}' has percent-escapes that are not UTF-8"));
        }
        let data = ::gltf::buffer::Data::from_source_and_blob(buffer.source(), base, &mut blob).map_err(|e| {
            match buffer.source() {
                ::gltf::buffer::Source::Uri(uri) if !uri.starts_with("data:") => {
                    let resolved = base.map_or_else(|| Path::new(uri).to_path_buf(), |b| b.join(uri));
                    format!("buffer {i}: cannot read '{uri}' ({}): {e}", resolved.display())
                }
                ::gltf::buffer::Source::Bin => {
                    format!("buffer {i}: the GLB has no BIN chunk to hold it")
                }
                ::gltf::buffer::Source::Uri(_) => format!("buffer {i}: {e}"),
            }
        })?;
        if data.len() < buffer.length() {
            return Err(format!("buffer {i}: declares {} bytes, but only {} were found", buffer.length(), data.len()));
        }
        buffers.push(data.0);
    }
    Ok(buffers)
}

/// Whether `uri`'s `%XX` escapes decode to valid UTF-8 (else the `gltf` crate panics on it).
fn percent_decodes_to_utf8(uri: &str) -> bool {
    let bytes = uri.as_bytes();
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
    String::from_utf8(decoded).is_ok()
}
