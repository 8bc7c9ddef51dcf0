//! Writing a [`Mesh`] to a file in the format its extension names.
//!
//! The writers live with their readers (`obj.rs`, `ply.rs`, `gltf.rs`); this module picks one
//! and hands it to [`crate::atomic::write_with`], so a failed save never leaves a truncated mesh
//! or a temporary file behind.

use std::io::Write;
use std::path::{Path, PathBuf};

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
    let write = writer(path)?;
    let mut dropped = Vec::new();
    crate::atomic::write_with(path, |out| {
        dropped = write(mesh, out)?;
        Ok(())
    })?;
    Ok(SaveReport { dropped })
}

/// What [`save`] would leave out of `mesh` in the format `path` names, found by encoding it into
/// nothing: for a caller that must know before it writes anything (`order --strict`).
pub fn would_drop(mesh: &Mesh, path: &Path) -> Result<Vec<String>> {
    let write = writer(path)?;
    write(mesh, &mut std::io::sink()).map_err(|e| Error::output(path, e))
}

type Writer = fn(&Mesh, &mut dyn Write) -> std::io::Result<Vec<String>>;

fn writer(path: &Path) -> Result<Writer> {
    match format_of(path) {
        Some(Format::Obj) => Ok(obj::write),
        Some(Format::Ply) => Ok(ply::write),
        Some(Format::Glb) => Ok(gltf::write),
        None => Err(Error::output(path, "unsupported file extension (supported: .obj, .ply, .glb)")),
    }
}

/// Writes the levels of a progressive mesh: `mesh`'s vertices with each level's triangles (a
/// name and triangles indexing those vertices, in draw order). A GLB holds them all, the
/// vertices once and an index buffer per level ([`gltf::write_levels`]); OBJ and PLY hold one
/// mesh, so level i goes to `STEM.leveli.EXT` beside `path`, each with every vertex, so a vertex
/// keeps its number at every level. All files are written or none ([`crate::atomic::write_all`]).
/// Returns what was dropped and the files written.
pub fn save_levels(mesh: &Mesh, levels: &[(String, Vec<[u32; 3]>)], path: &Path) -> Result<(SaveReport, Vec<PathBuf>)> {
    let write = writer(path)?;
    if format_of(path) == Some(Format::Glb) {
        let borrowed: Vec<(String, &[[u32; 3]])> = levels.iter().map(|(n, t)| (n.clone(), t.as_slice())).collect();
        crate::atomic::write_with(path, |out| gltf::write_levels(mesh, &borrowed, out).map(drop))?;
        return Ok((SaveReport::default(), vec![path.to_path_buf()]));
    }
    let paths: Vec<PathBuf> = (0..levels.len()).map(|i| level_path(path, i)).collect();
    let meshes: Vec<Mesh> =
        levels.iter().map(|(_, triangles)| Mesh { triangles: triangles.clone(), ..mesh.clone() }).collect();
    let dropped = std::cell::RefCell::new(Vec::new());
    let files = paths
        .iter()
        .zip(&meshes)
        .map(|(p, m)| {
            let dropped = &dropped;
            let fill: crate::atomic::Fill<'_> = Box::new(move |out| {
                let lost = write(m, out)?;
                let mut dropped = dropped.borrow_mut();
                lost.into_iter().for_each(|d| {
                    if !dropped.contains(&d) {
                        dropped.push(d)
                    }
                });
                Ok(())
            });
            (p.as_path(), fill)
        })
        .collect();
    crate::atomic::write_all(files)?;
    Ok((SaveReport { dropped: dropped.into_inner() }, paths))
}

/// `dir/STEM.leveli.EXT` for `dir/STEM.EXT`.
fn level_path(path: &Path, i: usize) -> PathBuf {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let extension = path.extension().unwrap_or_default().to_string_lossy();
    path.with_file_name(format!("{stem}.level{i}.{extension}"))
}
