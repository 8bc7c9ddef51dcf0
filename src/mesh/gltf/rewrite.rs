//! Reordering a glTF asset in place: the same asset, only faster to draw.
//!
//! An engine's asset holds far more than a mesh (nodes, skins, animations, morph targets,
//! materials, textures, cameras, extensions), and a mesh optimizer's first promise is to keep all
//! of it. So nothing is rebuilt here: each triangle primitive is ordered on its own (it is one
//! draw call), and only bytes change. An indexed primitive's new order is written over its index
//! accessor, same type, same place; a non-indexed one's vertex triples are permuted, every
//! attribute and morph target together; with `remap`, an indexed primitive's vertices are
//! renumbered in order of first use and every attribute and morph target of it permuted the same
//! way. Counts, types and bounds stay what they were, so the JSON needs no change and the
//! buffers are as compact as before: a GLB comes out the same size, with the same JSON chunk.
//!
//! A primitive whose data cannot be rewritten in place (another mode than triangles, indices or
//! attributes shared with another primitive, sparse accessors) is kept as it is, with a note
//! saying which and why. An asset whose geometry is compressed (Draco, meshopt) is refused: its
//! compressed copy would no longer match.

use std::path::Path;

use ::gltf::Semantic;
use ::gltf::mesh::Mode;

use super::accessors::{element_offsets, read_indices, read_vectors};
use super::document::open;
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Extensions that store geometry compressed: an in-place rewrite would leave them stale.
const COMPRESSED: &[&str] = &["KHR_draco_mesh_compression", "EXT_meshopt_compression", "KHR_meshopt_compression"];

/// A rewritten asset.
#[derive(Debug, Clone)]
pub struct Rewritten {
    /// The file itself: the GLB, or the `.gltf` JSON.
    pub main: Vec<u8>,
    /// The external buffers a `.gltf` refers to, to write beside it: (file name, bytes).
    pub beside: Vec<(String, Vec<u8>)>,
    /// How many primitives were reordered.
    pub reordered: usize,
    /// Primitives kept in their order and why, and what else changed.
    pub notes: Vec<String>,
}

/// Rewrites the glTF or GLB `bytes` (read from `origin`, external files from `base`; `binary`:
/// named `.glb`) with each triangle primitive in the order `order` gives for it (a permutation of
/// its triangles, given the primitive as a mesh), renumbering vertices too when `remap`. `out`
/// names the output: external buffers are written beside it as `STEM.bin` (`STEM-N.bin` for
/// buffer N > 0), and external image URIs are made relative to its folder.
pub fn rewrite(
    bytes: &[u8],
    origin: &str,
    base: Option<&Path>,
    binary: bool,
    out: &Path,
    remap: bool,
    order: &mut dyn FnMut(Mesh) -> Result<Vec<u32>>,
) -> Result<Rewritten> {
    let fail = |problem: String| Error::input(origin, problem);
    let (document, original) = open(bytes, origin, base, binary)?;
    if let Some(ext) = document.extensions_used().find(|e| COMPRESSED.contains(e)) {
        return Err(fail(format!(
            "uses {ext}: its geometry is compressed, and a reordered copy would no longer match it; \
             decompress the asset first (gltf-transform or gltfpack can), then reorder it"
        )));
    }
    let mut buffers = original.clone();
    // How many primitives use each accessor: what may be rewritten for one primitive alone.
    let mut uses = vec![0usize; document.accessors().len()];
    for primitive in document.meshes().flat_map(|m| m.primitives()) {
        for accessor in accessors_of(&primitive) {
            uses[accessor] += 1;
        }
        if let Some(indices) = primitive.indices() {
            uses[indices.index()] += 1;
        }
    }
    let mut notes = Vec::new();
    let mut reordered = 0;
    for mesh in document.meshes() {
        for primitive in mesh.primitives() {
            let at = format!("mesh {} primitive {}", mesh.index(), primitive.index());
            match reorder_primitive(&primitive, &at, origin, &mut buffers, &uses, remap, order)? {
                Some(note) => notes.push(format!("{at}: {note}")),
                None => reordered += 1,
            }
        }
    }
    let (main, beside) = assemble(bytes, &document, &original, buffers, binary, base, out).map_err(fail)?;
    Ok(Rewritten { main, beside, reordered, notes })
}

/// The accessors of `primitive`'s vertices: its attributes and its morph targets'.
fn accessors_of(primitive: &::gltf::Primitive<'_>) -> Vec<usize> {
    let mut all: Vec<usize> = primitive.attributes().map(|(_, a)| a.index()).collect();
    for target in primitive.morph_targets() {
        all.extend(target.positions().into_iter().chain(target.normals()).chain(target.tangents()).map(|a| a.index()));
    }
    all
}

/// Orders one primitive and writes it into `buffers`; `Some(why)` when it is kept as it is.
fn reorder_primitive(
    primitive: &::gltf::Primitive<'_>,
    at: &str,
    origin: &str,
    buffers: &mut [Vec<u8>],
    uses: &[usize],
    remap: bool,
    order: &mut dyn FnMut(Mesh) -> Result<Vec<u32>>,
) -> Result<Option<String>> {
    let fail = |problem: String| Error::input(origin, format!("{at}: {problem}"));
    if primitive.mode() != Mode::Triangles {
        return Ok(Some(format!("kept in its order: it draws {:?}, not a triangle list", primitive.mode())));
    }
    let position = primitive.get(&Semantic::Positions).ok_or_else(|| fail("has no POSITION attribute".into()))?;
    let positions: Vec<glam::Vec3> = read_vectors::<3>(&position, buffers, "POSITION")
        .map_err(fail)?
        .into_iter()
        .map(glam::Vec3::from_array)
        .collect();
    let n = positions.len();
    let indices = primitive.indices();
    let corners: Vec<u32> = match &indices {
        Some(accessor) if uses[accessor.index()] > 1 => {
            return Ok(Some("kept in its order: its index accessor is shared with another primitive".into()));
        }
        Some(accessor) => read_indices(accessor, buffers, n).map_err(fail)?,
        None => (0..n as u32).collect(),
    };
    let triangles: Vec<[u32; 3]> = corners.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    if triangles.len() < 2 {
        return Ok(Some(format!("kept: {} triangle(s), nothing to order", triangles.len())));
    }
    let vertices = accessors_of(primitive);
    let own_vertices = vertices.iter().all(|&a| uses[a] == 1);
    let vertex_offsets = || {
        let document_accessors = primitive.attributes().map(|(_, a)| a).chain(
            primitive
                .morph_targets()
                .flat_map(|t| t.positions().into_iter().chain(t.normals()).chain(t.tangents()).collect::<Vec<_>>()),
        );
        document_accessors.map(|a| element_offsets(&a, buffers)).collect::<std::result::Result<Vec<_>, String>>()
    };
    if indices.is_none() && !own_vertices {
        return Ok(Some(
            "kept in its order: it has no indices and shares its vertex data with another primitive".into(),
        ));
    }
    let mesh = Mesh::new(format!("{origin}: {at}"), positions, triangles.clone(), Default::default())?;
    let permutation = order(mesh)?;
    let mut drawn: Vec<[u32; 3]> = permutation.iter().map(|&t| triangles[t as usize]).collect();
    let mut note = None;
    // Vertices to move, as old ids in their new order: a non-indexed primitive's triples follow
    // the triangles; with `remap`, an indexed one's follow their first use.
    let moved: Option<Vec<u32>> = match (&indices, remap) {
        (None, _) => Some(
            permutation
                .iter()
                .flat_map(|&t| [3 * t, 3 * t + 1, 3 * t + 2])
                .chain(3 * triangles.len() as u32..n as u32)
                .collect(),
        ),
        (Some(_), true) if own_vertices => Some(first_use(&drawn, n)),
        (Some(_), true) => {
            note = Some("reordered, vertices not renumbered: its vertex data is shared with another primitive".into());
            None
        }
        (Some(_), false) => None,
    };
    if let Some(old_of_new) = &moved {
        let offsets = match vertex_offsets() {
            Ok(offsets) => offsets,
            Err(why) => return Ok(Some(format!("kept in its order: {why}"))),
        };
        for (buffer, elements, size) in offsets {
            permute(&mut buffers[buffer], &elements, size, old_of_new);
        }
        let mut new_of_old = vec![0u32; n];
        for (new, &old) in old_of_new.iter().enumerate() {
            new_of_old[old as usize] = new as u32;
        }
        drawn.iter_mut().for_each(|t| *t = t.map(|v| new_of_old[v as usize]));
    }
    if let Some(accessor) = &indices {
        let (buffer, elements, size) = element_offsets(accessor, buffers).map_err(fail)?;
        for (&at, value) in elements.iter().zip(drawn.iter().flatten()) {
            let bytes = value.to_le_bytes();
            buffers[buffer][at..at + size].copy_from_slice(&bytes[..size]);
        }
    }
    Ok(note)
}

/// Old vertex ids in order of first use by `triangles`, then the unused ones in their order.
fn first_use(triangles: &[[u32; 3]], n: usize) -> Vec<u32> {
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for &v in triangles.iter().flatten().chain(&(0..n as u32).collect::<Vec<_>>()) {
        if !std::mem::replace(&mut seen[v as usize], true) {
            order.push(v);
        }
    }
    order
}

/// Moves the elements of `size` bytes at `offsets` in `buffer` so that element `i` becomes what
/// element `old_of_new[i]` was.
fn permute(buffer: &mut [u8], offsets: &[usize], size: usize, old_of_new: &[u32]) {
    let old: Vec<u8> = offsets.iter().flat_map(|&at| buffer[at..at + size].to_vec()).collect();
    for (&at, &from) in offsets.iter().zip(old_of_new) {
        let from = from as usize * size;
        buffer[at..at + size].copy_from_slice(&old[from..from + size]);
    }
}

/// Files to write beside a `.gltf`: (file name, bytes).
type Beside = Vec<(String, Vec<u8>)>;

/// The output file and the buffers to write beside it. A GLB keeps its bytes but for the BIN
/// chunk's; JSON changes only where a buffer or image lives outside the file: each external
/// buffer is written beside the output, and each external image URI made relative to its folder.
fn assemble(
    bytes: &[u8],
    document: &::gltf::Document,
    original: &[Vec<u8>],
    buffers: Vec<Vec<u8>>,
    binary: bool,
    base: Option<&Path>,
    out: &Path,
) -> std::result::Result<(Vec<u8>, Beside), String> {
    let stem = out.file_stem().map_or("out".to_string(), |s| s.to_string_lossy().into_owned());
    let mut json: Option<serde_json::Value> = None;
    let mut edit = |path: &[&str], index: usize, value: String| -> std::result::Result<(), String> {
        // The file's own JSON, not the `gltf` crate's model of it, which drops what it does not
        // know (extensions, extras of some objects) and adds defaults.
        let root = match &mut json {
            Some(root) => root,
            None => json.insert(serde_json::from_slice(json_text(bytes, binary)).map_err(|e| e.to_string())?),
        };
        let slot = root.get_mut(path[0]).and_then(|a| a.get_mut(index)).and_then(|o| o.as_object_mut());
        slot.ok_or("the JSON does not hold what it declared")?.insert(path[1].to_string(), value.into());
        Ok(())
    };
    let mut beside = Vec::new();
    let mut bin = None;
    for (buffer, data) in document.buffers().zip(buffers) {
        let i = buffer.index();
        match buffer.source() {
            ::gltf::buffer::Source::Bin => bin = Some(data),
            ::gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                if data != original[i] {
                    use base64::Engine;
                    let encoded = base64::engine::general_purpose::STANDARD.encode(&data);
                    edit(&["buffers", "uri"], i, format!("data:application/octet-stream;base64,{encoded}"))?;
                }
            }
            ::gltf::buffer::Source::Uri(_) => {
                let name = if i == 0 { format!("{stem}.bin") } else { format!("{stem}-{i}.bin") };
                edit(&["buffers", "uri"], i, name.clone())?;
                beside.push((name, data));
            }
        }
    }
    let out_dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    for image in document.images() {
        if let ::gltf::image::Source::Uri { uri, .. } = image.source()
            && !uri.starts_with("data:")
            && let Some(base) = base
        {
            let target = base.join(uri);
            if let Some(relative) = relative_to(out_dir, &target)
                && relative != uri
            {
                edit(&["images", "uri"], image.index(), relative)?;
            }
        }
    }
    let main = match (binary, json) {
        (false, None) => bytes.to_vec(),
        (false, Some(json)) => serde_json::to_vec_pretty(&json).map_err(|e| e.to_string())?,
        (true, json) => glb(bytes, json, bin)?,
    };
    Ok((main, beside))
}

/// The JSON text of a glTF file: a GLB's first chunk, or the file itself.
fn json_text(bytes: &[u8], binary: bool) -> &[u8] {
    let bytes = bytes.strip_prefix(crate::mesh::BOM).unwrap_or(bytes);
    if !binary && !bytes.starts_with(b"glTF") {
        return bytes;
    }
    let length = bytes.get(12..16).map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    bytes.get(20..20 + length).unwrap_or_default()
}

/// The GLB `bytes` with its BIN chunk's buffer replaced by `bin`, and its JSON chunk by `json`
/// when that changed; chunks are padded to 4 bytes as the format requires.
fn glb(bytes: &[u8], json: Option<serde_json::Value>, bin: Option<Vec<u8>>) -> std::result::Result<Vec<u8>, String> {
    let word = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let mut chunks: Vec<(u32, Vec<u8>)> = Vec::new();
    let mut at = 12;
    while at + 8 <= bytes.len() {
        let (length, kind) = (word(at).unwrap_or(0), word(at + 4).unwrap_or(0) as u32);
        let data = bytes.get(at + 8..at + 8 + length).ok_or("a GLB chunk runs past the end of the file")?;
        chunks.push((kind, data.to_vec()));
        at += 8 + length;
    }
    const JSON: u32 = 0x4E4F_534A;
    const BIN: u32 = 0x004E_4942;
    for (kind, data) in &mut chunks {
        if *kind == JSON
            && let Some(json) = &json
        {
            *data = serde_json::to_vec(json).map_err(|e| e.to_string())?;
            while data.len() % 4 != 0 {
                data.push(b' ');
            }
        }
        if *kind == BIN
            && let Some(bin) = &bin
        {
            data[..bin.len()].copy_from_slice(bin);
        }
    }
    let total = 12 + chunks.iter().map(|(_, d)| 8 + d.len()).sum::<usize>();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&bytes[..8]);
    out.extend_from_slice(&(total as u32).to_le_bytes());
    for (kind, data) in chunks {
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(&kind.to_le_bytes());
        out.extend_from_slice(&data);
    }
    Ok(out)
}

/// `target` as a relative URI from the folder `from` (both resolved), if both exist.
fn relative_to(from: &Path, target: &Path) -> Option<String> {
    let (from, target) = (from.canonicalize().ok()?, target.canonicalize().ok()?);
    let common = from.components().zip(target.components()).take_while(|(a, b)| a == b).count();
    let ups = from.components().count() - common;
    let parts: Vec<String> = std::iter::repeat_n("..".to_string(), ups)
        .chain(target.components().skip(common).map(|c| c.as_os_str().to_string_lossy().into_owned()))
        .collect();
    Some(parts.join("/"))
}

/// What the glTF or GLB `bytes` hold beyond one mesh of positions, normals, texture coordinates
/// and colours: what a conversion to OBJ or PLY leaves behind, one entry each, empty when
/// nothing is.
pub fn contents(bytes: &[u8], origin: &str, base: Option<&Path>, binary: bool) -> Result<Vec<String>> {
    let (document, _) = open(bytes, origin, base, binary)?;
    let primitives = document.meshes().map(|m| m.primitives().len()).sum::<usize>();
    let morphed = document.meshes().flat_map(|m| m.primitives()).filter(|p| p.morph_targets().len() > 0).count();
    let counted = [
        (document.nodes().len().saturating_sub(1), "more node(s) of the node hierarchy (transforms applied)"),
        (primitives.saturating_sub(1), "more primitive(s): draw calls merged into one"),
        (document.skins().len(), "skin(s) (posed at rest)"),
        (document.animations().len(), "animation(s)"),
        (morphed, "primitive(s) with morph targets"),
        (document.materials().len(), "material(s)"),
        (document.textures().len(), "texture(s)"),
        (document.images().len(), "image(s)"),
        (document.cameras().len(), "camera(s)"),
    ];
    let mut held: Vec<String> = counted.iter().filter(|(n, _)| *n > 0).map(|(n, what)| format!("{n} {what}")).collect();
    let extensions: Vec<&str> = document.extensions_used().collect();
    if !extensions.is_empty() {
        held.push(format!("extensions {}", extensions.join(", ")));
    }
    Ok(held)
}
