//! Reading a mesh file of any supported format into a [`Mesh`].
//!
//! The format is chosen by the file's extension, not sniffed from its content: a user who names a
//! file `x.ply` expects it to be read as PLY, and an error that says "not a PLY file" is clearer
//! than one from whichever parser a guess picked. Every reader validates while it reads, so a
//! broken file gives an [`Error::Input`] naming the file and the line, element or accessor.

use std::path::Path;

use crate::error::{Error, Result};
use crate::mesh::{Mesh, gltf, obj, ply};

/// What a reader had to leave out of the mesh because the file holds it in a form the [`Mesh`]
/// cannot carry (an attribute only some vertices have, line primitives, unknown PLY elements).
/// Readers never drop anything silently: each entry is one human-readable sentence.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoadReport {
    pub dropped: Vec<String>,
    /// The file's draw calls as ranges of the mesh's triangles, in order: one per glTF primitive
    /// instance, per run of OBJ faces between statements that set a group, material or
    /// smoothing group, one for a PLY. What an engine draws separately, and so what `order`
    /// reorders each on its own.
    pub draw_calls: Vec<std::ops::Range<usize>>,
}

/// Loads `path`, printing on stderr a warning for each thing the reader had to leave out.
///
/// This is the call for code that only wants the geometry; use [`load_file_with_report`] to
/// handle the warnings yourself.
pub fn load_file(path: &Path) -> Result<Mesh> {
    load_file_with_draw_calls(path).map(|(mesh, _)| mesh)
}

/// [`load_file`], and the file's draw calls ([`LoadReport::draw_calls`]).
pub fn load_file_with_draw_calls(path: &Path) -> Result<(Mesh, Vec<std::ops::Range<usize>>)> {
    let (mesh, report) = load_file_with_report(path)?;
    for dropped in &report.dropped {
        eprintln!("warning: {}: {dropped}", path.display());
    }
    Ok((mesh, report.draw_calls))
}

/// Loads `path` (`.obj`, `.ply`, `.glb` or `.gltf`, any case) and says what was left out. The
/// mesh's name is the path as given.
pub fn load_file_with_report(path: &Path) -> Result<(Mesh, LoadReport)> {
    let origin = path.display().to_string();
    let format = Format::of(path).map_err(|problem| Error::input(&origin, problem))?;
    let bytes = std::fs::read(path).map_err(|e| Error::input(&origin, format!("cannot read: {e}")))?;
    match format {
        Format::Obj => obj::read(&bytes, &origin),
        Format::Ply => ply::read(&bytes, &origin),
        Format::Glb => gltf::read(&bytes, &origin, path.parent(), true),
        Format::Gltf => gltf::read(&bytes, &origin, path.parent(), false),
    }
}

/// The file formats we read, as named by extension.
enum Format {
    Obj,
    Ply,
    /// Binary glTF: must start with the GLB magic.
    Glb,
    /// glTF JSON (or GLB: the `gltf` crate tells them apart by the magic).
    Gltf,
}

impl Format {
    fn of(path: &Path) -> std::result::Result<Format, String> {
        let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        match extension.as_deref() {
            Some("obj") => Ok(Format::Obj),
            Some("ply") => Ok(Format::Ply),
            Some("glb") => Ok(Format::Glb),
            Some("gltf") => Ok(Format::Gltf),
            Some(other) => Err(format!("unsupported file extension '.{other}' (supported: .obj, .ply, .glb, .gltf)")),
            None => Err("no file extension to tell the format by (supported: .obj, .ply, .glb, .gltf)".into()),
        }
    }
}
