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
    let mut report = LoadReport { dropped: checked.dropped };

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

/// The outcome of [`check`]: the lines `tobj` should see, and what they leave out.
struct Checked {
    text: String,
    counts: Counts,
    dropped: Vec<String>,
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
    for (index, line) in text.lines().enumerate() {
        let at = |problem: String| format!("line {}: {problem}", index + 1);
        // `#` starts a comment anywhere on a line; what follows it is not data.
        let data = line.split_once('#').map_or(line, |(data, _)| data);
        let mut words = data.split_whitespace();
        let Some(keyword) = words.next() else {
            continue;
        };
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
    Ok(Checked { text: kept, counts: seen, dropped })
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
