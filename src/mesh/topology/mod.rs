//! Connectivity derived once per mesh and shared by every ordering.
//!
//! Two notions of "vertex" coexist on purpose. The vertex cache sees *mesh vertices* (one per
//! unique position+attribute combination), so [`Topology::vertex_triangles`] is indexed by them:
//! that is what Tipsify, Forsyth and the cache simulators walk. Geometry, on the other hand, is
//! continuous across UV or normal seams, so the dual graph ([`Topology::neighbors`]) is built over
//! *welded* vertices (bit-identical positions): two triangles are neighbours when they share an
//! undirected welded edge, whatever their attributes. Recursive cut, clustering and MLA walk it.

mod edges;
mod live;

pub use edges::{NONE, copies, edge_neighbors};
pub use live::LiveLists;

use std::collections::HashMap;

use crate::mesh::Mesh;

/// The most triangles on one edge that are all linked to each other in [`Topology::neighbors`]:
/// scanned and decimated meshes have a few on their non-manifold edges, but 20,000 copies of one
/// face in a 160 KB file would otherwise ask for 400 million links (15 GB).
pub const MAX_EDGE_CLIQUE: usize = 16;

/// Compressed sparse rows: `items[offsets[i]..offsets[i + 1]]` belong to row `i`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Csr {
    offsets: Vec<u32>,
    items: Vec<u32>,
}

impl Csr {
    /// Builds rows from `(row, item)` pairs by counting sort; items keep their input order.
    fn from_pairs(rows: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Csr {
        let mut offsets = vec![0u32; rows + 1];
        for (row, _) in pairs.clone() {
            offsets[row as usize + 1] += 1;
        }
        for i in 0..rows {
            offsets[i + 1] += offsets[i];
        }
        let mut cursor = offsets.clone();
        let mut items = vec![0u32; offsets[rows] as usize];
        for (row, item) in pairs {
            items[cursor[row as usize] as usize] = item;
            cursor[row as usize] += 1;
        }
        Csr { offsets, items }
    }

    pub fn row(&self, i: usize) -> &[u32] {
        &self.items[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// This vertex→triangle adjacency of `triangles` with each row listing its triangles in the
    /// order they come in `order` (a permutation of the triangles' ids), once per corner as
    /// before: for a walk over `order`'s runs that wants each run's entries together in a row.
    /// The rows keep their lengths, so only the items are placed, in one pass.
    pub fn reordered(&self, triangles: &[[u32; 3]], order: &[u32]) -> Csr {
        debug_assert_eq!(3 * order.len(), self.items.len());
        let mut cursor = self.offsets.clone();
        let mut items = vec![0u32; self.items.len()];
        for &t in order {
            for v in triangles[t as usize] {
                let at = &mut cursor[v as usize];
                items[*at as usize] = t;
                *at += 1;
            }
        }
        Csr { offsets: self.offsets.clone(), items }
    }

    pub fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The raw arrays, for code (METIS, simulators) that wants them flat.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    pub fn items(&self) -> &[u32] {
        &self.items
    }
}

/// Adjacency and edge statistics of one mesh.
#[derive(Debug, Clone)]
pub struct Topology {
    /// Mesh vertex → triangles using it (a triangle with a repeated vertex is listed once per use).
    pub vertex_triangles: Csr,
    /// Mesh vertex → canonical welded vertex (the first vertex with the same position).
    pub weld: Vec<u32>,
    /// The dual graph: triangle → triangles sharing an undirected welded edge (no self loops,
    /// no repeats). A non-manifold edge links every pair of its triangles, up to
    /// [`MAX_EDGE_CLIQUE`] of them; an edge shared by more (a fan of duplicate faces, hostile or
    /// not) links them in a chain instead, so the graph stays linear in the triangles and its
    /// components are the same.
    pub neighbors: Csr,
    /// Triangle → connected component of the dual graph, numbered from 0 in order of first triangle.
    pub component: Vec<u32>,
    pub component_count: usize,
    /// Distinct undirected welded edges (degenerate self-edges excluded).
    pub edge_count: usize,
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: usize,
    /// Edges used by exactly two triangles in the same direction (inconsistent winding).
    pub inconsistent_edges: usize,
}

impl Topology {
    pub fn new(mesh: &Mesh) -> Topology {
        let n_tris = mesh.triangle_count();
        let vertex_triangles = vertex_triangles(mesh);
        let weld = weld_positions(mesh);

        // Every directed welded edge with its triangle, sorted so equal undirected edges are adjacent.
        let mut half_edges: Vec<(u64, u32, bool)> = Vec::with_capacity(3 * n_tris);
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (weld[tri[k] as usize], weld[tri[(k + 1) % 3] as usize]);
                if a != b {
                    let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
                    half_edges.push((key, t as u32, a < b));
                }
            }
        }
        half_edges.sort_unstable();

        let (mut edge_count, mut boundary_edges, mut non_manifold_edges, mut inconsistent_edges) = (0, 0, 0, 0);
        let mut links: Vec<(u32, u32)> = Vec::with_capacity(3 * n_tris);
        for group in half_edges.chunk_by(|x, y| x.0 == y.0) {
            edge_count += 1;
            match group.len() {
                1 => boundary_edges += 1,
                2 => inconsistent_edges += usize::from(group[0].2 == group[1].2),
                _ => non_manifold_edges += 1,
            }
            let mut link = |x: u32, y: u32| {
                if x != y {
                    links.extend([(x, y), (y, x)]);
                }
            };
            // Every pair on an edge, or along a chain past MAX_EDGE_CLIQUE (see `neighbors`).
            if group.len() <= MAX_EDGE_CLIQUE {
                for (i, x) in group.iter().enumerate() {
                    group[i + 1..].iter().for_each(|y| link(x.1, y.1));
                }
            } else {
                group.windows(2).for_each(|w| link(w[0].1, w[1].1));
            }
        }
        links.sort_unstable();
        links.dedup();
        let neighbors = Csr::from_pairs(n_tris, links.iter().copied());
        let (component, component_count) = components(&neighbors);

        Topology {
            vertex_triangles,
            weld,
            neighbors,
            component,
            component_count,
            edge_count,
            boundary_edges,
            non_manifold_edges,
            inconsistent_edges,
        }
    }
}

/// Mesh vertex → the triangles using it, in triangle order, a triangle listed once per corner
/// (so a repeated corner lists it twice). [`Topology::new`] builds it; the benchmark builds it
/// alone to time an ordering together with the adjacency it needs, as meshoptimizer's are timed.
pub fn vertex_triangles(mesh: &Mesh) -> Csr {
    // Csr::from_pairs specialised to three items per triangle, as this is on the path of every
    // ordering that is timed with its adjacency. Vertex v is counted at `offsets[v + 2]`, so the
    // prefix sum leaves `offsets[v + 1]` at row v's start; filling the row advances it to the
    // row's end, which is row v + 1's start. The offsets thus come out right with no copy of them
    // as write cursors and no pass to rewind those cursors; the one slot too many is dropped.
    let n = mesh.vertex_count();
    let mut offsets = vec![0u32; n + 2];
    for &v in mesh.triangles.as_flattened() {
        offsets[v as usize + 2] += 1;
    }
    for i in 2..offsets.len() {
        offsets[i] += offsets[i - 1];
    }
    let mut items = vec![0u32; 3 * mesh.triangles.len()];
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for &v in tri {
            let end = &mut offsets[v as usize + 1];
            items[*end as usize] = t as u32;
            *end += 1;
        }
    }
    offsets.pop();
    Csr { offsets, items }
}

/// Maps each vertex to the first vertex at a bit-identical position (with -0.0 read as 0.0).
fn weld_positions(mesh: &Mesh) -> Vec<u32> {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.vertex_count());
    mesh.positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let key = [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits());
            *first.entry(key).or_insert(i as u32)
        })
        .collect()
}

/// Connected components of a graph by iterative flood fill.
fn components(graph: &Csr) -> (Vec<u32>, usize) {
    const UNSEEN: u32 = u32::MAX;
    let mut component = vec![UNSEEN; graph.rows()];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for start in 0..graph.rows() {
        if component[start] != UNSEEN {
            continue;
        }
        component[start] = count;
        stack.push(start as u32);
        while let Some(t) = stack.pop() {
            for &n in graph.row(t as usize) {
                if component[n as usize] == UNSEEN {
                    component[n as usize] = count;
                    stack.push(n);
                }
            }
        }
        count += 1;
    }
    (component, count as usize)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::VertexAttributes;
    use glam::Vec3;

    fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Mesh {
        let positions = positions.iter().map(|&p| Vec3::from(p)).collect();
        Mesh::new("test", positions, triangles.to_vec(), VertexAttributes::default()).unwrap()
    }

    #[test]
    fn tetrahedron_is_closed_and_connected() {
        let m = mesh(
            &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        );
        let t = Topology::new(&m);
        assert_eq!(t.edge_count, 6);
        assert_eq!((t.boundary_edges, t.non_manifold_edges, t.inconsistent_edges), (0, 0, 0));
        assert_eq!(t.component_count, 1);
        for tri in 0..4 {
            assert_eq!(t.neighbors.row(tri).len(), 3);
        }
        assert_eq!(t.vertex_triangles.row(0), &[0, 1, 3]);
    }

    #[test]
    fn vertex_triangles_lists_each_corner_in_triangle_order() {
        // A repeated corner, and vertices 1 and 5 used by no triangle (empty rows).
        let m = mesh(
            &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.], [0., 0., 1.], [1., 0., 1.]],
            &[[0, 2, 3], [3, 3, 4], [4, 0, 2], [2, 4, 3]],
        );
        let pairs = m.triangles.iter().enumerate().flat_map(|(t, tri)| tri.map(|v| (v, t as u32)));
        let expected = Csr::from_pairs(m.vertex_count(), pairs);
        assert_eq!(vertex_triangles(&m), expected);
        assert_eq!(expected.row(3), &[0, 1, 1, 3]);
        assert_eq!(expected.row(5), &[] as &[u32]);
        // Reordered, each row lists the same triangles in the new order's order.
        let order = [2, 0, 3, 1];
        let pairs = order.iter().flat_map(|&t| m.triangles[t as usize].map(|v| (v, t)));
        assert_eq!(expected.reordered(&m.triangles, &order), Csr::from_pairs(m.vertex_count(), pairs));
        assert_eq!(expected.reordered(&m.triangles, &order).row(3), &[0, 3, 1, 1]);
    }

    #[test]
    fn seams_are_welded_and_fins_are_non_manifold() {
        // Two triangles sharing an edge through duplicated (seam) vertices 2,3 == 4,5 positions,
        // plus a third triangle on the same edge: a fin.
        let m = mesh(
            &[[0., 0., 0.], [1., 1., 0.], [1., 0., 0.], [0., 1., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
            &[[0, 2, 3], [4, 1, 5], [2, 3, 6], [0, 1, 6]],
        );
        let t = Topology::new(&m);
        assert_eq!(t.weld[4], 2);
        assert_eq!(t.weld[5], 3);
        assert_eq!(t.non_manifold_edges, 1);
        assert_eq!(t.neighbors.row(0), &[1, 2]);
        assert_eq!(t.neighbors.row(3), &[] as &[u32]);
        assert_eq!(t.component_count, 2);
        assert_eq!(t.component, vec![0, 0, 0, 1]);
    }

    #[test]
    fn opposite_orientation_is_counted() {
        let m = mesh(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]], &[[0, 1, 2], [1, 2, 3]]);
        let t = Topology::new(&m);
        assert_eq!(t.inconsistent_edges, 1);
        assert_eq!(t.boundary_edges, 4);
    }
}
