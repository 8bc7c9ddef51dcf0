//! The orderings of meshoptimizer (through the `meshopt` crate), registered as peers: our
//! yardsticks, not our code. meshoptimizer speaks flat index buffers; triorder speaks triangle
//! ids. [`order_from_index_buffer`] converts back, checking that what comes back is a permutation
//! of the input's triangles rather than trusting it.

pub mod fifo;
pub mod overdraw;
pub mod vcache;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::topology::Topology;
use crate::order::Order;

/// Recovers triangle ids from an index buffer that a library (meshoptimizer) produced by permuting
/// the input's triangles. A triangle may come back rotated (same winding); it must not come back
/// reversed or altered. Each returned triangle is looked up among the triangles of its first
/// vertex (O(valence), no hashing, so this adds little to the peer's measured time); duplicate
/// triangles are matched in input order.
pub fn order_from_index_buffer(mesh: &Mesh, topology: &Topology, indices: &[u32]) -> Result<Order> {
    let wrong = |what: String| Error::usage(format!("internal error: peer library returned {what}"));
    if indices.len() != 3 * mesh.triangle_count() {
        return Err(wrong(format!("{} indices for {} triangles", indices.len(), mesh.triangle_count())));
    }
    let same_rotation = |t: [u32; 3], u: [u32; 3]| (0..3).any(|k| [t[k], t[(k + 1) % 3], t[(k + 2) % 3]] == u);
    let mut used = vec![false; mesh.triangle_count()];
    indices
        .chunks_exact(3)
        .map(|c| {
            let tri = [c[0], c[1], c[2]];
            let candidates = topology.vertex_triangles.row(tri[0] as usize);
            let found = candidates
                .iter()
                .copied()
                .find(|&t| !used[t as usize] && same_rotation(mesh.triangles[t as usize], tri))
                .ok_or_else(|| wrong(format!("triangle {tri:?}, which is not one of the input's")))?;
            used[found as usize] = true;
            Ok(found)
        })
        .collect()
}
