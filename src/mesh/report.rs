//! What is unusual about a mesh, counted and reported, never silently repaired.
//!
//! Degenerate triangles (a repeated index, or zero area), duplicates, non-manifold and
//! inconsistently wound edges all change what orderings and metrics do, so `triorder` prints
//! these counts when it loads a mesh and keeps every triangle as given.

use std::collections::HashSet;
use std::fmt;

use glam::Vec3;

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
    /// Triangles with three distinct indices but zero area (collinear or coincident positions),
    /// decided exactly on the stored coordinates ([`has_zero_area`]), so at any scale.
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
                zero_area += usize::from(has_zero_area(tri.map(|v| mesh.positions[v as usize])));
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

/// Whether the triangle `[a, b, c]` has exactly zero area: its corners collinear, or two of them
/// at one point. Its cross product (b − a) × (c − a) is evaluated exactly: each component, a 2×2
/// determinant of the coordinates, expands into six products of two f32 coordinates, each exact
/// in f64 (48 significant bits, no overflow or underflow for any f32), summed without rounding
/// ([`exact_sum_is_zero`]). Computed in f32, the cross product of a proper triangle of a 1e-30
/// mesh underflowed to zero (and every triangle was reported degenerate); a threshold relative to
/// the mesh's size would instead call thin but proper triangles degenerate.
pub fn has_zero_area([a, b, c]: [Vec3; 3]) -> bool {
    // The filter: in f64 the cross product of a triangle with an area worth the name is far from
    // zero (its rounding error is a few units in the last place of the edges' product), so only
    // nearly degenerate triangles take the exact path.
    let (d1, d2) = (b.as_dvec3() - a.as_dvec3(), c.as_dvec3() - a.as_dvec3());
    let bound = 8.0 * f64::EPSILON * d1.abs().element_sum() * d2.abs().element_sum();
    if d1.cross(d2).abs().max_element() > bound {
        return false;
    }
    // The determinant of rows (a_u, a_v, 1), (b_u, b_v, 1), (c_u, c_v, 1) over the axes u, v: the
    // component of the cross product along the third axis.
    let orient = |u: usize, v: usize| {
        let p = |x: Vec3, y: Vec3| f64::from(x[u]) * f64::from(y[v]);
        [p(a, b), -p(b, a), p(b, c), -p(c, b), p(c, a), -p(a, c)]
    };
    exact_sum_is_zero(&orient(1, 2)) && exact_sum_is_zero(&orient(2, 0)) && exact_sum_is_zero(&orient(0, 1))
}

/// Whether `terms` (finite, far from overflow) sum to exactly zero: they are added into a
/// nonoverlapping expansion by error-free two-sums (Shewchuk 1997, "Adaptive precision
/// floating-point arithmetic and fast robust geometric predicates", Grow-Expansion), whose
/// components then sum exactly to the terms' sum, and which is zero only when every component is.
fn exact_sum_is_zero<const N: usize>(terms: &[f64; N]) -> bool {
    let mut expansion = [0.0f64; N];
    for (n, &term) in terms.iter().enumerate() {
        let mut q = term;
        for e in &mut expansion[..n] {
            let s = q + *e;
            let b = s - q;
            let error = (q - (s - b)) + (*e - b);
            (q, *e) = (s, error);
        }
        expansion[n] = q;
    }
    expansion.iter().all(|&e| e == 0.0)
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

    #[test]
    fn zero_area_is_exact_at_any_scale() {
        let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        for s in [1e-38f32, 1e-30, 1e-25, 1.0, 1e20, 1e30, 1e38] {
            // A proper right triangle: its f32 cross product underflows below 1e-23 and overflows
            // above 1e19, its exact one does neither.
            assert!(!has_zero_area([v(0., 0., 0.), v(s, 0., 0.), v(0., s, 0.)]), "{s}");
            assert!(!has_zero_area([v(s, s, s), v(2. * s, s, -s), v(s, 3. * s, s)]), "{s}");
            // Collinear and coincident corners, along a diagonal and off the axes.
            assert!(has_zero_area([v(s, s, s), v(2. * s, 2. * s, 2. * s), v(-s, -s, -s)]), "{s}");
            assert!(has_zero_area([v(0., s, 0.), v(0., s, 0.), v(s, 0., s)]), "{s}");
        }
        // Far from the origin, a sliver one ulp off the line is proper; on it, degenerate.
        let (a, b) = (v(1e7, 0., 5.), v(1e7 + 2., 2., 5.));
        assert!(!has_zero_area([a, b, v(1e7 + 1., 2., 5.)]));
        assert!(has_zero_area([a, b, v(1e7 + 1., 1., 5.)]));
        // Terms that cancel only exactly: 2^60 + 1 − 2^60 − 1 with the ones lost in any f64 sum.
        assert!(exact_sum_is_zero(&[2f64.powi(60), 1.0, -(2f64.powi(60)), -1.0]));
        assert!(!exact_sum_is_zero(&[2f64.powi(60), 1.0, -(2f64.powi(60))]));
    }
}
