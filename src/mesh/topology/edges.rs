//! Edge structures over welded vertices that the strip-growing orderings (`hoppe`, `kcache`)
//! walk: the triangle across each edge, and which triangles repeat an earlier one.

/// No face, corner or vertex.
pub const NONE: u32 = u32::MAX;

/// The triangle across each edge, as a *corner*: slot `3·t + k` describes edge k of triangle t,
/// from `tri[k]` to `tri[k+1]` (welded); it holds `3·g + e` where edge e of triangle g is the same
/// welded edge run the other way, or [`NONE`]. Read it as "enter g across its edge e": the
/// corner of g at `g[e]`, which is (welded) `tri[k+1]`.
///
/// Only edges used by exactly two different triangles with opposite orientation are linked
/// (DirectXMesh's rule): a fin, a duplicated face or a flipped neighbour has no well-defined
/// "next face around the vertex", so we treat such edges as boundaries.
///
/// Two kinds of triangles are left out of the adjacency altogether, so that they do not make the
/// edges of real neighbours non-manifold: degenerate ones (two corners welded together: no area,
/// no "around") and copies of an earlier triangle (see [`copies`]; scanned meshes carry them,
/// dragon_vrip_res3 has 1,254, each of which would otherwise cut its original and three
/// neighbours out of the strips).
pub fn edge_neighbors(triangles: &[[u32; 3]], weld: &[u32]) -> Vec<u32> {
    let copy_of = copies(triangles, weld);
    let mut half_edges: Vec<(u64, u32, bool)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        let w = tri.map(|v| weld[v as usize]);
        if copy_of[t] != NONE || w[0] == w[1] || w[1] == w[2] || w[2] == w[0] {
            continue;
        }
        for k in 0..3 {
            let (a, b) = (w[k], w[(k + 1) % 3]);
            let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
            half_edges.push((key, (3 * t + k) as u32, a < b));
        }
    }
    half_edges.sort_unstable();
    let mut across = vec![NONE; 3 * triangles.len()];
    for group in half_edges.chunk_by(|x, y| x.0 == y.0) {
        if let [x, y] = group
            && x.2 != y.2
            && x.1 / 3 != y.1 / 3
        {
            across[x.1 as usize] = y.1;
            across[y.1 as usize] = x.1;
        }
    }
    across
}

/// For each triangle, the first triangle with the same three welded corners (in either
/// orientation), or [`NONE`] for a triangle that is not a copy. Degenerate triangles (two corners
/// welded together) are never copies: they have no area and no adjacency (see
/// [`edge_neighbors`]) anyway.
pub fn copies(triangles: &[[u32; 3]], weld: &[u32]) -> Vec<u32> {
    let mut keyed: Vec<([u32; 3], u32)> = triangles
        .iter()
        .enumerate()
        .filter_map(|(t, tri)| {
            let mut w = tri.map(|v| weld[v as usize]);
            w.sort_unstable();
            (w[0] != w[1] && w[1] != w[2]).then_some((w, t as u32))
        })
        .collect();
    keyed.sort_unstable();
    let mut copy_of = vec![NONE; triangles.len()];
    for group in keyed.chunk_by(|x, y| x.0 == y.0) {
        for x in &group[1..] {
            copy_of[x.1 as usize] = group[0].1;
        }
    }
    copy_of
}
