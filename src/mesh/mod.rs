//! Triangle meshes: the one in-memory form every loader produces and every ordering consumes.
//!
//! A [`Mesh`] is an indexed triangle list. The order of [`Mesh::triangles`] *is* the draw order,
//! and a vertex is what a GPU's vertex cache sees: one unique combination of position and
//! attributes (so an OBJ with UV seams has more vertices than `v` lines). Loaders validate while
//! reading; [`Mesh::new`] re-checks the invariants every other module relies on (finite
//! coordinates, indices in range, at least one triangle) so no later stage has to.

pub mod animated;
pub mod frames;
pub mod gltf;

pub mod load;
pub mod obj;
pub mod ply;
pub mod procedural;
pub mod progressive;
pub mod report;
pub mod save;
pub mod scene;
pub mod simplify;
pub mod source;
pub mod subdivide;
pub mod topology;
pub mod z_order;

use glam::Vec3;

/// The UTF-8 byte-order mark some editors put at the start of a text file. Readers of text
/// formats (OBJ, PLY headers, glTF JSON, specs) skip it: it is not part of the first line.
pub const BOM: &[u8] = b"\xEF\xBB\xBF";

pub use frames::{Frames, Framing};
pub use scene::Scene;
pub use source::Source;
pub use topology::Topology;

use crate::error::{Error, Result};

/// Per-vertex data carried along with positions so that reordering and re-export lose nothing.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VertexAttributes {
    pub normals: Option<Vec<[f32; 3]>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    /// RGBA in 0..=1.
    pub colors: Option<Vec<[f32; 4]>>,
    /// Any other scalar per-vertex property (e.g. a PLY scan's `confidence`), kept by name.
    pub extra: Vec<NamedAttribute>,
}

/// A scalar per-vertex property the formats we read may carry and we must write back.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedAttribute {
    pub name: String,
    pub values: Vec<f32>,
}

/// An indexed triangle mesh; `triangles` in draw order, winding counter-clockwise = front.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Where the mesh came from (file path or procedural spec): used in errors and provenance.
    pub name: String,
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub attributes: VertexAttributes,
}

impl Mesh {
    /// Builds a mesh after checking the invariants the rest of the crate assumes. Errors name
    /// `name` and the offending element.
    pub fn new(
        name: impl Into<String>,
        positions: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        attributes: VertexAttributes,
    ) -> Result<Mesh> {
        let name = name.into();
        if triangles.is_empty() {
            return Err(Error::input(&name, "the mesh has no triangles"));
        }
        if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(Error::input(&name, format!("vertex {i} has a non-finite coordinate ({p})")));
        }
        let n = positions.len();
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= n) {
                return Err(Error::input(
                    &name,
                    format!("triangle {t} references vertex {v}, but there are only {n} vertices"),
                ));
            }
        }
        let attribute_lengths = [
            ("normals", attributes.normals.as_ref().map(Vec::len)),
            ("uvs", attributes.uvs.as_ref().map(Vec::len)),
            ("colors", attributes.colors.as_ref().map(Vec::len)),
        ];
        let extra_lengths = attributes.extra.iter().map(|a| (a.name.as_str(), Some(a.values.len())));
        for (what, len) in attribute_lengths.into_iter().chain(extra_lengths) {
            if let Some(len) = len.filter(|&len| len != n) {
                return Err(Error::input(&name, format!("{len} {what} for {n} vertices")));
            }
        }
        Ok(Mesh { name, positions, triangles, attributes })
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    /// The triangles as a flat index buffer, as libraries and GPUs take them.
    pub fn index_buffer(&self) -> Vec<u32> {
        self.triangles.iter().flatten().copied().collect()
    }

    /// The positions as meshoptimizer reads them: tightly packed `[f32; 3]`.
    pub fn meshopt_positions(&self) -> meshopt::VertexDataAdapter<'_> {
        meshopt_positions(&self.positions)
    }

    /// The triangles in the order `order` (new position → old triangle id). The caller guarantees
    /// `order` is a permutation (see [`crate::order::check_permutation`]).
    pub fn triangles_in_order(&self, order: &[u32]) -> Vec<[u32; 3]> {
        order.iter().map(|&t| self.triangles[t as usize]).collect()
    }

    /// A copy with the triangles drawn in `order`; vertices and winding untouched.
    pub fn reordered(&self, order: &[u32]) -> Mesh {
        Mesh { triangles: self.triangles_in_order(order), ..self.clone() }
    }

    /// Renumbers vertices in order of first use by the triangle list (vertex-fetch locality, what
    /// engines do after reordering triangles). Every attribute moves with its vertex; vertices no
    /// triangle uses are kept, after the used ones, in their old relative order.
    pub fn remap_vertices_first_use(&self) -> Mesh {
        const UNSET: u32 = u32::MAX;
        let mut new_of_old = vec![UNSET; self.vertex_count()];
        let mut old_of_new = Vec::with_capacity(self.vertex_count());
        for &v in self.triangles.iter().flatten() {
            if new_of_old[v as usize] == UNSET {
                new_of_old[v as usize] = old_of_new.len() as u32;
                old_of_new.push(v);
            }
        }
        for v in 0..self.vertex_count() as u32 {
            if new_of_old[v as usize] == UNSET {
                new_of_old[v as usize] = old_of_new.len() as u32;
                old_of_new.push(v);
            }
        }
        let a = &self.attributes;
        Mesh {
            name: self.name.clone(),
            positions: gather(&self.positions, &old_of_new),
            triangles: self.triangles.iter().map(|t| t.map(|v| new_of_old[v as usize])).collect(),
            attributes: VertexAttributes {
                normals: a.normals.as_deref().map(|n| gather(n, &old_of_new)),
                uvs: a.uvs.as_deref().map(|n| gather(n, &old_of_new)),
                colors: a.colors.as_deref().map(|n| gather(n, &old_of_new)),
                extra: a
                    .extra
                    .iter()
                    .map(|e| NamedAttribute { name: e.name.clone(), values: gather(&e.values, &old_of_new) })
                    .collect(),
            },
        }
    }
}

impl Mesh {
    /// The mesh without the vertices no triangle uses, the rest numbered in order of first use
    /// (what a simplifier's output needs before vertex counts mean anything).
    pub fn without_unused_vertices(&self) -> Mesh {
        let mut seen = vec![false; self.vertex_count()];
        self.triangles.iter().flatten().for_each(|&v| seen[v as usize] = true);
        let used = seen.iter().filter(|&&s| s).count();
        let mut mesh = self.remap_vertices_first_use();
        mesh.positions.truncate(used);
        let a = &mut mesh.attributes;
        a.normals.iter_mut().for_each(|v| v.truncate(used));
        a.uvs.iter_mut().for_each(|v| v.truncate(used));
        a.colors.iter_mut().for_each(|v| v.truncate(used));
        a.extra.iter_mut().for_each(|e| e.values.truncate(used));
        mesh
    }
}

/// `values` permuted so that element `i` of the result is `values[index[i]]`.
fn gather<T: Copy>(values: &[T], index: &[u32]) -> Vec<T> {
    index.iter().map(|&i| values[i as usize]).collect()
}

/// `positions` as meshoptimizer reads them: tightly packed `[f32; 3]` (a mesh's, a keyframe's or
/// the unit-frame copy the cameras see).
pub fn meshopt_positions(positions: &[Vec3]) -> meshopt::VertexDataAdapter<'_> {
    meshopt::VertexDataAdapter::new(meshopt::typed_to_bytes(positions), std::mem::size_of::<Vec3>(), 0)
        .expect("Vec3 slices are a whole number of 12-byte vertices")
}
