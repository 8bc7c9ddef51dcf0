//! Minimum-linear-arrangement (MLA) costs of a draw order: how far apart, in the order, the
//! triangles that belong together end up.
//!
//! Two definitions are in use, and they are not interchangeable:
//!
//! * [`dual_cost`] — Σ over edges (u, v) of the *dual graph* of |π(u) − π(v)|, the classical
//!   graph MinLA objective on the triangle adjacency (two triangles are adjacent when they share
//!   a welded edge, [`Topology::neighbors`]). It is what the orderings optimise (`mla`) and what
//!   the project's tests compare.
//! * [`hypergraph_cost`] — Bogomjakov & Gotsman 2002, §2.3: nodes are triangles, each *mesh
//!   vertex* is a hyperedge over the triangles using it, and its length is
//!   max π(t) − min π(t) over those triangles. This is closer to what a vertex cache sees: a
//!   vertex stays useful as long as the triangles using it are drawn close together.
//!
//! Here π(t) is the position of triangle t in the order (0-based). Both are one linear pass.

use crate::mesh::Mesh;
use crate::mesh::topology::Topology;

/// Position of each triangle in `order` (the inverse permutation).
///
/// # Panics
/// If `order` is not a permutation of `0..n` (as [`crate::order::run`] guarantees).
fn positions(order: &[u32], n: usize) -> Vec<u32> {
    assert_eq!(order.len(), n, "an order must list each of the {n} triangles once");
    let mut pos = vec![u32::MAX; n];
    for (i, &t) in order.iter().enumerate() {
        pos[t as usize] = i as u32;
    }
    assert!(pos.iter().all(|&p| p != u32::MAX), "the order is not a permutation");
    pos
}

/// Σ over dual-graph edges {u, v} of |π(u) − π(v)|, each edge counted once: the graph MinLA
/// cost of the triangle adjacency.
///
/// # Panics
/// If `order` is not a permutation of the topology's triangles.
pub fn dual_cost(order: &[u32], topology: &Topology) -> u64 {
    let graph = &topology.neighbors;
    let pos = positions(order, graph.rows());
    (0..graph.rows())
        .map(|t| {
            graph
                .row(t)
                .iter()
                .filter(|&&u| u as usize > t)
                .map(|&u| u64::from(pos[t].abs_diff(pos[u as usize])))
                .sum::<u64>()
        })
        .sum()
}

/// Σ over mesh vertices of (max π(t) − min π(t)) over the triangles t using the vertex:
/// Bogomjakov & Gotsman's hypergraph arrangement cost (§2.3). Unused vertices count 0.
///
/// # Panics
/// If `order` is not a permutation of the mesh's triangles.
pub fn hypergraph_cost(order: &[u32], mesh: &Mesh) -> u64 {
    let pos = positions(order, mesh.triangle_count());
    let mut first = vec![u32::MAX; mesh.vertex_count()];
    let mut last = vec![0u32; mesh.vertex_count()];
    for (tri, &p) in mesh.triangles.iter().zip(&pos) {
        for &v in tri {
            first[v as usize] = first[v as usize].min(p);
            last[v as usize] = last[v as usize].max(p);
        }
    }
    first.iter().zip(&last).filter(|(f, _)| **f != u32::MAX).map(|(&f, &l)| u64::from(l - f)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::VertexAttributes;
    use glam::Vec3;

    /// A strip of three triangles 0–1–2 (0 and 2 share only vertex 2) plus a lone triangle 3.
    fn strip() -> Mesh {
        let positions = [[0., 0.], [1., 0.], [0., 1.], [1., 1.], [0., 2.], [5., 5.], [6., 5.], [5., 6.]]
            .iter()
            .map(|&[x, y]| Vec3::new(x, y, 0.0))
            .collect();
        let triangles = vec![[0, 1, 2], [1, 3, 2], [2, 3, 4], [5, 6, 7]];
        Mesh::new("strip", positions, triangles, VertexAttributes::default()).unwrap()
    }

    #[test]
    fn costs_by_hand() {
        let mesh = strip();
        let topology = Topology::new(&mesh);
        // Dual edges: 0–1, 1–2.
        assert_eq!(dual_cost(&[0, 1, 2, 3], &topology), 2);
        // Order 1, 3, 0, 2: π = [2, 0, 3, 1]; |2−0| + |0−3| = 5.
        assert_eq!(dual_cost(&[1, 3, 0, 2], &topology), 5);
        // Identity: v0 {0}: 0, v1 {0,1}: 1, v2 {0,1,2}: 2, v3 {1,2}: 1, v4 {2}: 0, lone: 0 → 4.
        assert_eq!(hypergraph_cost(&[0, 1, 2, 3], &mesh), 4);
        // π = [2, 0, 3, 1]: v1 {2,0}: 2, v2 {2,0,3}: 3, v3 {0,3}: 3 → 8.
        assert_eq!(hypergraph_cost(&[1, 3, 0, 2], &mesh), 8);
    }
}
