//! Walks over the squares of a regular triangulated grid, shared by `snake` and `hilbert`:
//! recognising the grid, and turning a path of squares into a triangle order that follows
//! Bogomjakov & Gotsman 2002, Fig. 2 (two triangles per square, the one on the entry side first).
//!
//! The grid is the exact layout `grid:WxH` generates (see [`crate::mesh::procedural`]): square
//! (x, y) is `s = y·W + x` with corners a = (x, y), b = (x+1, y), c = (x+1, y+1), d = (x, y+1)
//! (vertex `y·(W+1) + x`), triangle `2s` = [a, b, c] (lower right) and `2s + 1` = [a, c, d]
//! (upper left). The lower-right triangle holds the square's bottom and right sides, the
//! upper-left one its top and left sides.
//!
//! Why a walk over squares cannot always be edge-continuous: every dual edge joins a lower-right
//! triangle to an upper-left one, so a continuous path alternates between them, and a square
//! drawn (upper-left, lower-right) must be followed by one drawn the same way, which lies to the
//! right or below; (lower-right, upper-left) squares only lead left or up. A path that turns
//! between these two families of moves (every row turn of a snake, many Hilbert turns) must
//! therefore take one step between triangles that share a vertex but not an edge.
//! [`RegularGrid::emit`] takes exactly those steps and no others.

use crate::mesh::Mesh;

use crate::order::Order;

/// A recognised regular grid of `w` × `h` squares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct RegularGrid {
    pub w: u32,
    pub h: u32,
}

/// A side of a square, as seen from inside it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Left,
    Right,
    Bottom,
    Top,
}

impl Side {
    /// Whether this side belongs to the lower-right triangle (`2s`) rather than the upper-left one.
    fn on_lower_right(self) -> bool {
        matches!(self, Side::Right | Side::Bottom)
    }
}

impl RegularGrid {
    /// The grid, if `mesh` has exactly the `grid:WxH` triangle layout. Recognition is structural
    /// (W is read off triangle 0 = [0, 1, W+2], H from the triangle count, then every triangle
    /// and the vertex count are checked), so a grid saved and reloaded is still recognised, and a
    /// reordered or edited grid is not — whatever the mesh is called. Positions are not looked
    /// at: the walks only use connectivity.
    pub fn recognize(mesh: &Mesh) -> Option<RegularGrid> {
        let first = *mesh.triangles.first()?;
        if first[0] != 0 || first[1] != 1 || first[2] < 3 {
            return None;
        }
        let w = u64::from(first[2]) - 2;
        let n = mesh.triangles.len() as u64;
        if !n.is_multiple_of(2 * w) {
            return None;
        }
        let h = n / (2 * w);
        let vertices = (w + 1).checked_mul(h + 1)?;
        if vertices != mesh.vertex_count() as u64 || u32::try_from(vertices).is_err() {
            return None;
        }
        let (w, h) = (u32::try_from(w).ok()?, u32::try_from(h).ok()?);
        let grid = RegularGrid { w, h };
        let all_match = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).all(|(x, y)| {
            let s = grid.square(x, y) as usize;
            let [a, b, c, d] = grid.corners(x, y);
            mesh.triangles[2 * s] == [a, b, c] && mesh.triangles[2 * s + 1] == [a, c, d]
        });
        all_match.then_some(grid)
    }

    fn square(&self, x: u32, y: u32) -> u32 {
        y * self.w + x
    }

    fn corners(&self, x: u32, y: u32) -> [u32; 4] {
        let v = |x: u32, y: u32| y * (self.w + 1) + x;
        [v(x, y), v(x + 1, y), v(x + 1, y + 1), v(x, y + 1)]
    }

    /// The triangle order for a walk visiting every square once (`path` in (x, y) cells).
    ///
    /// Within each square the triangle touching the side the walk came in by is drawn first, so
    /// consecutive triangles share an edge wherever the grid allows (see the module comment).
    /// The first square of the walk, and any square reached by a jump from a non-adjacent one,
    /// has no entry side: its triangles are drawn so that the second touches the side the walk
    /// leaves by (if the next square is adjacent).
    pub fn emit(&self, path: &[(u32, u32)]) -> Order {
        let mut order = Vec::with_capacity(2 * path.len());
        for (i, &(x, y)) in path.iter().enumerate() {
            let entry = i.checked_sub(1).and_then(|p| side_towards((x, y), path[p]));
            let exit = path.get(i + 1).and_then(|&next| side_towards((x, y), next));
            let lower_right_first = match (entry, exit) {
                (Some(side), _) => side.on_lower_right(),
                (None, Some(side)) => !side.on_lower_right(),
                (None, None) => true,
            };
            let s = self.square(x, y);
            let (lower_right, upper_left) = (2 * s, 2 * s + 1);
            if lower_right_first {
                order.extend([lower_right, upper_left]);
            } else {
                order.extend([upper_left, lower_right]);
            }
        }
        order
    }
}

/// The side of square `from` that faces square `to`, if they are edge-adjacent.
fn side_towards(from: (u32, u32), to: (u32, u32)) -> Option<Side> {
    let (dx, dy) = (i64::from(to.0) - i64::from(from.0), i64::from(to.1) - i64::from(from.1));
    match (dx, dy) {
        (-1, 0) => Some(Side::Left),
        (1, 0) => Some(Side::Right),
        (0, -1) => Some(Side::Bottom),
        (0, 1) => Some(Side::Top),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    fn grid(spec: &str) -> Mesh {
        procedural::generate(spec, 0).unwrap().unwrap()
    }

    #[test]
    fn recognises_grids_only() {
        assert_eq!(RegularGrid::recognize(&grid("grid:16x8")), Some(RegularGrid { w: 16, h: 8 }));
        assert_eq!(RegularGrid::recognize(&grid("grid:1x1")), Some(RegularGrid { w: 1, h: 1 }));
        assert_eq!(RegularGrid::recognize(&grid("grid:3x7")), Some(RegularGrid { w: 3, h: 7 }));
        let mut shuffled = grid("grid:4x4");
        shuffled.triangles.swap(3, 9);
        assert_eq!(RegularGrid::recognize(&shuffled), None);
        assert_eq!(RegularGrid::recognize(&grid("disk:950")), None);
        assert_eq!(RegularGrid::recognize(&grid("layers:3")), None);
    }

    #[test]
    fn entry_side_triangle_comes_first() {
        let g = RegularGrid { w: 2, h: 2 };
        // (0,0) → (1,0) → (1,1) → (0,1): start exits right (lower right last), then enter from
        // the left (upper left first), from below (lower right first), from the right.
        assert_eq!(g.emit(&[(0, 0), (1, 0), (1, 1), (0, 1)]), vec![1, 0, 3, 2, 6, 7, 4, 5]);
    }
}
