//! Stanford PLY: reading (ascii, binary little and big endian, via `ply-rs-bw`), writing
//! (binary little endian), and [`reorder`]ing a file's faces in place, which keeps what `read`
//! drops (face properties, other elements) so that an ordered file is the same asset.
//!
//! `ply-rs-bw` parses the header and decodes one element at a time; it returns errors, not
//! panics, on truncated or malformed payloads (tested in `tests/bad_input.rs`). Driving it one
//! element at a time lets every error say which element failed (`vertex 12`, `face 3`), and a
//! light scan of the header text of our own supplies header line numbers, which its header model
//! does not keep. Three things it accepts are checked here: a name declared twice in the header
//! (it keeps only the last, then misreads the payload), an ASCII line with more values than the
//! header declares (it ignores the rest), and non-finite or out-of-range values.

use std::io::{self, Write};
use std::ops::Range;

use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{ElementDef, Encoding, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType};

use crate::error::{Error, Result};
use crate::mesh::load::LoadReport;
use crate::mesh::{Mesh, NamedAttribute, VertexAttributes};

/// One decoded element: its property values in header order. `ply-rs-bw` calls the setter once
/// per property, in order, so position `i` is the element's `i`-th property.
struct Row(Vec<Property>);

impl PropertyAccess for Row {
    fn new() -> Self {
        Row(Vec::new())
    }

    fn set_property(&mut self, _name: &str, property: Property) -> PropertyAccessResult {
        self.0.push(property);
        PropertyAccessResult::Set
    }
}

/// The texture-coordinate property pairs in use, in the order we look for them.
const UV_NAMES: [(&str, &str); 4] = [("s", "t"), ("u", "v"), ("texture_u", "texture_v"), ("texture_s", "texture_t")];

/// Reads a PLY file. The `vertex` element needs scalar `x`, `y`, `z`; `nx ny nz`, a UV pair
/// ([`UV_NAMES`]) and `red green blue [alpha]` become normals, UVs and colours; every other
/// scalar vertex property is kept as a [`NamedAttribute`]. The `face` element's
/// `vertex_indices` (or `vertex_index`) integer list gives polygons, fan-triangulated from their
/// first vertex. Anything else (other elements, list or face properties) is reported as dropped.
pub fn read(bytes: &[u8], origin: &str) -> Result<(Mesh, LoadReport)> {
    let fail = |problem: String| Error::input(origin, problem);
    if bytes.is_empty() {
        return Err(fail("not a PLY file: the file is empty".into()));
    }
    // The header is text, which an editor may have saved with a UTF-8 byte-order mark.
    let bytes = bytes.strip_prefix(crate::mesh::BOM).unwrap_or(bytes);
    let first_line = bytes.split(|&b| b == b'\n').next().unwrap_or_default();
    if first_line.trim_ascii_end() != b"ply" {
        return Err(fail("not a PLY file: line 1 is not 'ply'".into()));
    }
    let header_text = HeaderText::scan(bytes);
    let mut rest = bytes;
    let parser = Parser::<Row>::new();
    let header = {
        let mut reader = ply_rs_bw::parser::Reader::new(&mut rest);
        parser.read_header(&mut reader).map_err(|e| {
            // Its message repeats the line number and the line's text; keep the first sentence.
            let message = e.to_string();
            let message = e.line().and_then(|n| message.strip_prefix(&format!("Line {n}: "))).unwrap_or(&message);
            let first = message.lines().next().unwrap_or_default();
            match e.line().and_then(|n| header_text.line(n).map(|text| (n, text))) {
                Some((n, text)) if first.starts_with("Couldn't parse line") => {
                    fail(format!("header line {n} ('{text}'): {}", explain_header_line(text)))
                }
                Some((n, text)) => fail(format!("header line {n} ('{text}'): {first}")),
                None => fail(format!("header: {first}")),
            }
        })?
    };
    header_text.check_duplicates().map_err(fail)?;
    let version = &header.version;
    if (version.major, version.minor) != (1, 0) {
        let line = header_text.words().find(|(_, w)| w.first() == Some(&"format")).map_or(2, |(n, _)| n);
        return Err(fail(format!(
            "header line {line}: PLY format version {}.{} is not supported (the only PLY version is 1.0)",
            version.major, version.minor
        )));
    }

    let vertex_def = header.elements.get("vertex").ok_or_else(|| fail("header: no 'vertex' element".into()))?;
    let layout = VertexLayout::of(vertex_def, &header_text).map_err(fail)?;
    let face_def = header
        .elements
        .get("face")
        .ok_or_else(|| fail(format!("no faces: the header has no 'face' element ({} vertices)", vertex_def.count)))?;
    let face_list = face_list_index(face_def, &header_text).map_err(fail)?;

    let mut report = LoadReport::default();
    let mut payload = Payload { parser, encoding: header.encoding, rest, line: header_text.lines.len() + 1 };
    let mut vertices = Vec::new();
    let mut faces = Vec::new();
    for def in header.elements.values() {
        let rows = payload.read_element(def).map_err(fail)?;
        match def.name.as_str() {
            "vertex" => vertices = rows,
            "face" => faces = rows,
            other => report
                .dropped
                .push(format!("element '{other}' ({} entries): only vertices and faces are loaded", def.count)),
        }
    }

    let (positions, attributes) = layout.build(&vertices, &mut report).map_err(fail)?;
    for property in face_def.properties.keys().filter(|&name| *name != face_list.name) {
        report.dropped.push(format!("face property '{property}': only vertex indices are loaded"));
    }
    if face_def.count == 0 {
        return Err(fail(format!("no faces: element 'face' is empty ({} vertices)", positions.len())));
    }
    let triangles = triangulate(&faces, face_list.position, positions.len()).map_err(fail)?;
    report.draw_calls = std::iter::once(0..triangles.len()).collect();
    Ok((Mesh::new(origin, positions, triangles, attributes)?, report))
}

/// Reads the payload, one element at a time, after the header.
struct Payload<'a> {
    parser: Parser<Row>,
    encoding: Encoding,
    rest: &'a [u8],
    /// 1-based line number of the next ASCII line.
    line: usize,
}

impl Payload<'_> {
    /// All `def.count` entries of one element, or an error naming the entry that failed.
    fn read_element(&mut self, def: &ElementDef) -> std::result::Result<Vec<Row>, String> {
        // A count the file cannot hold must not size an allocation: every entry takes at least
        // one byte, unless the element has no properties.
        let mut rows = Vec::with_capacity(def.count.min(self.rest.len()));
        for i in 0..def.count {
            let row = match self.encoding {
                Encoding::Ascii => self.read_ascii(def, i)?,
                Encoding::BinaryLittleEndian => {
                    self.parser.read_little_endian_element(&mut self.rest, def).map_err(|e| binary_error(def, i, &e))?
                }
                Encoding::BinaryBigEndian => {
                    self.parser.read_big_endian_element(&mut self.rest, def).map_err(|e| binary_error(def, i, &e))?
                }
            };
            rows.push(row);
        }
        Ok(rows)
    }

    fn read_ascii(&mut self, def: &ElementDef, i: usize) -> std::result::Result<Row, String> {
        let at = format!("{} {i} (line {})", def.name, self.line);
        if self.rest.is_empty() {
            return Err(format!("{at}: the file ends before this element ({} declared)", def.count));
        }
        let end = self.rest.iter().position(|&b| b == b'\n').map_or(self.rest.len(), |n| n + 1);
        let (line, rest) = self.rest.split_at(end);
        self.rest = rest;
        self.line += 1;
        let line = std::str::from_utf8(line).map_err(|_| format!("{at}: the line is not text"))?;
        let row = self.parser.read_ascii_element(line, def).map_err(|e| {
            match line.split_ascii_whitespace().find(|t| !plain_number(t)) {
                Some(token) => format!("{at}: '{token}' is not a number"),
                None => {
                    format!("{at}: {}", explain_ascii_values(line, def).unwrap_or_else(|| one_line(&e.to_string())))
                }
            }
        })?;
        let expected: usize = row.0.iter().map(|p| list_len(p).map_or(1, |n| 1 + n)).sum();
        let found = line.split_ascii_whitespace().count();
        if found != expected {
            return Err(format!("{at}: {found} values, but the header declares {expected}"));
        }
        Ok(row)
    }
}

fn binary_error(def: &ElementDef, i: usize, e: &ply_rs_bw::parser::ParseError) -> String {
    if e.kind() == io::ErrorKind::UnexpectedEof {
        format!("{} {i}: the file ends inside this element ({} declared; truncated?)", def.name, def.count)
    } else {
        format!("{} {i}: {}", def.name, one_line(&e.to_string()))
    }
}

/// Whether `token` is a number as `ply-rs-bw` reads ASCII payloads: `[+-]digits[.digits][e[+-]digits]`
/// (so not `nan`, `inf`, `.5` or `5.`).
fn plain_number(token: &str) -> bool {
    let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
    let unsigned = |s: &str| s.strip_prefix(['+', '-']).unwrap_or(s).to_string();
    let token = unsigned(token);
    let (mantissa, exponent) = match token.split_once(['e', 'E']) {
        Some((m, e)) => (m, Some(unsigned(e))),
        None => (token.as_str(), None),
    };
    let mantissa_ok = match mantissa.split_once('.') {
        Some((whole, fraction)) => digits(whole) && digits(fraction),
        None => digits(mantissa),
    };
    mantissa_ok && exponent.is_none_or(|e| digits(&e))
}

/// What a header line that does not parse should look like, in place of `ply-rs-bw`'s
/// "Couldn't parse line." and its grammar's debug text.
fn explain_header_line(text: &str) -> String {
    const TYPES: [&str; 16] = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16", "uint16",
        "int32", "uint32", "float32", "float64",
    ];
    let words: Vec<&str> = text.split_whitespace().collect();
    // The type words: `property TYPE NAME`, or `property list COUNT_TYPE TYPE NAME`.
    let types = if words.get(1) == Some(&"list") { words.get(2..4) } else { words.get(1..2) };
    let unknown = types.unwrap_or_default().iter().find(|t| !TYPES.contains(t));
    match words.first().copied() {
        Some("format") => "a format line is 'format ascii|binary_little_endian|binary_big_endian 1.0'".into(),
        Some("element") => "an element line is 'element NAME COUNT', with COUNT a whole number".into(),
        Some("property") if unknown.is_some() => {
            format!("unknown property type '{}' (known: {})", unknown.unwrap_or(&""), TYPES.join(", "))
        }
        Some("property") => "a property line is 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'".into(),
        _ => "not a PLY header line (one of format, element, property, comment, obj_info, end_header)".into(),
    }
}

/// Why the ASCII `line` (whose tokens are all numbers) does not hold `def`'s values, in the
/// header's words, where `ply-rs-bw` would say `ParseIntError { kind: PosOverflow }` or speak of
/// "list elements": a value that does not fit its property's type, or a list longer than the
/// line.
fn explain_ascii_values(line: &str, def: &ElementDef) -> Option<String> {
    let mut tokens = line.split_ascii_whitespace();
    for (name, property) in def.properties.iter() {
        let (count_type, item_type) = match &property.data_type {
            PropertyType::Scalar(scalar) => (None, scalar),
            PropertyType::List(count, item) => (Some(count), item),
        };
        let count = match count_type {
            None => 1,
            Some(count_type) => {
                let token = tokens.next()?;
                if let Err(range) = fits(token, count_type) {
                    return Some(format!("list length '{token}' of '{name}' does not fit its type ({range})"));
                }
                token.parse::<usize>().ok()?
            }
        };
        for k in 0..count {
            let Some(token) = tokens.next() else {
                return Some(format!("the list '{name}' declares {count} values, but the line ends after {k}"));
            };
            if let Err(range) = fits(token, item_type) {
                return Some(format!("'{token}' does not fit the property '{name}' ({range})"));
            }
        }
    }
    None
}

/// Ok if the number `token` is a value of `scalar`; else the type's range, as words.
fn fits(token: &str, scalar: &ScalarType) -> std::result::Result<(), String> {
    let (min, max, name): (i128, i128, &str) = match scalar {
        ScalarType::Char => (i8::MIN.into(), i8::MAX.into(), "char"),
        ScalarType::UChar => (0, u8::MAX.into(), "uchar"),
        ScalarType::Short => (i16::MIN.into(), i16::MAX.into(), "short"),
        ScalarType::UShort => (0, u16::MAX.into(), "ushort"),
        ScalarType::Int => (i32::MIN.into(), i32::MAX.into(), "int"),
        ScalarType::UInt => (0, u32::MAX.into(), "uint"),
        ScalarType::Float | ScalarType::Double => return Ok(()),
    };
    match token.parse::<i128>() {
        Ok(v) if (min..=max).contains(&v) => Ok(()),
        _ => Err(format!("{name}: a whole number from {min} to {max}")),
    }
}

/// `ply-rs-bw` messages span several tab-indented lines; an error message is one line.
fn one_line(message: &str) -> String {
    message.split(['\n', '\t']).map(str::trim).filter(|s| !s.is_empty()).collect::<Vec<_>>().join("; ")
}

/// The header's lines (up to `end_header`), for line numbers and checks `ply-rs-bw` does not make.
struct HeaderText {
    lines: Vec<String>,
}

impl HeaderText {
    /// Headers are a few hundred bytes; looking no further than the first MiB keeps a binary file
    /// that lacks `end_header` from being turned into text whole.
    fn scan(bytes: &[u8]) -> HeaderText {
        let mut lines = Vec::new();
        for line in bytes[..bytes.len().min(1 << 20)].split(|&b| b == b'\n') {
            let line = String::from_utf8_lossy(line).trim_end().to_string();
            let end = line == "end_header";
            lines.push(line);
            if end {
                break;
            }
        }
        HeaderText { lines }
    }

    /// The text of 1-based line `n`.
    fn line(&self, n: usize) -> Option<&str> {
        self.lines.get(n.checked_sub(1)?).map(String::as_str)
    }

    /// `(1-based line number, words)` of each header line.
    fn words(&self) -> impl Iterator<Item = (usize, Vec<&str>)> {
        self.lines.iter().enumerate().map(|(i, l)| (i + 1, l.split_whitespace().collect()))
    }

    /// The line declaring property `property` of element `element`.
    fn property_line(&self, element: &str, property: &str) -> Option<usize> {
        let mut current = "";
        for (n, words) in self.words() {
            match words.as_slice() {
                ["element", name, ..] => current = name,
                ["property", .., name] if current == element && *name == property => {
                    return Some(n);
                }
                _ => {}
            }
        }
        None
    }

    /// `ply-rs-bw` keeps only the last of two same-named elements or properties and would then
    /// misread the payload; refuse such headers, naming the line.
    fn check_duplicates(&self) -> std::result::Result<(), String> {
        let mut elements: Vec<&str> = Vec::new();
        let mut properties: Vec<&str> = Vec::new();
        for (n, words) in self.words() {
            match words.as_slice() {
                ["element", name, ..] => {
                    if elements.contains(name) {
                        return Err(format!("header line {n}: element '{name}' is declared twice"));
                    }
                    elements.push(name);
                    properties.clear();
                }
                ["property", .., name] => {
                    if properties.contains(name) {
                        let element = elements.last().copied().unwrap_or_default();
                        return Err(format!(
                            "header line {n}: property '{name}' of element '{element}' is declared twice"
                        ));
                    }
                    properties.push(name);
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// "header line N" for a property, or just "header" when it cannot be found.
    fn locate(&self, element: &str, property: &str) -> String {
        self.property_line(element, property).map_or_else(|| "header".to_string(), |n| format!("header line {n}"))
    }
}

/// Where each vertex property goes.
struct VertexLayout {
    /// Row positions of x, y, z.
    position: [usize; 3],
    normal: Option<[usize; 3]>,
    uv: Option<[usize; 2]>,
    /// Row positions of red, green, blue and maybe alpha, with their types (for normalising).
    color: Option<([usize; 3], Option<usize>, Vec<ScalarType>)>,
    /// Other scalar properties: name and row position.
    extra: Vec<(String, usize)>,
    /// List properties, which cannot be per-vertex attributes.
    lists: Vec<String>,
}

impl VertexLayout {
    fn of(def: &ElementDef, header: &HeaderText) -> std::result::Result<VertexLayout, String> {
        let mut scalars: Vec<(&str, usize, ScalarType)> = Vec::new();
        let mut lists = Vec::new();
        for (position, (name, property)) in def.properties.iter().enumerate() {
            match &property.data_type {
                PropertyType::Scalar(t) => scalars.push((name, position, t.clone())),
                PropertyType::List(..) => lists.push(name.clone()),
            }
        }
        let find = |name: &str| scalars.iter().find(|s| s.0 == name).map(|s| s.1);
        let all = |names: &[&str]| names.iter().map(|n| find(n)).collect::<Option<Vec<usize>>>();

        let mut position = [0; 3];
        for (slot, axis) in position.iter_mut().zip(["x", "y", "z"]) {
            *slot = match find(axis) {
                Some(p) => p,
                None if lists.iter().any(|l| l == axis) => {
                    return Err(format!(
                        "{}: vertex property '{axis}' is a list, not a number",
                        header.locate("vertex", axis)
                    ));
                }
                None => return Err(format!("header: element 'vertex' has no property '{axis}'")),
            };
        }
        let normal = all(&["nx", "ny", "nz"]).map(|p| [p[0], p[1], p[2]]);
        let uv = UV_NAMES.iter().find_map(|(u, v)| Some([find(u)?, find(v)?]));
        let color = all(&["red", "green", "blue"]).map(|rgb| {
            let alpha = find("alpha");
            let types = rgb.iter().chain(alpha.as_ref()).map(|&p| scalar_type(def, p)).collect();
            ([rgb[0], rgb[1], rgb[2]], alpha, types)
        });

        let mut claimed: Vec<usize> = position.to_vec();
        claimed.extend(normal.iter().flatten());
        claimed.extend(uv.iter().flatten());
        if let Some((rgb, alpha, _)) = &color {
            claimed.extend(rgb.iter().chain(alpha.as_ref()));
        }
        let extra = scalars
            .iter()
            .filter(|s| !claimed.contains(&s.1))
            .map(|&(name, position, _)| (name.to_string(), position))
            .collect();
        Ok(VertexLayout { position, normal, uv, color, extra, lists })
    }

    /// Positions and attributes from the decoded vertex rows, every value checked finite.
    fn build(
        &self,
        rows: &[Row],
        report: &mut LoadReport,
    ) -> std::result::Result<(Vec<Vec3>, VertexAttributes), String> {
        for name in &self.lists {
            report.dropped.push(format!("vertex property '{name}': list properties cannot be vertex attributes"));
        }
        let mut positions = Vec::with_capacity(rows.len());
        let mut normals = self.normal.map(|_| Vec::with_capacity(rows.len()));
        let mut uvs = self.uv.map(|_| Vec::with_capacity(rows.len()));
        let mut colors = self.color.as_ref().map(|_| Vec::with_capacity(rows.len()));
        let mut extra: Vec<NamedAttribute> = self
            .extra
            .iter()
            .map(|(name, _)| NamedAttribute { name: name.clone(), values: Vec::with_capacity(rows.len()) })
            .collect();
        for (i, row) in rows.iter().enumerate() {
            let get = |p: usize, what: &str| -> std::result::Result<f64, String> {
                let value =
                    row.0.get(p).and_then(scalar_value).ok_or_else(|| format!("vertex {i}: {what} is missing"))?;
                if value.is_finite() {
                    Ok(value)
                } else {
                    Err(format!("vertex {i}: {what} is {value}, not a finite number"))
                }
            };
            let [x, y, z] = self.position;
            positions.push(Vec3::new(get(x, "x")? as f32, get(y, "y")? as f32, get(z, "z")? as f32));
            if let (Some(normals), Some([a, b, c])) = (normals.as_mut(), self.normal) {
                normals.push([get(a, "nx")? as f32, get(b, "ny")? as f32, get(c, "nz")? as f32]);
            }
            if let (Some(uvs), Some([u, v])) = (uvs.as_mut(), self.uv) {
                uvs.push([get(u, "texture u")? as f32, get(v, "texture v")? as f32]);
            }
            if let (Some(colors), Some((rgb, alpha, types))) = (colors.as_mut(), &self.color) {
                let mut rgba = [1.0; 4];
                for (k, (&p, what)) in
                    rgb.iter().chain(alpha.as_ref()).zip(["red", "green", "blue", "alpha"]).enumerate()
                {
                    rgba[k] = normalise_color(get(p, what)?, &types[k]);
                }
                colors.push(rgba);
            }
            for (attribute, (name, p)) in extra.iter_mut().zip(&self.extra) {
                // Scanner properties (confidence, intensity) are data, not geometry: NaN is kept.
                let value =
                    row.0.get(*p).and_then(scalar_value).ok_or_else(|| format!("vertex {i}: {name} is missing"))?;
                attribute.values.push(value as f32);
            }
        }
        Ok((positions, VertexAttributes { normals, uvs, colors, extra }))
    }
}

fn scalar_type(def: &ElementDef, position: usize) -> ScalarType {
    match def.properties.get_index(position).map(|(_, p)| &p.data_type) {
        Some(PropertyType::Scalar(t)) => t.clone(),
        _ => ScalarType::Float,
    }
}

/// Integer colour channels are fractions of their type's maximum; float channels are 0..=1.
fn normalise_color(value: f64, t: &ScalarType) -> f32 {
    let max = match t {
        ScalarType::Char => f64::from(i8::MAX),
        ScalarType::UChar => f64::from(u8::MAX),
        ScalarType::Short => f64::from(i16::MAX),
        ScalarType::UShort => f64::from(u16::MAX),
        ScalarType::Int => f64::from(i32::MAX),
        ScalarType::UInt => f64::from(u32::MAX),
        ScalarType::Float | ScalarType::Double => 1.0,
    };
    (value / max) as f32
}

/// The face element's vertex-index list: its name and row position.
struct FaceList {
    name: String,
    position: usize,
}

fn face_list_index(def: &ElementDef, header: &HeaderText) -> std::result::Result<FaceList, String> {
    let found =
        def.properties.iter().enumerate().find(|(_, (name, _))| *name == "vertex_indices" || *name == "vertex_index");
    let Some((position, (name, property))) = found else {
        return Err("header: element 'face' has no 'vertex_indices' (or 'vertex_index') property".into());
    };
    match &property.data_type {
        PropertyType::List(_, ScalarType::Float | ScalarType::Double) => Err(format!(
            "{}: face property '{name}' is a list of floating-point numbers; vertex indices must be integers",
            header.locate("face", name)
        )),
        PropertyType::List(..) => Ok(FaceList { name: name.clone(), position }),
        PropertyType::Scalar(_) => {
            Err(format!("{}: face property '{name}' is a single number, not a list", header.locate("face", name)))
        }
    }
}

/// Fan-triangulates every face (`a b c d` → `a b c`, `a c d`), checking its indices.
fn triangulate(faces: &[Row], list: usize, vertex_count: usize) -> std::result::Result<Vec<[u32; 3]>, String> {
    let mut triangles = Vec::with_capacity(faces.len());
    let mut corners = Vec::new();
    for (f, row) in faces.iter().enumerate() {
        corners.clear();
        for index in
            row.0.get(list).and_then(list_values).ok_or_else(|| format!("face {f}: vertex indices are missing"))?
        {
            match u32::try_from(index).ok().filter(|&v| (v as usize) < vertex_count) {
                Some(v) => corners.push(v),
                None => {
                    return Err(format!(
                        "face {f}: vertex index {index} is out of range (the file has {vertex_count} vertices)"
                    ));
                }
            }
        }
        if corners.len() < 3 {
            return Err(format!("face {f}: has {} vertex indices; a face needs at least 3", corners.len()));
        }
        for k in 1..corners.len() - 1 {
            triangles.push([corners[0], corners[k], corners[k + 1]]);
        }
    }
    Ok(triangles)
}

/// A scalar property's value (every PLY scalar type is exact in `f64`), or `None` for a list.
fn scalar_value(property: &Property) -> Option<f64> {
    Some(match *property {
        Property::Char(v) => v.into(),
        Property::UChar(v) => v.into(),
        Property::Short(v) => v.into(),
        Property::UShort(v) => v.into(),
        Property::Int(v) => v.into(),
        Property::UInt(v) => v.into(),
        Property::Float(v) => v.into(),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// A list property's length, or `None` for a scalar.
fn list_len(property: &Property) -> Option<usize> {
    Some(match property {
        Property::ListChar(v) => v.len(),
        Property::ListUChar(v) => v.len(),
        Property::ListShort(v) => v.len(),
        Property::ListUShort(v) => v.len(),
        Property::ListInt(v) => v.len(),
        Property::ListUInt(v) => v.len(),
        Property::ListFloat(v) => v.len(),
        Property::ListDouble(v) => v.len(),
        _ => return None,
    })
}

/// An integer list property's values, or `None` for a scalar or a floating-point list.
fn list_values(property: &Property) -> Option<Vec<i64>> {
    fn widen<T: Copy + Into<i64>>(values: &[T]) -> Vec<i64> {
        values.iter().map(|&v| v.into()).collect()
    }
    Some(match property {
        Property::ListChar(v) => widen(v),
        Property::ListUChar(v) => widen(v),
        Property::ListShort(v) => widen(v),
        Property::ListUShort(v) => widen(v),
        Property::ListInt(v) => widen(v),
        Property::ListUInt(v) => widen(v),
        _ => return None,
    })
}

/// The vertex property names [`write`] uses or [`read`] would claim, which an extra attribute
/// must not take.
const STANDARD_NAMES: [&str; 18] = [
    "x",
    "y",
    "z",
    "nx",
    "ny",
    "nz",
    "s",
    "t",
    "u",
    "v",
    "texture_u",
    "texture_v",
    "texture_s",
    "texture_t",
    "red",
    "green",
    "blue",
    "alpha",
];

/// Writes `mesh` as binary little-endian PLY: `x y z`, `nx ny nz`, `s t`, `red green blue alpha`
/// (uchar) and each extra attribute as a float, then one 3-index face per triangle in draw order.
/// Returns what could not be written: extra attributes whose name is not a PLY identifier or
/// clashes with a standard property, and colour precision below 8 bits per channel.
pub fn write(mesh: &Mesh, out: &mut dyn Write) -> io::Result<Vec<String>> {
    let a = &mesh.attributes;
    let mut dropped = Vec::new();
    let mut extras: Vec<&NamedAttribute> = Vec::new();
    for e in &a.extra {
        let identifier = e.name.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && e.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if !identifier {
            dropped.push(format!("vertex attribute '{}' (not a valid PLY property name)", e.name));
        } else if STANDARD_NAMES.contains(&e.name.as_str()) || extras.iter().any(|x| x.name == e.name) {
            dropped.push(format!("vertex attribute '{}' (its name clashes with another property)", e.name));
        } else {
            extras.push(e);
        }
    }
    let to_byte = |c: f32| (c.clamp(0.0, 1.0) * 255.0).round() as u8;
    if a.colors.iter().flatten().flatten().any(|&c| f32::from(to_byte(c)) / 255.0 != c) {
        dropped.push("colour precision beyond 8 bits per channel".into());
    }

    let name: String = mesh.name.chars().map(|c| if c.is_control() { ' ' } else { c }).collect();
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment {name}, written by triorder\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.vertex_count()
    );
    if a.normals.is_some() {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if a.uvs.is_some() {
        header.push_str("property float s\nproperty float t\n");
    }
    if a.colors.is_some() {
        header.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n");
    }
    for e in &extras {
        header.push_str(&format!("property float {}\n", e.name));
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangle_count()
    ));
    out.write_all(header.as_bytes())?;

    let mut record = Vec::new();
    for (i, p) in mesh.positions.iter().enumerate() {
        record.clear();
        let mut floats = |values: &[f32]| values.iter().for_each(|v| record.extend_from_slice(&v.to_le_bytes()));
        floats(&p.to_array());
        if let Some(n) = a.normals.as_ref().and_then(|n| n.get(i)) {
            floats(n);
        }
        if let Some(t) = a.uvs.as_ref().and_then(|t| t.get(i)) {
            floats(t);
        }
        if let Some(c) = a.colors.as_ref().and_then(|c| c.get(i)) {
            record.extend(c.map(to_byte));
        }
        for e in &extras {
            record.extend_from_slice(&e.values.get(i).copied().unwrap_or(f32::NAN).to_le_bytes());
        }
        out.write_all(&record)?;
    }
    for t in &mesh.triangles {
        record.clear();
        record.push(3);
        t.iter().for_each(|v| record.extend_from_slice(&v.to_le_bytes()));
        out.write_all(&record)?;
    }
    Ok(dropped)
}

/// One face record of a PLY payload, as byte ranges of the file: `text` is the record itself,
/// `end` its line ending (`\n`, `\r\n`, or none for the last line of an ASCII file; always empty
/// in binary). `corners` is its number of vertex indices.
struct FaceRecord {
    text: Range<usize>,
    end: Range<usize>,
    corners: usize,
}

/// `bytes` (a PLY file that [`read`] accepts) with its face records in the order `order` gives:
/// `order` is a permutation of the triangles `read` returns for the same bytes (faces with n > 3
/// corners are fan-triangulated by `read` into n − 2 consecutive triangles). Every face record is
/// written whole (all its properties: the index list, and any other face property such as
/// colours or flags), in the order of the first of its triangles in `order`; the header, the
/// vertex records, every other element, comments and the encoding (ascii, binary little or big
/// endian) are kept exactly as they are. Returns the new bytes and, as notes, anything worth
/// telling the user (how many polygons were kept whole, and of those, how many `order` had
/// spread apart).
///
/// Why not [`write`] the reordered mesh: `order` promises the same asset, only faster to draw,
/// and [`read`] keeps neither face properties nor other elements. So the file is checked by
/// `read` first, then walked record by record exactly as `read` walks it (the same header
/// parser for where the payload starts, one line per ASCII record, what `ply-rs-bw` consumes
/// for a binary one): the two cannot disagree on where a face is. ASCII line endings stay with
/// their line position, so a last line without one stays so and the file keeps its length.
pub fn reorder(bytes: &[u8], origin: &str, order: &[u32]) -> Result<(Vec<u8>, Vec<String>)> {
    let fail = |problem: String| Error::input(origin, problem);
    let (mesh, _) = read(bytes, origin)?;
    crate::order::check_permutation(order, mesh.triangle_count())
        .map_err(|e| fail(format!("the triangle order does not fit this file: {e}")))?;
    let faces = face_records(bytes).ok_or_else(|| fail("the face records could not be located".into()))?;
    // Triangle → face: face f owns the next `corners - 2` triangles, as `triangulate` made them.
    let face_of: Vec<usize> =
        faces.iter().enumerate().flat_map(|(f, r)| std::iter::repeat_n(f, r.corners.saturating_sub(2))).collect();
    let (Some(first), Some(last)) = (faces.first(), faces.last()) else {
        return Err(fail("no faces".into()));
    };
    if face_of.len() != order.len() {
        return Err(fail(format!("{} triangles in the face records, {} read", face_of.len(), order.len())));
    }

    let mut out = Vec::with_capacity(bytes.len());
    out.extend_from_slice(&bytes[..first.text.start]);
    let mut placed = vec![false; faces.len()];
    let mut slots = faces.iter();
    for &t in order {
        let f = face_of[t as usize];
        if !std::mem::replace(&mut placed[f], true) {
            let slot = slots.next().ok_or_else(|| fail("more faces placed than read".into()))?;
            out.extend_from_slice(&bytes[faces[f].text.clone()]);
            out.extend_from_slice(&bytes[slot.end.clone()]);
        }
    }
    out.extend_from_slice(&bytes[last.end.end..]);

    // A polygon is drawn whole where its first triangle was placed: say how far that departs
    // from `order`, which may have spread a polygon's triangles apart.
    let mut position = vec![0; order.len()];
    order.iter().enumerate().for_each(|(p, &t)| position[t as usize] = p);
    let (mut polygons, mut apart, mut next) = (0, 0, 0);
    for record in &faces {
        let triangles = &position[next..next + record.corners.saturating_sub(2)];
        next += triangles.len();
        if let (Some(lo), Some(hi)) = (triangles.iter().min(), triangles.iter().max())
            && triangles.len() > 1
        {
            polygons += 1;
            apart += usize::from(hi - lo + 1 != triangles.len());
        }
    }
    let mut notes = Vec::new();
    if polygons > 0 {
        let (s, were) = if polygons == 1 { ("", "was") } else { ("s", "were") };
        notes.push(format!(
            "{polygons} polygon{s} (faces of more than 3 corners) {were} kept whole: the triangles of each are \
             drawn together, where the order placed the first ({apart} had been spread apart by the order)"
        ));
    }
    Ok((out, notes))
}

/// The face records of a PLY file [`read`] accepts, in file order; `None` if the payload does
/// not walk as `read` walks it (which `read` accepting the file rules out).
fn face_records(bytes: &[u8]) -> Option<Vec<FaceRecord>> {
    let body = bytes.strip_prefix(crate::mesh::BOM).unwrap_or(bytes);
    let parser = Parser::<Row>::new();
    let mut payload = body;
    let header = parser.read_header(&mut ply_rs_bw::parser::Reader::new(&mut payload)).ok()?;
    let face_def = header.elements.get("face")?;
    let list = face_list_index(face_def, &HeaderText::scan(body)).ok()?.position;
    let mut faces = Vec::with_capacity(face_def.count.min(payload.len()));
    for def in header.elements.values() {
        for _ in 0..def.count {
            let start = bytes.len() - payload.len();
            let (row, ending) = next_record(&parser, &header.encoding, def, &mut payload)?;
            let end = bytes.len() - payload.len();
            if def.name == "face" {
                let corners = row.0.get(list).and_then(list_len)?;
                faces.push(FaceRecord { text: start..end - ending, end: end - ending..end, corners });
            }
        }
        if def.name == "face" {
            return Some(faces);
        }
    }
    None
}

/// Decodes the next record of `def` as [`read`] does (an ASCII record is one line), moves
/// `payload` past it and returns it with the length of its line ending.
fn next_record(
    parser: &Parser<Row>,
    encoding: &Encoding,
    def: &ElementDef,
    payload: &mut &[u8],
) -> Option<(Row, usize)> {
    match encoding {
        Encoding::Ascii => {
            let end = payload.iter().position(|&b| b == b'\n').map_or(payload.len(), |n| n + 1);
            let (line, rest) = payload.split_at(end);
            *payload = rest;
            let ending = [&b"\r\n"[..], b"\n"].iter().find(|e| line.ends_with(e)).map_or(0, |e| e.len());
            Some((parser.read_ascii_element(std::str::from_utf8(line).ok()?, def).ok()?, ending))
        }
        Encoding::BinaryLittleEndian => Some((parser.read_little_endian_element(payload, def).ok()?, 0)),
        Encoding::BinaryBigEndian => Some((parser.read_big_endian_element(payload, def).ok()?, 0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangles `read` makes of [`square_and_pentagon`]'s faces 0, 1 and 2 (a pentagon).
    const TRIANGLES: [&[[u32; 3]]; 3] = [&[[0, 1, 2]], &[[0, 2, 3]], &[[4, 5, 6], [4, 6, 7], [4, 7, 8]]];

    /// A PLY with a square (faces 0 and 1, triangles) and a pentagon (face 2), each face with a
    /// `uchar red` of 10, 20, 30, and an `edge` element; faces written in `faces` order, the face
    /// element first or last, lines ending in `eol` (the payload too, in ASCII).
    fn square_and_pentagon(format: &str, faces: [usize; 3], face_first: bool, eol: &str) -> Vec<u8> {
        let positions = [[0.0f32, 0.0, 0.0], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]].into_iter().chain([
            [2.0f32, 0.0, 0.0],
            [3., 0., 0.],
            [3.5, 1., 0.],
            [2.5, 1.5, 0.],
            [1.5, 1., 0.],
        ]);
        let corners: [&[i32]; 3] = [&[0, 1, 2], &[0, 2, 3], &[4, 5, 6, 7, 8]];
        let big = format == "binary_big_endian";
        let int = |v: i32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
        let float = |v: f32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
        let record = |words: Vec<String>, binary: Vec<u8>| match format {
            "ascii" => (words.join(" ") + eol).into_bytes(),
            _ => binary,
        };

        let vertex_header = "element vertex 9\nproperty float x\nproperty float y\nproperty float z\n";
        let face_header = "element face 3\nproperty list uchar int vertex_indices\nproperty uchar red\n";
        let edge_header = "element edge 1\nproperty int vertex1\nproperty int vertex2\n";
        let vertices: Vec<u8> = positions
            .flat_map(|p| record(p.map(|c| c.to_string()).to_vec(), p.into_iter().flat_map(float).collect()))
            .collect();
        let face_records: Vec<u8> = faces
            .iter()
            .flat_map(|&f| {
                let red = 10 * (f as u8 + 1);
                let mut words = vec![corners[f].len().to_string()];
                words.extend(corners[f].iter().map(i32::to_string));
                words.push(red.to_string());
                let mut binary = vec![corners[f].len() as u8];
                binary.extend(corners[f].iter().flat_map(|&v| int(v)));
                binary.push(red);
                record(words, binary)
            })
            .collect();
        let edges = record(vec!["0".into(), "2".into()], [int(0), int(2)].concat());

        let (elements, payload) = if face_first {
            ([face_header, vertex_header, edge_header], [face_records, vertices, edges])
        } else {
            ([vertex_header, edge_header, face_header], [vertices, edges, face_records])
        };
        let header =
            format!("ply\nformat {format} 1.0\ncomment two faces and a polygon\n{}end_header\n", elements.concat());
        let mut bytes = header.replace('\n', eol).into_bytes();
        bytes.extend(payload.concat());
        bytes
    }

    /// `order` puts triangle 3 (the pentagon's second) first, then face 1, then face 0.
    const ORDER: [u32; 5] = [3, 1, 4, 0, 2];

    fn check(original: &[u8], expected: &[u8]) {
        let (bytes, notes) = reorder(original, "in.ply", &ORDER).unwrap();
        assert_eq!(bytes.len(), original.len());
        assert!(bytes == expected, "{:?}\n{:?}", String::from_utf8_lossy(&bytes), String::from_utf8_lossy(expected));
        let (before, _) = read(original, "in.ply").unwrap();
        let (after, _) = read(&bytes, "out.ply").unwrap();
        assert_eq!(after.positions, before.positions);
        assert_eq!(after.triangles, [TRIANGLES[2], TRIANGLES[1], TRIANGLES[0]].concat());
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].starts_with("1 polygon (") && notes[0].ends_with("(1 had been spread apart by the order)"),
            "{notes:?}"
        );
    }

    #[test]
    fn faces_move_whole_with_their_properties_in_every_encoding() {
        for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
            for face_first in [false, true] {
                let original = square_and_pentagon(format, [0, 1, 2], face_first, "\n");
                // Every byte but the face records' is the same; the red values moved with them.
                check(&original, &square_and_pentagon(format, [2, 1, 0], face_first, "\n"));
            }
        }
    }

    #[test]
    fn a_byte_order_mark_and_crlf_line_endings_are_kept() {
        for format in ["ascii", "binary_little_endian"] {
            let with_bom = |faces| [crate::mesh::BOM, &square_and_pentagon(format, faces, false, "\r\n")].concat();
            check(&with_bom([0, 1, 2]), &with_bom([2, 1, 0]));
        }
        // The last ASCII line without a line ending: the face that moves there goes without one.
        let unterminated = |faces| {
            let mut bytes = square_and_pentagon("ascii", faces, false, "\r\n");
            bytes.truncate(bytes.len() - 2);
            bytes
        };
        check(&unterminated([0, 1, 2]), &unterminated([2, 1, 0]));
    }

    #[test]
    fn no_note_without_polygons_and_the_identity_changes_nothing() {
        let original = square_and_pentagon("ascii", [0, 1, 2], false, "\n");
        assert_eq!(reorder(&original, "in.ply", &[0, 1, 2, 3, 4]).unwrap().0, original);
        let triangles_only = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
            property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
            0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
        assert_eq!(reorder(triangles_only, "t.ply", &[0]).unwrap(), (triangles_only.to_vec(), vec![]));
    }

    #[test]
    fn an_order_that_is_not_a_permutation_is_refused_naming_the_file() {
        let original = square_and_pentagon("binary_little_endian", [0, 1, 2], false, "\n");
        for order in [&[0, 1, 2, 3][..], &[0, 1, 2, 3, 3], &[0, 1, 2, 3, 5]] {
            let error = reorder(&original, "in.ply", order).unwrap_err().to_string();
            assert!(error.starts_with("in.ply: the triangle order does not fit this file"), "{error}");
        }
    }

    #[test]
    fn broken_files_are_errors_not_panics() {
        for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
            let original = square_and_pentagon(format, [0, 1, 2], true, "\n");
            // (An ASCII file cut just before its final line ending is whole.)
            for end in 0..original.len() - usize::from(format == "ascii") {
                assert!(reorder(&original[..end], "in.ply", &ORDER).is_err(), "{format} cut at {end}");
            }
        }
        let no_faces = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
            property float z\nend_header\n0 0 0\n";
        let error = reorder(no_faces, "v.ply", &[]).unwrap_err().to_string();
        assert!(error.starts_with("v.ply: no faces"), "{error}");
    }
}
