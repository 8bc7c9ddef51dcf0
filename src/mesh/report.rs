//! What is unusual about a mesh, counted and reported, never silently repaired.
//!
//! Degenerate triangles (a repeated index, or zero area), duplicates, non-manifold and
//! inconsistently wound edges all change what orderings and metrics do, so `triorder` prints
//! these counts when it loads a mesh and keeps every triangle as given.

use std::collections::HashSet;
use std::fmt;

use crate::mesh::Mesh;
use crate::mesh::topology::Topology;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshReport {
    pub triangles: usize,
    pub vertices: usize,
    /// Vertices no triangle references.
    pub unused_vertices: usize,
    /// Vertices that two or more corners reference: the reuse a vertex cache can exploit.
    pub shared_vertices: usize,
    /// Triangles repeating a vertex index.
    pub repeated_index: usize,
    /// Triangles with three distinct indices but zero area (collinear or coincident positions).
    pub zero_area: usize,
    /// Extra copies of a triangle over the same three welded vertices (any order or winding).
    pub duplicates: usize,
    pub boundary_edges: usize,
    pub non_manifold_edges: usize,
    /// Edges whose two triangles traverse them in the same direction (inconsistent winding).
    pub inconsistent_edges: usize,
    pub components: usize,
}

impl MeshReport {
    pub fn new(mesh: &Mesh, topology: &Topology) -> MeshReport {
        let mut used = vec![0u32; mesh.vertex_count()];
        let mut seen = HashSet::with_capacity(mesh.triangle_count());
        let (mut repeated_index, mut zero_area, mut duplicates) = (0, 0, 0);
        for tri in &mesh.triangles {
            tri.iter().for_each(|&v| used[v as usize] += 1);
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
                repeated_index += 1;
            } else {
                let [a, b, c] = tri.map(|v| mesh.positions[v as usize]);
                zero_area += usize::from((b - a).cross(c - a) == glam::Vec3::ZERO);
            }
            let mut key = tri.map(|v| topology.weld[v as usize]);
            key.sort_unstable();
            duplicates += usize::from(!seen.insert(key));
        }
        MeshReport {
            triangles: mesh.triangle_count(),
            vertices: mesh.vertex_count(),
            unused_vertices: used.iter().filter(|&&u| u == 0).count(),
            shared_vertices: used.iter().filter(|&&u| u > 1).count(),
            repeated_index,
            zero_area,
            duplicates,
            boundary_edges: topology.boundary_edges,
            non_manifold_edges: topology.non_manifold_edges,
            inconsistent_edges: topology.inconsistent_edges,
            components: topology.component_count,
        }
    }

    /// One line per irregularity worth a user's attention (empty for a clean mesh).
    pub fn warnings(&self) -> Vec<String> {
        [
            (self.repeated_index, "degenerate triangles (repeated vertex index)"),
            (self.zero_area, "degenerate triangles (zero area)"),
            (self.duplicates, "duplicate triangles"),
            (self.non_manifold_edges, "non-manifold edges (3+ triangles)"),
            (self.inconsistent_edges, "edges with inconsistent winding"),
            (self.unused_vertices, "unused vertices"),
        ]
        .into_iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| format!("{n} {what}; kept as given"))
        .chain((self.shared_vertices == 0 && self.triangles > 1).then(|| {
            "no vertex is shared between triangles (an unindexed mesh): every order misses 3 vertices \
             per triangle, so vertex-cache metrics cannot tell orders apart; weld its vertices first"
                .to_string()
        }))
        .collect()
    }
}

impl fmt::Display for MeshReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} triangles, {} vertices, {} components, {} boundary edges",
            self.triangles, self.vertices, self.components, self.boundary_edges
        )?;
        for w in self.warnings() {
            write!(f, "\n  note: {w}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::VertexAttributes;
    use glam::Vec3;

    #[test]
    fn irregularities_are_counted_not_dropped() {
        let positions = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [2., 0., 0.], [0., 0., 1.], [5., 5., 5.]]
            .map(Vec3::from)
            .to_vec();
        let triangles = vec![
            [0, 1, 2],
            [2, 1, 0], // duplicate of the first (reversed)
            [0, 0, 1], // repeated index
            [0, 1, 3], // zero area (collinear)
            [0, 1, 4], // third triangle on edge 0-1 with the first two: non-manifold
        ];
        let mesh = Mesh::new("m", positions.clone(), triangles, VertexAttributes::default()).unwrap();
        let report = MeshReport::new(&mesh, &Topology::new(&mesh));
        assert_eq!(report.triangles, 5);
        assert_eq!((report.repeated_index, report.zero_area, report.duplicates), (1, 1, 1));
        assert_eq!(report.non_manifold_edges, 1);
        assert_eq!(report.unused_vertices, 1);
        let text = report.to_string();
        assert!(text.contains("1 duplicate triangles; kept as given"), "{text}");
        assert!(text.contains("non-manifold"), "{text}");
        assert!(!text.contains("unindexed"), "{text}");
        let soup = Mesh::new("soup", positions[..6].to_vec(), vec![[0, 1, 2], [3, 4, 5]], VertexAttributes::default());
        let soup = soup.unwrap();
        let text = MeshReport::new(&soup, &Topology::new(&soup)).to_string();
        assert!(text.contains("unindexed"), "{text}");
    }
}
