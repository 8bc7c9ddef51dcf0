//! Triangle centroids snapped to a grid of cubic cells, shared by the generalisations of `snake`
//! and `hilbert` to meshes that are not a regular grid (ours, not Bogomjakov & Gotsman's: their
//! Fig. 2 curves exist only on the grid). A curve over the cells, with ties broken by triangle
//! id, is then a triangle order.
//!
//! Cells are cubes (the same side on every axis, so neither curve is stretched) sized so that an
//! occupied cell holds about one triangle: a surface crosses a cube of side `s` over an area of
//! about s², so s = √(total area / triangle count). Finer cells would only leave more empty cells
//! for the curve to skip; coarser ones would leave more triangles in arbitrary (id) order.
//!
//! Everything is computed in f64 on the positions in the mesh's unit frame
//! ([`crate::mesh::frames::unit_positions64`]), so the cells, which the grid scales with the mesh,
//! are the same bits wherever the mesh stands and whatever its units.

use glam::DVec3;

use crate::mesh::Mesh;
use crate::mesh::frames::unit_positions64;
use crate::order::Order;

/// Most cells along one axis: 2^20, so three axes fit a 64-bit curve index.
pub(crate) const MAX_BITS: u32 = 20;

/// Each triangle's cell, and the grid's size in cells.
pub(crate) struct CentroidGrid {
    /// Cell coordinates of each triangle's centroid, each `< dims[axis]`.
    pub cells: Vec<[u32; 3]>,
    /// Cells along x, y, z (at least 1, at most 2^[`MAX_BITS`]).
    pub dims: [u32; 3],
}

impl CentroidGrid {
    pub fn new(mesh: &Mesh) -> CentroidGrid {
        let positions = unit_positions64(&mesh.positions);
        let corner = |v: u32| positions[v as usize];
        let centroids: Vec<DVec3> =
            mesh.triangles.iter().map(|t| (corner(t[0]) + corner(t[1]) + corner(t[2])) / 3.0).collect();
        let area: f64 = mesh
            .triangles
            .iter()
            .map(|t| 0.5 * (corner(t[1]) - corner(t[0])).cross(corner(t[2]) - corner(t[0])).length())
            .sum();
        let (lo, hi) =
            centroids.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        let extent = (hi - lo).max(DVec3::ZERO);
        let n = centroids.len().max(1) as f64;
        // One triangle per occupied cell; without area (all triangles degenerate), as many cells
        // as triangles in the bounding cube.
        let mut side = (area / n).sqrt();
        if !(side.is_finite() && side > 0.0) {
            side = extent.max_element() / n.cbrt();
        }
        let max_cells = f64::from(1u32 << MAX_BITS);
        // Never more than 2^MAX_BITS cells along an axis: coarsen rather than clamp.
        side = side.max(extent.max_element() / (max_cells - 1.0));
        let dims_of = |e: f64| {
            if side > 0.0 && side.is_finite() { (e / side).floor().clamp(0.0, max_cells - 1.0) as u32 + 1 } else { 1 }
        };
        let dims = [dims_of(extent.x), dims_of(extent.y), dims_of(extent.z)];
        let cells = centroids
            .iter()
            .map(|&c| {
                let rel = c - lo;
                let cell = |r: f64, d: u32| if d > 1 { ((r / side) as u32).min(d - 1) } else { 0 };
                [cell(rel.x, dims[0]), cell(rel.y, dims[1]), cell(rel.z, dims[2])]
            })
            .collect();
        CentroidGrid { cells, dims }
    }

    /// The axes from the most cells to the fewest (ties: x before y before z).
    pub fn axes_by_extent(&self) -> [usize; 3] {
        let mut axes = [0, 1, 2];
        axes.sort_by_key(|&a| std::cmp::Reverse(self.dims[a]));
        axes
    }

    /// Triangles sorted by `key(cell)`, ties by triangle id.
    pub fn order_by(&self, key: impl Fn([u32; 3]) -> u64) -> Order {
        let mut keyed: Vec<(u64, u32)> = self.cells.iter().enumerate().map(|(t, &c)| (key(c), t as u32)).collect();
        keyed.sort_unstable();
        keyed.into_iter().map(|(_, t)| t).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    #[test]
    fn about_one_triangle_per_cell_on_a_plane() {
        let mesh = procedural::generate("grid:32x16", 0).unwrap().unwrap();
        let grid = CentroidGrid::new(&mesh);
        // Area 512, 1024 triangles: side √0.5, so 32/0.707 → 44 and 16/0.707 → 22 cells (+1).
        assert_eq!(grid.dims[2], 1);
        assert!((40..=48).contains(&grid.dims[0]) && (20..=24).contains(&grid.dims[1]), "{:?}", grid.dims);
        assert_eq!(grid.axes_by_extent(), [0, 1, 2]);
        assert!(grid.cells.iter().all(|c| (0..3).all(|a| c[a] < grid.dims[a])));
    }

    #[test]
    fn degenerate_meshes_get_one_cell() {
        use crate::mesh::VertexAttributes;
        let mesh =
            Mesh::new("flat", vec![glam::Vec3::ZERO; 3], vec![[0, 1, 2], [0, 0, 0]], VertexAttributes::default())
                .unwrap();
        let grid = CentroidGrid::new(&mesh);
        assert_eq!(grid.dims, [1, 1, 1]);
        assert_eq!(grid.order_by(|_| 0), vec![0, 1]);
    }
}
