//! Wavefront OBJ: reading (validated here, parsed by `tobj`) and writing.
//!
//! `tobj` does the parsing and builds the single index (one vertex per distinct
//! position/uv/normal index triple, which is what a GPU vertex cache sees), but on bad input its
//! errors name no line, and some bad input it accepts: a texture-coordinate or normal index of 0,
//! or any such index in a file with no `vt`/`vn` lines, is silently treated as absent,
//! `nan`/`inf` coordinates parse, a face of two
//! vertices silently vanishes, a non-numeric colour value silently shifts the colours of later
//! vertices, polylines (`l`) with three or more points become triangles, and a negative
//! texture-coordinate or normal index reaching before the first one wraps around and overflows its
//! index arithmetic (a panic in debug builds). So [`read`] first makes one light pass that checks
//! every line `tobj` will look at and stops at the first problem with its line number; only text
//! that passed is handed to `tobj`.
//!
//! That pass also hands `tobj` only the `v`, `vt`, `vn` and `f` lines. `tobj` splits the mesh at
//! `o`/`g` lines (and at `usemtl` when materials load) and numbers vertices per piece, which would
//! duplicate every vertex on a group boundary; without those lines it builds one index over the
//! whole file, in face order. Materials are never loaded: ordering needs no materials.

use std::io::{self, Write};

use glam::Vec3;

use crate::error::{Error, Result};
use crate::mesh::load::LoadReport;
use crate::mesh::{Mesh, VertexAttributes};

/// Reads OBJ text. Polygons are fan-triangulated from their first corner (what `tobj` does:
/// `a b c d e` becomes `a b c`, `a c d`, `a d e`). Vertices are numbered in order of first use
/// by the faces, so vertices no face uses are not kept. Normals, texture coordinates and vertex
/// colours are kept when every vertex has them, otherwise dropped and reported.
pub fn read(bytes: &[u8], origin: &str) -> Result<(Mesh, LoadReport)> {
    // Numbers and keywords are ASCII; a stray Latin-1 byte in a comment must not fail the file.
    // A UTF-8 byte-order mark would otherwise be read as part of the first keyword.
    let text = String::from_utf8_lossy(bytes.strip_prefix(crate::mesh::BOM).unwrap_or(bytes));
    if text.trim().is_empty() {
        return Err(Error::input(origin, "not an OBJ file: the file is empty"));
    }
    let checked = check(&text).map_err(|problem| Error::input(origin, problem))?;
    let mut report = LoadReport { dropped: checked.dropped, draw_calls: checked.draw_calls };

    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let no_materials = |_: &std::path::Path| Err(tobj::LoadError::OpenFileFailed);
    let (models, _) = tobj::load_obj_buf(&mut checked.text.as_bytes(), &options, no_materials)
        .map_err(|e| Error::input(origin, format!("OBJ parser: {e}")))?;

    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut colors = Vec::new();
    let mut triangles = Vec::new();
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        positions.extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        normals.extend(m.normals.chunks_exact(3).map(|n| [n[0], n[1], n[2]]));
        uvs.extend(m.texcoords.chunks_exact(2).map(|t| [t[0], t[1]]));
        colors.extend(m.vertex_color.chunks_exact(3).map(|c| [c[0], c[1], c[2], 1.0]));
        triangles.extend(m.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
    }
    let n = positions.len();
    let attributes = VertexAttributes {
        normals: keep_if_complete(normals, n, checked.counts.normals, "normals", "vn", &mut report),
        uvs: keep_if_complete(uvs, n, checked.counts.uvs, "texture coordinates", "vt", &mut report),
        colors: if colors.len() == n && n > 0 { Some(colors) } else { None },
        extra: Vec::new(),
    };
    // The draw calls count the triangles `tobj` makes of each face; should it ever make others,
    // the whole file is one draw call rather than ranges that point at the wrong triangles.
    if report.draw_calls.last().map(|r| r.end) != Some(triangles.len()) {
        report.draw_calls = std::iter::once(0..triangles.len()).collect();
    }
    Ok((Mesh::new(origin, positions, triangles, attributes)?, report))
}

/// `values` if every one of the `vertices` has one; otherwise `None`, noting in `report` why the
/// `defined` `keyword` lines of the file were not used.
fn keep_if_complete<T>(
    values: Vec<T>,
    vertices: usize,
    defined: usize,
    what: &str,
    keyword: &str,
    report: &mut LoadReport,
) -> Option<Vec<T>> {
    if values.len() == vertices {
        return Some(values);
    }
    if values.is_empty() {
        if defined > 0 {
            report.dropped.push(format!("{what}: the file has {defined} `{keyword}` lines but no face uses them"));
        }
    } else {
        report.dropped.push(format!(
            "{what}: only some face corners reference one ({} of {vertices} vertices have them)",
            values.len()
        ));
    }
    None
}

/// How many of each kind of line the file has.
#[derive(Default)]
struct Counts {
    positions: usize,
    uvs: usize,
    normals: usize,
    /// `v` lines that carry an RGB colour.
    colored: usize,
    faces: usize,
    polylines: usize,
    /// Lines whose keyword OBJ does not define, and where the first one is.
    unknown: usize,
    first_unknown: String,
}

/// The keywords of the OBJ specification (and `mtllib`'s companions) that carry no triangles:
/// skipped without a word. Any other keyword is counted and reported.
const OTHER_KEYWORDS: [&str; 32] = [
    "o",
    "g",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "usemap",
    "maplib",
    "vp",
    "p",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
];

/// The outcome of [`check`]: the lines `tobj` should see, what they leave out, and the draw calls.
struct Checked {
    text: String,
    counts: Counts,
    dropped: Vec<String>,
    draw_calls: Vec<std::ops::Range<usize>>,
}

/// Whether an OBJ keyword only describes data (vertices, faces, free-form points), so that faces
/// on either side of it share their group, material and smoothing group; any other statement
/// (`o`, `g`, `s`, `usemtl`, …) sets state, and ends a draw call.
pub(crate) fn keeps_state(keyword: &str) -> bool {
    matches!(keyword, "v" | "vt" | "vn" | "vp" | "f" | "l" | "p")
}

/// Checks every `v`, `vt`, `vn` and `f` line, returning them (only them) as new text, or the
/// first problem, starting with its line number.
fn check(text: &str) -> std::result::Result<Checked, String> {
    // Positive face indices may refer forward, so they are checked against the file's totals.
    let mut totals = Counts::default();
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals.positions += 1,
            Some("vt") => totals.uvs += 1,
            Some("vn") => totals.normals += 1,
            _ => {}
        }
    }

    let mut seen = Counts::default();
    let mut kept = String::with_capacity(text.len());
    let (mut draw_calls, mut triangles, mut call_start) = (Vec::new(), 0, 0);
    for (index, line) in text.lines().enumerate() {
        let at = |problem: String| format!("line {}: {problem}", index + 1);
        // `#` starts a comment anywhere on a line; what follows it is not data.
        let data = line.split_once('#').map_or(line, |(data, _)| data);
        let mut words = data.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
        if !keeps_state(keyword) && triangles > call_start {
            draw_calls.push(call_start..triangles);
            call_start = triangles;
        }
        let values: Vec<&str> = words.collect();
        match keyword {
            "v" => {
                check_vertex(&values).map_err(at)?;
                seen.positions += 1;
                seen.colored += usize::from(values.len() == 6);
            }
            "vt" => {
                // A third (w) component is allowed and ignored, as by `tobj`.
                check_numbers(values.get(..2), "a texture coordinate needs u and v").map_err(at)?;
                seen.uvs += 1;
            }
            "vn" => {
                check_numbers(values.get(..3), "a normal needs x, y and z").map_err(at)?;
                seen.normals += 1;
            }
            "f" => {
                if values.len() < 3 {
                    let s = if values.len() == 1 { "ex" } else { "ices" };
                    return Err(at(format!("face has {} vert{s}; a face needs at least 3", values.len())));
                }
                for corner in &values {
                    check_corner(corner, &seen, &totals).map_err(at)?;
                }
                seen.faces += 1;
                // `tobj` fans a polygon of n corners into n − 2 triangles.
                triangles += values.len() - 2;
            }
            "l" => {
                seen.polylines += 1;
                continue;
            }
            // Grouping, materials, smoothing groups, free-form geometry: not triangles.
            k if OTHER_KEYWORDS.contains(&k) => continue,
            unknown => {
                if seen.unknown == 0 {
                    seen.first_unknown = format!("`{}` on line {}", crate::error::printable(unknown), index + 1);
                }
                seen.unknown += 1;
                continue;
            }
        }
        kept.push_str(keyword);
        for value in &values {
            kept.push(' ');
            kept.push_str(value);
        }
        kept.push('\n');
    }

    if seen.faces == 0 {
        return Err(format!("no faces: the file has {} vertices and no `f` lines", seen.positions));
    }
    if triangles > call_start {
        draw_calls.push(call_start..triangles);
    }
    let mut dropped = Vec::new();
    if seen.unknown > 0 {
        dropped.push(format!(
            "{} line(s) with a keyword OBJ does not define, skipped (the first: {})",
            seen.unknown, seen.first_unknown
        ));
    }
    if seen.polylines > 0 {
        dropped.push(format!("{} polyline (`l`) elements: only faces are loaded", seen.polylines));
    }
    if seen.colored > 0 && seen.colored < seen.positions {
        dropped.push(format!("vertex colours: only {} of {} `v` lines have them", seen.colored, seen.positions));
        kept = strip_colors(&kept);
        seen.colored = 0;
    }
    Ok(Checked { text: kept, counts: seen, dropped, draw_calls })
}

/// `text` (as built by [`check`]) with every `v` line cut to its three coordinates.
fn strip_colors(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if line.starts_with("v ") {
            let coordinates: Vec<&str> = line.split(' ').take(4).collect();
            out.push_str(&coordinates.join(" "));
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// A `v` line's values: `x y z`, `x y z w` or `x y z r g b`, all finite, `w` not zero.
fn check_vertex(values: &[&str]) -> std::result::Result<(), String> {
    check_numbers(values.get(..3), "a vertex needs x, y and z")?;
    match values.len() {
        3 | 6 => check_numbers(values.get(3..), ""),
        4 => {
            let w = finite(values[3])?;
            if w == 0.0 {
                return Err("vertex weight w is 0".into());
            }
            for coordinate in &values[..3] {
                if !(finite(coordinate)? / w).is_finite() {
                    return Err(format!("coordinate {coordinate} divided by w = {w} is not finite"));
                }
            }
            Ok(())
        }
        n => Err(format!(
            "a vertex has 3 coordinates, optionally followed by w or by r g b, but this line has {n} values"
        )),
    }
}

/// Checks that `values` exist (else `missing`) and are all finite numbers.
fn check_numbers(values: Option<&[&str]>, missing: &str) -> std::result::Result<(), String> {
    let values = values.ok_or_else(|| missing.to_string())?;
    for value in values {
        finite(value)?;
    }
    Ok(())
}

/// Parses `token` as `tobj` will (an `f32`), requiring a finite value.
fn finite(token: &str) -> std::result::Result<f32, String> {
    let value: f32 = token.parse().map_err(|_| format!("'{token}' is not a number"))?;
    if value.is_finite() { Ok(value) } else { Err(format!("'{token}' is not a finite number")) }
}

/// Checks one face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`: indices present where needed,
/// integers, not 0, and inside the vertices/uvs/normals defined (so far, for negative ones).
fn check_corner(corner: &str, seen: &Counts, totals: &Counts) -> std::result::Result<(), String> {
    let parts: Vec<&str> = corner.split('/').collect();
    if parts.len() > 3 {
        return Err(format!("face corner '{corner}' has more than 3 indices"));
    }
    let kinds = [
        ("", "vertices", seen.positions, totals.positions),
        ("texture-coordinate ", "texture coordinates", seen.uvs, totals.uvs),
        ("normal ", "normals", seen.normals, totals.normals),
    ];
    for (part, (kind, plural, so_far, total)) in parts.iter().zip(kinds) {
        if part.is_empty() {
            if kind.is_empty() {
                return Err(format!("face corner '{corner}' has no vertex index"));
            }
            continue;
        }
        let index: i64 =
            part.parse().map_err(|_| format!("face {kind}index '{part}' in corner '{corner}' is not an integer"))?;
        let in_range = match index {
            0 => {
                return Err(format!("face {kind}index 0 is invalid (OBJ indices start at 1)"));
            }
            i if i < 0 => i.unsigned_abs() <= so_far as u64,
            i => i as u64 <= total as u64,
        };
        if !in_range {
            return Err(if index < 0 {
                format!("face {kind}index {index} is out of range ({so_far} {plural} defined so far)")
            } else {
                format!("face {kind}index {index} is out of range (the file defines {total} {plural})")
            });
        }
    }
    Ok(())
}

/// Writes `mesh` as OBJ with 1-based indices: `v x y z [r g b]`, `vt u v`, `vn x y z`, and one
/// `f` line per triangle in draw order, winding kept. Every vertex has its own `v` (and `vt`,
/// `vn`) line with the same number, so the corner triple is `i/i/i`. Floats are written with
/// Rust's shortest round-trip formatting, so reading the file back gives the same bits. Returns
/// what OBJ cannot hold: extra attributes and colour alpha (OBJ vertex colours are RGB).
pub fn write(mesh: &Mesh, out: &mut dyn Write) -> io::Result<Vec<String>> {
    let a = &mesh.attributes;
    let mut dropped: Vec<String> = a.extra.iter().map(|e| format!("vertex attribute '{}'", e.name)).collect();
    if a.colors.iter().flatten().any(|c| c[3] != 1.0) {
        dropped.push("colour alpha".into());
    }

    // The name may come from a path holding a newline, which would end the comment early.
    let name: String = mesh.name.chars().map(|c| if c.is_control() { ' ' } else { c }).collect();
    writeln!(
        out,
        "# {name}: {} vertices, {} triangles, written by triorder",
        mesh.vertex_count(),
        mesh.triangle_count()
    )?;
    for (i, p) in mesh.positions.iter().enumerate() {
        write!(out, "v {} {} {}", p.x, p.y, p.z)?;
        if let Some(c) = a.colors.as_ref().and_then(|c| c.get(i)) {
            write!(out, " {} {} {}", c[0], c[1], c[2])?;
        }
        writeln!(out)?;
    }
    for t in a.uvs.iter().flatten() {
        writeln!(out, "vt {} {}", t[0], t[1])?;
    }
    for n in a.normals.iter().flatten() {
        writeln!(out, "vn {} {} {}", n[0], n[1], n[2])?;
    }
    for t in &mesh.triangles {
        out.write_all(b"f")?;
        for i in t.map(|v| u64::from(v) + 1) {
            match (a.uvs.is_some(), a.normals.is_some()) {
                (false, false) => write!(out, " {i}")?,
                (true, false) => write!(out, " {i}/{i}")?,
                (false, true) => write!(out, " {i}//{i}")?,
                (true, true) => write!(out, " {i}/{i}/{i}")?,
            }
        }
        writeln!(out)?;
    }
    Ok(dropped)
}

/// One `f` line of a file, as [`reorder`] moves it.
struct FaceLine {
    /// Its line, as in the file (ending included).
    line: usize,
    /// The triangles it makes: n − 2 for n corners.
    triangles: usize,
    /// The draw call (run of faces between state statements) it belongs to.
    call: usize,
    /// How many `v`, `vt` and `vn` lines precede it: what its negative indices count back from.
    before: [i64; 3],
}

/// The OBJ `bytes` (a file [`read`] accepts) with its face lines in the order `order` gives: a
/// permutation of the triangles `read` returns, keeping each draw call's triangles within it
/// (`order::draw_calls` does). Everything else stays where it is, byte for byte: comments,
/// `mtllib`, `o`, `g`, `s`, `usemtl`, the vertex lines and their order, line endings. Each face
/// line moves whole (a polygon stays a polygon, placed where the order put its first triangle)
/// to a face slot of its own draw call, so every face keeps its object, group, material and
/// smoothing group. A face with negative (relative) indices that moves is written with the
/// absolute indices they meant. Returns the bytes and notes for the user.
pub fn reorder(bytes: &[u8], origin: &str, order: &[u32]) -> Result<(Vec<u8>, Vec<String>)> {
    let (mesh, _) = read(bytes, origin)?;
    crate::order::check_permutation(order, mesh.triangle_count())
        .map_err(|why| Error::input(origin, format!("the triangle order does not fit this file: {why}")))?;
    let body = bytes.strip_prefix(crate::mesh::BOM).unwrap_or(bytes);
    let lines: Vec<&[u8]> = body.split_inclusive(|&b| b == b'\n').collect();
    let mut faces: Vec<FaceLine> = Vec::new();
    let (mut counts, mut call, mut in_call) = ([0i64; 3], 0, false);
    for (i, line) in lines.iter().enumerate() {
        let text = String::from_utf8_lossy(line);
        let data = text.split_once('#').map_or(&*text, |(data, _)| data);
        let mut words = data.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        match keyword {
            "v" => counts[0] += 1,
            "vt" => counts[1] += 1,
            "vn" => counts[2] += 1,
            "f" => {
                faces.push(FaceLine { line: i, triangles: words.count() - 2, call, before: counts });
                in_call = true;
            }
            k if !keeps_state(k) && in_call => {
                call += 1;
                in_call = false;
            }
            _ => {}
        }
    }
    // Each triangle's face, then the faces in the order of their first triangle.
    let face_of: Vec<usize> =
        faces.iter().enumerate().flat_map(|(f, face)| std::iter::repeat_n(f, face.triangles)).collect();
    if face_of.len() != order.len() {
        return Err(Error::input(origin, "the faces do not make the triangles the reader found".to_string()));
    }
    let mut placed = vec![false; faces.len()];
    let mut sequence = Vec::with_capacity(faces.len());
    for &t in order {
        let f = face_of[t as usize];
        if !std::mem::replace(&mut placed[f], true) {
            sequence.push(f);
        }
    }
    let mut out = Vec::with_capacity(bytes.len());
    out.extend_from_slice(&bytes[..bytes.len() - body.len()]);
    // Face slot k (the k-th face line of the file) takes the k-th face of the new sequence.
    let mut k = 0;
    for (i, line) in lines.iter().enumerate() {
        if faces.get(k).is_none_or(|slot| slot.line != i) {
            out.extend_from_slice(line);
            continue;
        }
        let (slot, face) = (&faces[k], &faces[sequence[k]]);
        k += 1;
        if face.call != slot.call {
            return Err(Error::input(origin, "the order moves a face out of its draw call (group, material)"));
        }
        // The face's text, with the slot's own line ending: a file's line endings stay put.
        let content = moved_face(lines[face.line], face.before, face.line != slot.line);
        out.extend_from_slice(&content[..without_ending(&content)]);
        out.extend_from_slice(&line[without_ending(line)..]);
    }
    let mut notes = Vec::new();
    let polygons = faces.iter().filter(|f| f.triangles > 1).count();
    if polygons > 0 {
        notes.push(format!(
            "{polygons} polygon(s) (faces of more than 3 corners) kept whole: each is drawn where the order placed its first triangle ({} had been spread apart by the order)",
            spread(order, &faces, &face_of)
        ));
    }
    Ok((out, notes))
}

/// The length of `line` without its line ending.
fn without_ending(line: &[u8]) -> usize {
    line.len() - line.iter().rev().take_while(|&&b| b == b'\n' || b == b'\r').count()
}

/// How many polygons of `faces` (with `face_of` each triangle's face) `order` does not draw in one
/// run of consecutive triangles.
fn spread(order: &[u32], faces: &[FaceLine], face_of: &[usize]) -> usize {
    let mut at: Vec<Vec<usize>> = faces.iter().map(|f| Vec::with_capacity(f.triangles)).collect();
    for (rank, &t) in order.iter().enumerate() {
        at[face_of[t as usize]].push(rank);
    }
    at.iter().filter(|ranks| ranks.len() > 1 && ranks.windows(2).any(|w| w[1] != w[0] + 1)).count()
}

/// A face line as written at its new place: as it was, unless it moved and counts back from its
/// old place (negative indices), which are then made absolute.
fn moved_face(line: &[u8], before: [i64; 3], moved: bool) -> Vec<u8> {
    let text = String::from_utf8_lossy(line);
    let (data, comment) = text.split_once('#').map_or((&*text, None), |(d, c)| (d, Some(c)));
    if !moved || !data.contains('-') {
        return line.to_vec();
    }
    let absolute = |corner: &str| {
        corner
            .split('/')
            .enumerate()
            .map(|(k, part)| match part.parse::<i64>() {
                Ok(i) if i < 0 => (before[k.min(2)] + 1 + i).to_string(),
                _ => part.to_string(),
            })
            .collect::<Vec<_>>()
            .join("/")
    };
    let corners: Vec<String> = data.split_whitespace().skip(1).map(absolute).collect();
    let mut out = format!("f {}", corners.join(" "));
    if let Some(comment) = comment {
        out.push_str(&format!(" #{comment}"));
    }
    out.into_bytes()
}
