//! glTF 2.0 (`.gltf` + buffers, or binary `.glb`): reading static meshes and writing GLB.
//!
//! The `gltf` crate parses and validates the JSON and loads the buffers; the accessor data is
//! decoded here. Its own readers assume a valid file: they index and subtract without checks
//! (a debug-build panic on a zero count, an element type that does not match the attribute, or a
//! stride too small), and return `None`, not an error, for data past the end of a buffer view.
//! Decoding here checks every byte range and says which accessor or buffer view is wrong; node
//! transforms are composed here too, refusing hierarchies that are not trees (the crate does not
//! check). Three more inputs make the `gltf` crate itself panic, so they are refused before it
//! sees them: a GLB header whose length field is below 12, a `POSITION` accessor index past the
//! end (its validator indexes without checking), and a buffer URI whose percent-escapes are not
//! UTF-8. [`super::gltf_animation`] reads skins and animations with the same pieces (parsing,
//! accessors, hierarchy, primitives), so its rest mesh is this reader's mesh before posing.

use std::collections::hash_map::Entry;
use std::collections::{BTreeSet, HashMap};
use std::io::{self, Write};
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::{Accessor, Document, Gltf, Semantic};
use glam::{Mat3, Mat4, Vec3};

use crate::error::{Error, Result};
use crate::mesh::load::LoadReport;
use crate::mesh::{Mesh, NamedAttribute, VertexAttributes};

/// Reads a glTF or GLB file. `base` is the directory external buffers are resolved from;
/// `binary` says the file was named `.glb`, so it must start with the GLB magic.
///
/// Every primitive of every mesh node of the default scene (of all scenes if none is the
/// default) is merged into one mesh, in node and primitive order, placed by its node's world
/// transform: positions by the matrix, normals by its inverse transpose (renormalised), and each
/// triangle's winding reversed where the matrix mirrors. Skinned meshes are posed at rest, as a
/// viewer shows the file with no animation playing: linear blend skinning with every joint at its
/// node's world transform (`JOINTS_n`/`WEIGHTS_n`, inverse bind matrices), the skinned node's own
/// transform ignored as the glTF spec requires; so skinned and rigid parts line up. Strips and
/// fans become triangle lists; point and line primitives are skipped and reported. Attributes:
/// `POSITION`, `NORMAL`, `TEXCOORD_0`, `COLOR_0` and scalar `_NAME` attributes (as extra
/// attribute `NAME`), each kept only if every primitive has it.
pub fn read(bytes: &[u8], origin: &str, base: Option<&Path>, binary: bool) -> Result<(Mesh, LoadReport)> {
    let fail = |problem: String| Error::input(origin, problem);
    let (document, buffers) = open(bytes, origin, base, binary)?;
    let mut report = LoadReport::default();
    let world = world_transforms(&document).map_err(fail)?;
    let mut skins: HashMap<usize, Vec<Mat4>> = HashMap::new();
    let mut parts = Vec::new();
    for ScenePart { node, at, part, .. } in scene_parts(&document, &buffers, &mut report).map_err(fail)? {
        parts.push(match node.skin() {
            Some(skin) => {
                let joints = match skins.entry(skin.index()) {
                    Entry::Occupied(known) => known.into_mut(),
                    Entry::Vacant(slot) => slot.insert(joint_matrices(&skin, &world, &buffers).map_err(fail)?),
                };
                part.skinned(joints, &at).map_err(fail)?
            }
            None => part.transformed(world[node.index()]),
        });
    }
    let (positions, triangles, attributes) = merge(parts, &mut report);
    Ok((Mesh::new(origin, positions, triangles, attributes)?, report))
}

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

/// One triangle primitive of a mesh node of the scene, read but not yet placed.
pub(super) struct ScenePart<'a> {
    pub(super) node: ::gltf::Node<'a>,
    pub(super) primitive: ::gltf::Primitive<'a>,
    /// "mesh M primitive P", to name the primitive in errors.
    pub(super) at: String,
    pub(super) part: Part,
}

/// Every triangle primitive of every mesh node of the scene, in node and primitive order, with
/// its skinning attributes if its node has a skin. Point and line primitives, and attributes not
/// loaded, are noted in `report`. Fails if no primitive has a triangle.
pub(super) fn scene_parts<'a>(
    document: &'a Document,
    buffers: &[Vec<u8>],
    report: &mut LoadReport,
) -> std::result::Result<Vec<ScenePart<'a>>, String> {
    let mut parts = Vec::new();
    let mut unloaded = BTreeSet::new();
    for node in scene_nodes(document)? {
        let Some(mesh) = node.mesh() else { continue };
        for primitive in mesh.primitives() {
            let at = format!("mesh {} primitive {}", mesh.index(), primitive.index());
            match primitive.mode() {
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {}
                mode => {
                    report.dropped.push(format!("{at}: {mode:?} primitive skipped (only triangles are loaded)"));
                    continue;
                }
            }
            let part = Part::read(&primitive, buffers, &at, node.skin().is_some(), &mut unloaded)?;
            parts.push(ScenePart { node: node.clone(), primitive, at, part });
        }
    }
    if !unloaded.is_empty() {
        let names: Vec<String> = unloaded.into_iter().collect();
        report.dropped.push(format!("attributes not loaded: {}", names.join(", ")));
    }
    if parts.iter().all(|p| p.part.triangles.is_empty()) {
        return Err("no triangles: the scene has no triangle primitive with faces".into());
    }
    Ok(parts)
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

/// Every node's world transform at rest.
fn world_transforms(document: &Document) -> std::result::Result<Vec<Mat4>, String> {
    let hierarchy = Hierarchy::of(document)?;
    Ok(hierarchy.world(&local_transforms(document)?))
}

/// Every node's own transform (its matrix, or its translation, rotation and scale composed).
pub(super) fn local_transforms(document: &Document) -> std::result::Result<Vec<Mat4>, String> {
    document
        .nodes()
        .map(|node| {
            let matrix = Mat4::from_cols_array_2d(&node.transform().matrix());
            match matrix.is_finite() {
                true => Ok(matrix),
                false => Err(format!("node {}: its transform has a non-finite value", node.index())),
            }
        })
        .collect()
}

/// The node tree: each node's parent, and every node listed after its parent.
pub(super) struct Hierarchy {
    parent: Vec<Option<usize>>,
    parents_first: Vec<usize>,
}

impl Hierarchy {
    /// glTF node hierarchies must be trees: a node with two parents would be drawn twice and a
    /// cycle has no root, so both are refused.
    pub(super) fn of(document: &Document) -> std::result::Result<Hierarchy, String> {
        let count = document.nodes().len();
        let mut parent: Vec<Option<usize>> = vec![None; count];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); count];
        for node in document.nodes() {
            for child in node.children() {
                let slot = parent
                    .get_mut(child.index())
                    .ok_or_else(|| format!("node {}: no child {}", node.index(), child.index()))?;
                if let Some(other) = slot.replace(node.index()) {
                    return Err(format!(
                        "node {}: it is a child of both node {other} and node {}",
                        child.index(),
                        node.index()
                    ));
                }
                children[node.index()].push(child.index());
            }
        }
        // Every node has at most one parent, so the nodes no root reaches are on or below a cycle.
        let mut parents_first = Vec::with_capacity(count);
        let mut stack: Vec<usize> = (0..count).rev().filter(|&n| parent[n].is_none()).collect();
        while let Some(n) = stack.pop() {
            parents_first.push(n);
            stack.extend(children[n].iter().rev());
        }
        if parents_first.len() < count {
            let mut reached = vec![false; count];
            parents_first.iter().for_each(|&n| reached[n] = true);
            let first = reached.iter().position(|&r| !r).unwrap_or_default();
            return Err(format!("node {first}: the node hierarchy has a cycle"));
        }
        Ok(Hierarchy { parent, parents_first })
    }

    /// The world transforms of nodes whose own transforms are `local` (one per node).
    pub(super) fn world(&self, local: &[Mat4]) -> Vec<Mat4> {
        let mut world = local.to_vec();
        for &n in &self.parents_first {
            if let Some(p) = self.parent[n] {
                world[n] = world[p] * local[n];
            }
        }
        world
    }
}

/// The nodes of the default scene (of every scene if none is the default), parents first.
pub(super) fn scene_nodes(document: &Document) -> std::result::Result<Vec<::gltf::Node<'_>>, String> {
    let scenes: Vec<::gltf::Scene<'_>> = match document.default_scene() {
        Some(scene) => vec![scene],
        None => document.scenes().collect(),
    };
    if scenes.is_empty() {
        return Err("no scene: the file defines no scenes to take meshes from".into());
    }
    let mut out = Vec::new();
    for scene in scenes {
        let mut seen = vec![false; document.nodes().len()];
        let mut stack: Vec<::gltf::Node<'_>> = scene.nodes().collect::<Vec<_>>().into_iter().rev().collect();
        while let Some(node) = stack.pop() {
            match seen.get_mut(node.index()) {
                Some(s) if !*s => *s = true,
                _ => {
                    return Err(format!("scene {}: node {} is listed twice", scene.index(), node.index()));
                }
            }
            stack.extend(node.children().collect::<Vec<_>>().into_iter().rev());
            out.push(node);
        }
    }
    Ok(out)
}

/// Each joint's skinning matrix at rest: its node's world transform times its inverse bind
/// matrix.
fn joint_matrices(
    skin: &::gltf::Skin<'_>,
    world: &[Mat4],
    buffers: &[Vec<u8>],
) -> std::result::Result<Vec<Mat4>, String> {
    let inverse_bind = inverse_bind_matrices(skin, buffers)?;
    Ok(skin
        .joints()
        .zip(inverse_bind)
        .map(|(j, ibm)| world.get(j.index()).copied().unwrap_or(Mat4::IDENTITY) * ibm)
        .collect())
}

/// A skin's inverse bind matrices, one per joint (identity when the skin gives none).
pub(super) fn inverse_bind_matrices(
    skin: &::gltf::Skin<'_>,
    buffers: &[Vec<u8>],
) -> std::result::Result<Vec<Mat4>, String> {
    let joints = skin.joints().len();
    let Some(accessor) = skin.inverse_bind_matrices() else { return Ok(vec![Mat4::IDENTITY; joints]) };
    if accessor.dimensions() != Dimensions::Mat4 || accessor.data_type() != DataType::F32 {
        return Err(format!(
            "skin {}: inverse bind matrix accessor {} is not MAT4 of floats",
            skin.index(),
            accessor.index()
        ));
    }
    if accessor.count() < joints {
        return Err(format!(
            "skin {}: inverse bind matrix accessor {} has {} matrices for {joints} joints",
            skin.index(),
            accessor.index(),
            accessor.count(),
        ));
    }
    let values = accessor_values(&accessor, buffers, 16)?;
    Ok(values
        .chunks_exact(16)
        .take(joints)
        .map(|m| Mat4::from_cols_slice(&m.iter().map(|&v| v as f32).collect::<Vec<_>>()))
        .collect())
}

/// One `JOINTS_n`/`WEIGHTS_n` pair: per vertex, four joints and their weights.
pub(super) struct Influences {
    pub(super) set: u32,
    pub(super) joints: Vec<[f32; 4]>,
    pub(super) weights: Vec<[f32; 4]>,
}

/// One triangle primitive's vertices and triangles, before merging.
pub(super) struct Part {
    pub(super) positions: Vec<Vec3>,
    /// For a skinned primitive, each `JOINTS_n`/`WEIGHTS_n` set.
    pub(super) influences: Vec<Influences>,
    normals: Option<Vec<[f32; 3]>>,
    uvs: Option<Vec<[f32; 2]>>,
    colors: Option<Vec<[f32; 4]>>,
    extra: Vec<NamedAttribute>,
    pub(super) triangles: Vec<[u32; 3]>,
}

impl Part {
    /// Reads one primitive (with its skinning attributes if `skinned`), adding the names of
    /// attributes it does not load to `unloaded`.
    fn read(
        primitive: &::gltf::Primitive<'_>,
        buffers: &[Vec<u8>],
        at: &str,
        skinned: bool,
        unloaded: &mut BTreeSet<String>,
    ) -> std::result::Result<Part, String> {
        let position = primitive.get(&Semantic::Positions).ok_or_else(|| format!("{at}: has no POSITION attribute"))?;
        let positions: Vec<Vec3> =
            read_vectors::<3>(&position, buffers, "POSITION")?.into_iter().map(Vec3::from_array).collect();
        let n = positions.len();
        let mut normals = None;
        let mut uvs = None;
        let mut colors = None;
        let mut extra = Vec::new();
        let mut joints = Vec::new();
        let mut weights = Vec::new();
        for (semantic, accessor) in primitive.attributes() {
            let name = semantic.to_string();
            let loaded = match &semantic {
                Semantic::Positions => continue,
                Semantic::Normals | Semantic::TexCoords(0) | Semantic::Colors(0) => true,
                Semantic::Joints(_) | Semantic::Weights(_) => skinned,
                Semantic::Extras(_) => accessor.dimensions() == Dimensions::Scalar,
                _ => false,
            };
            if !loaded {
                unloaded.insert(name);
                continue;
            }
            if accessor.count() != n {
                return Err(format!(
                    "{at}: {name} accessor {} has {} elements, but POSITION has {n}",
                    accessor.index(),
                    accessor.count()
                ));
            }
            match &semantic {
                Semantic::Normals => normals = Some(read_vectors::<3>(&accessor, buffers, &name)?),
                Semantic::TexCoords(_) => uvs = Some(read_vectors::<2>(&accessor, buffers, &name)?),
                Semantic::Colors(_) if accessor.dimensions() == Dimensions::Vec3 => {
                    let rgb = read_vectors::<3>(&accessor, buffers, &name)?;
                    colors = Some(rgb.into_iter().map(|[r, g, b]| [r, g, b, 1.0]).collect());
                }
                Semantic::Colors(_) => colors = Some(read_vectors::<4>(&accessor, buffers, &name)?),
                Semantic::Extras(short) => {
                    let values = read_vectors::<1>(&accessor, buffers, &name)?.into_iter().map(|[v]| v).collect();
                    extra.push(NamedAttribute { name: short.clone(), values });
                }
                // Element i is vertex i, so with the primitive named the error locates the vertex.
                Semantic::Joints(set) => {
                    let values = read_vectors::<4>(&accessor, buffers, &name).map_err(|e| format!("{at}: {e}"))?;
                    joints.push((*set, values));
                }
                Semantic::Weights(set) => {
                    let values = read_vectors::<4>(&accessor, buffers, &name).map_err(|e| format!("{at}: {e}"))?;
                    weights.push((*set, values));
                }
                _ => {}
            }
        }
        let mut influences = Vec::new();
        for (set, joints) in joints {
            let Some(position) = weights.iter().position(|(s, _)| *s == set) else {
                return Err(format!("{at}: has JOINTS_{set} but no WEIGHTS_{set}"));
            };
            let weights = weights.swap_remove(position).1;
            influences.push(Influences { set, joints, weights });
        }
        if skinned && influences.is_empty() {
            return Err(format!("{at}: its node has a skin, but it has no JOINTS_0/WEIGHTS_0"));
        }
        if primitive.morph_targets().len() > 0 {
            unloaded.insert("morph targets".into());
        }

        let indices: Vec<u32> = match primitive.indices() {
            Some(accessor) => read_indices(&accessor, buffers, n)?,
            None => (0..n as u32).collect(),
        };
        let triangles = assemble(primitive.mode(), &indices).map_err(|p| format!("{at}: {p}"))?;
        Ok(Part { positions, influences, normals, uvs, colors, extra, triangles })
    }

    /// The part posed by linear blend skinning with `joints` (each joint's world transform times
    /// its inverse bind matrix). Weights are renormalised to sum to 1; a vertex with no weight
    /// stays where it is.
    fn skinned(mut self, joints: &[Mat4], at: &str) -> std::result::Result<Part, String> {
        for (v, position) in self.positions.iter_mut().enumerate() {
            let mut blend = Mat4::ZERO;
            let mut total = 0.0;
            for influences in &self.influences {
                let set = influences.set;
                let (Some(indices), Some(weights)) = (influences.joints.get(v), influences.weights.get(v)) else {
                    continue;
                };
                for (&j, &w) in indices.iter().zip(weights).filter(|(_, w)| **w != 0.0) {
                    let joint = joints.get(j as usize).ok_or_else(|| {
                        format!(
                            "{at}: JOINTS_{set} of vertex {v} names joint {j}, but the skin has {} joints",
                            joints.len()
                        )
                    })?;
                    blend += *joint * w;
                    total += w;
                }
            }
            let m = if total > 0.0 { blend * (1.0 / total) } else { Mat4::IDENTITY };
            *position = m.transform_point3(*position);
            if let Some(normal) = self.normals.as_mut().and_then(|n| n.get_mut(v)) {
                let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
                *normal = (normal_matrix * Vec3::from_array(*normal)).normalize_or_zero().to_array();
            }
        }
        Ok(self)
    }

    /// The part placed by `m`: positions transformed, normals by the inverse transpose, winding
    /// reversed if `m` mirrors (so front faces stay front).
    fn transformed(mut self, m: Mat4) -> Part {
        if m != Mat4::IDENTITY {
            for p in &mut self.positions {
                *p = m.transform_point3(*p);
            }
            let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
            for n in self.normals.iter_mut().flatten() {
                *n = (normal_matrix * Vec3::from_array(*n)).normalize_or_zero().to_array();
            }
            self.keep_front_faces(m);
        }
        self
    }

    /// Reverses every triangle's winding if `m` mirrors, so that the faces that were front
    /// faces stay front faces once the part is placed by `m`.
    pub(super) fn keep_front_faces(&mut self, m: Mat4) {
        if m.determinant() < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
        }
    }
}

/// Triangles from a primitive's index list, per the glTF spec's strip and fan rules.
fn assemble(mode: Mode, indices: &[u32]) -> std::result::Result<Vec<[u32; 3]>, String> {
    Ok(match mode {
        Mode::TriangleStrip => indices
            .windows(3)
            .enumerate()
            .map(|(i, w)| if i % 2 == 0 { [w[0], w[1], w[2]] } else { [w[0], w[2], w[1]] })
            .collect(),
        Mode::TriangleFan => match indices.split_first() {
            Some((&first, rest)) => rest.windows(2).map(|w| [w[0], w[1], first]).collect(),
            None => Vec::new(),
        },
        _ => {
            if !indices.len().is_multiple_of(3) {
                return Err(format!("a TRIANGLES primitive has {} indices, not a multiple of 3", indices.len()));
            }
            indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
        }
    })
}

/// Concatenates the parts; an attribute survives only if every part has it.
pub(super) fn merge(parts: Vec<Part>, report: &mut LoadReport) -> (Vec<Vec3>, Vec<[u32; 3]>, VertexAttributes) {
    let total: usize = parts.iter().map(|p| p.positions.len()).sum();
    let all = |has: &dyn Fn(&Part) -> bool, what: &str, report: &mut LoadReport| {
        let count = parts.iter().filter(|p| has(p)).count();
        if count > 0 && count < parts.len() {
            report.dropped.push(format!("{what}: only {count} of {} primitives have them", parts.len()));
        }
        count == parts.len()
    };
    let keep_normals = all(&|p| p.normals.is_some(), "normals", report);
    let keep_uvs = all(&|p| p.uvs.is_some(), "texture coordinates (TEXCOORD_0)", report);
    let keep_colors = all(&|p| p.colors.is_some(), "colours (COLOR_0)", report);
    let extra_names: BTreeSet<String> = parts.iter().flat_map(|p| p.extra.iter().map(|e| e.name.clone())).collect();
    let kept_extras: Vec<String> = extra_names
        .into_iter()
        .filter(|name| all(&|p| p.extra.iter().any(|e| &e.name == name), &format!("attribute _{name}"), report))
        .collect();

    let mut positions = Vec::with_capacity(total);
    let mut triangles = Vec::new();
    let mut normals = keep_normals.then(|| Vec::with_capacity(total));
    let mut uvs = keep_uvs.then(|| Vec::with_capacity(total));
    let mut colors = keep_colors.then(|| Vec::with_capacity(total));
    let mut extra: Vec<NamedAttribute> = kept_extras
        .iter()
        .map(|name| NamedAttribute { name: name.clone(), values: Vec::with_capacity(total) })
        .collect();
    for part in parts {
        let base = positions.len() as u32;
        positions.extend(part.positions);
        triangles.extend(part.triangles.iter().map(|t| t.map(|v| v + base)));
        if let (Some(all), Some(mine)) = (normals.as_mut(), part.normals) {
            all.extend(mine);
        }
        if let (Some(all), Some(mine)) = (uvs.as_mut(), part.uvs) {
            all.extend(mine);
        }
        if let (Some(all), Some(mine)) = (colors.as_mut(), part.colors) {
            all.extend(mine);
        }
        for attribute in &mut extra {
            if let Some(mine) = part.extra.iter().find(|e| e.name == attribute.name) {
                attribute.values.extend(&mine.values);
            }
        }
    }
    (positions, triangles, VertexAttributes { normals, uvs, colors, extra })
}

/// Where an accessor's elements lie: the buffer, the first byte, the stride and element size.
struct Layout<'b> {
    data: &'b [u8],
    start: usize,
    stride: usize,
    element: usize,
}

/// Checks that `count` elements of `element` bytes at `offset` with `stride` fit in `view`, and
/// `view` in its buffer; names the accessor (or `what`) and the view when they do not.
fn layout<'b>(
    view: &::gltf::buffer::View<'_>,
    offset: usize,
    count: usize,
    element: usize,
    stride: Option<usize>,
    buffers: &'b [Vec<u8>],
    what: &str,
) -> std::result::Result<Layout<'b>, String> {
    let v = view.index();
    let buffer = view.buffer();
    let data = buffers.get(buffer.index()).map_or(&[][..], Vec::as_slice);
    let view_end = view.offset().checked_add(view.length());
    let Some(view_data) = view_end.and_then(|end| data.get(view.offset()..end).filter(|_| end <= buffer.length()))
    else {
        return Err(format!(
            "buffer view {v}: bytes {}..{} lie past the end of buffer {} ({} bytes)",
            view.offset(),
            view.offset() as u128 + view.length() as u128,
            buffer.index(),
            buffer.length()
        ));
    };
    let stride = stride.unwrap_or(element);
    if stride < element {
        return Err(format!(
            "{what}: buffer view {v} has byteStride {stride}, less than the {element}-byte element size"
        ));
    }
    let end = match count {
        0 => Some(offset),
        _ => (count - 1).checked_mul(stride).and_then(|s| s.checked_add(offset)).and_then(|s| s.checked_add(element)),
    };
    match end {
        Some(end) if end <= view_data.len() => Ok(Layout { data: view_data, start: offset, stride, element }),
        _ => Err(format!(
            "{what}: {count} elements of {element} bytes at offset {offset} (stride {stride}) run past the end of buffer view {v} ({} bytes)",
            view_data.len()
        )),
    }
}

/// Reads element `i`'s components of type `t` from `layout` (in range: [`layout`] checked it).
fn components(layout: &Layout<'_>, i: usize, t: DataType, into: &mut Vec<f64>) {
    let at = layout.start + i * layout.stride;
    let bytes = layout.data.get(at..at + layout.element).unwrap_or_default();
    let size = t.size();
    for c in bytes.chunks_exact(size) {
        let value = match t {
            DataType::I8 => f64::from(c[0] as i8),
            DataType::U8 => f64::from(c[0]),
            DataType::I16 => f64::from(i16::from_le_bytes([c[0], c[1]])),
            DataType::U16 => f64::from(u16::from_le_bytes([c[0], c[1]])),
            DataType::U32 => f64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]])),
            DataType::F32 => f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        };
        into.push(value);
    }
}

/// The most elements a sparse accessor without a buffer view may have: it is all zeros but the
/// substitutions, so its count is the only thing sizing the allocation.
const MAX_VIEWLESS_ELEMENTS: usize = 1 << 26;

/// All of an accessor's components, as stored (not normalised), sparse substitutions applied.
fn accessor_values(accessor: &Accessor<'_>, buffers: &[Vec<u8>], dims: usize) -> std::result::Result<Vec<f64>, String> {
    let what = format!("accessor {}", accessor.index());
    let t = accessor.data_type();
    let element = t.size() * dims;
    let count = accessor.count();
    let mut values = Vec::new();
    match accessor.view() {
        Some(view) => {
            let l = layout(&view, accessor.offset(), count, element, view.stride(), buffers, &what)?;
            values.reserve(count * dims);
            for i in 0..count {
                components(&l, i, t, &mut values);
            }
        }
        // Only a sparse accessor has no view; its count is not bounded by any buffer's size.
        None if count > MAX_VIEWLESS_ELEMENTS => {
            return Err(format!("{what}: count {count} without a buffer view exceeds {MAX_VIEWLESS_ELEMENTS}"));
        }
        None => values.resize(count * dims, 0.0),
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let index_type = match indices.index_type() {
            ::gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            ::gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            ::gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let sparse_what = format!("{what} (sparse indices)");
        let il = layout(&indices.view(), indices.offset(), n, index_type.size(), None, buffers, &sparse_what)?;
        let vl = layout(
            &sparse.values().view(),
            sparse.values().offset(),
            n,
            element,
            None,
            buffers,
            &format!("{what} (sparse values)"),
        )?;
        let mut index = Vec::with_capacity(1);
        let mut substitute = Vec::with_capacity(dims);
        for k in 0..n {
            index.clear();
            substitute.clear();
            components(&il, k, index_type, &mut index);
            components(&vl, k, t, &mut substitute);
            let target = index.first().map_or(usize::MAX, |&i| i as usize);
            let slot = target.checked_mul(dims).and_then(|s| values.get_mut(s..s + dims));
            let Some(slot) = slot else {
                return Err(format!("{what}: sparse index {target} is past the accessor's {count} elements"));
            };
            slot.copy_from_slice(&substitute);
        }
    }
    Ok(values)
}

/// An attribute accessor as `N`-component float vectors (normalised if the accessor says so).
pub(super) fn read_vectors<const N: usize>(
    accessor: &Accessor<'_>,
    buffers: &[Vec<u8>],
    name: &str,
) -> std::result::Result<Vec<[f32; N]>, String> {
    let dims = accessor.dimensions().multiplicity();
    let matrix = matches!(accessor.dimensions(), Dimensions::Mat2 | Dimensions::Mat3 | Dimensions::Mat4);
    if dims != N || matrix {
        return Err(format!(
            "accessor {} ({name}) has type {:?}; expected {}",
            accessor.index(),
            accessor.dimensions(),
            ["SCALAR", "VEC2", "VEC3", "VEC4"].get(N - 1).unwrap_or(&"?")
        ));
    }
    let t = accessor.data_type();
    let normalised = accessor.normalized();
    let values = accessor_values(accessor, buffers, dims)?;
    let mut out = Vec::with_capacity(values.len() / N);
    for (i, chunk) in values.chunks_exact(N).enumerate() {
        let mut v = [0.0f32; N];
        for (slot, &raw) in v.iter_mut().zip(chunk) {
            *slot = if normalised { normalise(raw, t) } else { raw as f32 };
            if !slot.is_finite() {
                return Err(format!("accessor {} ({name}): element {i} has a non-finite value", accessor.index()));
            }
        }
        out.push(v);
    }
    Ok(out)
}

/// glTF's normalised-integer decoding (spec section 3.11).
fn normalise(raw: f64, t: DataType) -> f32 {
    (match t {
        DataType::I8 => (raw / 127.0).max(-1.0),
        DataType::U8 => raw / 255.0,
        DataType::I16 => (raw / 32767.0).max(-1.0),
        DataType::U16 => raw / 65535.0,
        DataType::U32 => raw / f64::from(u32::MAX),
        DataType::F32 => raw,
    }) as f32
}

/// A primitive's index accessor: unsigned integer scalars, each below `vertex_count`.
fn read_indices(
    accessor: &Accessor<'_>,
    buffers: &[Vec<u8>],
    vertex_count: usize,
) -> std::result::Result<Vec<u32>, String> {
    let a = accessor.index();
    if accessor.dimensions() != Dimensions::Scalar
        || !matches!(accessor.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
    {
        return Err(format!(
            "accessor {a} (indices) has type {:?} of {:?}; expected SCALAR of an unsigned integer type",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    let values = accessor_values(accessor, buffers, 1)?;
    let mut indices = Vec::with_capacity(values.len());
    for (i, &v) in values.iter().enumerate() {
        if v >= vertex_count as f64 {
            return Err(format!(
                "accessor {a} (indices): index {i} is {v}, but the primitive has {vertex_count} vertices"
            ));
        }
        indices.push(v as u32);
    }
    Ok(indices)
}

/// Writes `mesh` as a GLB with one mesh, one node, one triangle primitive: `POSITION` (with
/// min/max), `NORMAL`, `TEXCOORD_0`, `COLOR_0` (float RGBA) and each extra attribute as a
/// scalar float `_NAME` attribute, and `u32` indices in draw order, winding kept. Everything is
/// stored as 32-bit floats or integers, so reading it back gives the same bits. GLB holds every
/// attribute the mesh has, so nothing is dropped.
pub fn write(mesh: &Mesh, out: &mut dyn Write) -> io::Result<Vec<String>> {
    let a = &mesh.attributes;
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut attributes = serde_json::Map::new();
    // Every element is a 4-byte float or integer, so each view starts 4-byte aligned.
    let mut add = |floats: &mut dyn Iterator<Item = f32>, kind: &str, semantic: &str, extra: serde_json::Value| {
        let start = bin.len();
        floats.for_each(|f| bin.extend_from_slice(&f.to_le_bytes()));
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34962}),
        );
        let mut accessor = serde_json::json!({
            "bufferView": views.len() - 1, "componentType": 5126, "count": mesh.vertex_count(), "type": kind
        });
        if let (Some(target), serde_json::Value::Object(more)) = (accessor.as_object_mut(), extra) {
            target.extend(more);
        }
        accessors.push(accessor);
        attributes.insert(semantic.to_string(), (accessors.len() - 1).into());
    };
    let (min, max) = mesh.bounds();
    add(
        &mut mesh.positions.iter().flat_map(|p| p.to_array()),
        "VEC3",
        "POSITION",
        serde_json::json!({"min": min.to_array(), "max": max.to_array()}),
    );
    if let Some(n) = &a.normals {
        add(&mut n.iter().flatten().copied(), "VEC3", "NORMAL", serde_json::Value::Null);
    }
    if let Some(t) = &a.uvs {
        add(&mut t.iter().flatten().copied(), "VEC2", "TEXCOORD_0", serde_json::Value::Null);
    }
    if let Some(c) = &a.colors {
        add(&mut c.iter().flatten().copied(), "VEC4", "COLOR_0", serde_json::Value::Null);
    }
    for e in &a.extra {
        add(&mut e.values.iter().copied(), "SCALAR", &format!("_{}", e.name), serde_json::Value::Null);
    }
    let start = bin.len();
    mesh.triangles.iter().flatten().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
    views.push(serde_json::json!({"buffer": 0, "byteOffset": start, "byteLength": bin.len() - start, "target": 34963}));
    accessors.push(serde_json::json!({
        "bufferView": views.len() - 1, "componentType": 5125, "count": mesh.triangle_count() * 3, "type": "SCALAR"
    }));

    let json = serde_json::json!({
        "asset": {"version": "2.0", "generator": "triorder"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"name": mesh.name, "primitives": [{"attributes": attributes, "indices": accessors.len() - 1, "mode": 4}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let json = serde_json::to_vec(&json).map_err(io::Error::other)?;
    let glb = ::gltf::binary::Glb {
        header: ::gltf::binary::Header { magic: *b"glTF", version: 2, length: 0 },
        json: json.into(),
        bin: Some(bin.into()),
    };
    glb.to_writer(out).map_err(|e| io::Error::other(e.to_string()))?;
    Ok(Vec::new())
}
