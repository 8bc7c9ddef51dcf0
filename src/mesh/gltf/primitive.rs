//! One primitive read into a part (positions, attributes, triangles, skin influences), placed
//! by its node or skin, and the parts merged into one mesh.

use std::collections::BTreeSet;

use ::gltf::Semantic;
use ::gltf::accessor::Dimensions;
use ::gltf::mesh::Mode;
use glam::{Mat3, Mat4, Vec3};

use super::accessors::{read_indices, read_vectors};
use crate::mesh::load::LoadReport;
use crate::mesh::{NamedAttribute, VertexAttributes};

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
    pub(super) fn read(
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
    pub(super) fn skinned(mut self, joints: &[Mat4], at: &str) -> std::result::Result<Part, String> {
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
    pub(super) fn transformed(mut self, m: Mat4) -> Part {
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
        report.draw_calls.push(triangles.len()..triangles.len() + part.triangles.len());
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
