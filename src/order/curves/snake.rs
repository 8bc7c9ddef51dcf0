//! `snake`: the "simple snake raster" of Bogomjakov & Gotsman 2002, §2.1 and Fig. 2(a) — the
//! squares of a regular grid row by row, alternating direction (boustrophedon), the two triangles
//! of each square drawn entry side first. B&G use it as the simplest space-filling reference:
//! on the grid it is no worse than Hilbert or recursive cut at very small or very large caches
//! (their Fig. 5a), since once a row of vertices fits in the cache every vertex misses once.
//!
//! On the grid (`grid:WxH`, recognised by its exact triangle layout, see [`super::grid_walk`])
//! row 0 runs left to right, row 1 right to left, and so on. Consecutive triangles share an edge
//! except at the H − 1 row turns, where they share a vertex: with every square cut by the same
//! diagonal no walk over whole squares can turn a row without such a step (proof in
//! [`super::grid_walk`]), and the entry-side rule takes exactly one per turn.
//!
//! Elsewhere the paper defines nothing; our generalisation (not theirs) snaps triangle centroids
//! to cubic cells holding about one triangle each ([`super::centroid_grid`]) and scans them as a
//! 3D boustrophedon: columns along the axis with the most cells, rows along the next, slabs along
//! the last; every row reverses the column direction and every slab the row direction, so the
//! scan never jumps across the mesh between consecutive cells. Triangles in one cell are drawn in
//! id order.

use super::centroid_grid::CentroidGrid;
use super::grid_walk::RegularGrid;
use crate::error::Result;
use crate::mesh::Scene;
use crate::order::{Cost, Method, Order, Ordering, Orders, Params};

pub static METHOD: Method = Method {
    name: "snake",
    summary: "boustrophedon rows of grid squares (elsewhere: our 3D boustrophedon over triangle centroids)",
    source: "Bogomjakov & Gotsman 2002, §2.1, Fig. 2(a); non-grid generalisation ours",
    peer: false,
    per_node: false,
    cost: Cost::Linear,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(Snake)
}

struct Snake;

impl Ordering for Snake {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        Ok(Orders::from(match RegularGrid::recognize(&scene.mesh) {
            Some(grid) => grid.emit(&grid_path(grid.w, grid.h)),
            None => centroid_snake(&CentroidGrid::new(&scene.mesh)),
        }))
    }
}

/// Squares row by row from the bottom, even rows left to right, odd rows right to left.
fn grid_path(w: u32, h: u32) -> Vec<(u32, u32)> {
    (0..h).flat_map(|y| (0..w).map(move |i| (if y % 2 == 0 { i } else { w - 1 - i }, y))).collect()
}

/// The 3D boustrophedon over centroid cells.
fn centroid_snake(grid: &CentroidGrid) -> Order {
    let [column, row, slab] = grid.axes_by_extent();
    let (columns, rows) = (u64::from(grid.dims[column]), u64::from(grid.dims[row]));
    grid.order_by(|cell| {
        let k = u64::from(cell[slab]);
        let j = u64::from(cell[row]);
        let j = if k % 2 == 0 { j } else { rows - 1 - j };
        // Rows visited so far, over all slabs: its parity flips the column direction each row.
        let i = u64::from(cell[column]);
        let i = if (k * rows + j) % 2 == 0 { i } else { columns - 1 - i };
        (k * rows + j) * columns + i
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boustrophedon_rows() {
        assert_eq!(grid_path(3, 2), vec![(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)]);
    }
}
