//! Writing a [`Mesh`] to a file in the format its extension names.
//!
//! The writers live with their readers (`obj.rs`, `ply.rs`, `gltf.rs`); this module picks one
//! and hands it to [`crate::atomic::write_with`], so a failed save never leaves a truncated mesh
//! or a temporary file behind.

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::mesh::{Mesh, gltf, obj, ply};

/// What the chosen format could not hold. Saving never loses anything silently: each entry names
/// an attribute (or a precision) that is missing from the file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SaveReport {
    pub dropped: Vec<String>,
}

/// The formats [`save`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Obj,
    /// Binary little-endian PLY.
    Ply,
    Glb,
}

/// The format `path`'s extension (any case) names, if [`save`] can write it. Lets a command
/// refuse a bad output name before doing the work whose result it would save.
pub fn format_of(path: &Path) -> Option<Format> {
    let extension = path.extension()?.to_string_lossy().to_ascii_lowercase();
    match extension.as_str() {
        "obj" => Some(Format::Obj),
        "ply" => Some(Format::Ply),
        "glb" => Some(Format::Glb),
        _ => None,
    }
}

/// Writes `mesh` to `path` as OBJ, binary PLY or GLB, chosen by [`format_of`]. Triangle order
/// and winding are written exactly as in the mesh. On error nothing is left behind: neither a
/// partial target nor a temporary file.
pub fn save(mesh: &Mesh, path: &Path) -> Result<SaveReport> {
    type Writer = fn(&Mesh, &mut dyn Write) -> std::io::Result<Vec<String>>;
    let write: Writer = match format_of(path) {
        Some(Format::Obj) => obj::write,
        Some(Format::Ply) => ply::write,
        Some(Format::Glb) => gltf::write,
        None => {
            return Err(Error::output(path, "unsupported file extension (supported: .obj, .ply, .glb)"));
        }
    };
    let mut dropped = Vec::new();
    crate::atomic::write_with(path, |out| {
        dropped = write(mesh, out)?;
        Ok(())
    })?;
    Ok(SaveReport { dropped })
}
