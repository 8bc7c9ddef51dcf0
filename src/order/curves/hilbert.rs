//! `hilbert`: the Hilbert space-filling curve of Bogomjakov & Gotsman 2002, §2.1 and Fig. 2(b) —
//! the squares of a regular grid in Hilbert order, the two triangles of each square drawn entry
//! side first. It is the construction their recursive cut generalises: split into quarters,
//! draw each quarter recursively, the last triangle of a quarter next to the first of the next.
//!
//! On the grid (`grid:WxH`, recognised by its exact layout, see [`super::grid_walk`]) the square
//! path is the generalised Hilbert curve ("gilbert", J. Červený, after the classical recursive
//! construction) from the bottom-left square to the bottom-right one (to the top-left one when
//! H > W). For a 2^m square it is the classical Hilbert curve; for a 2:1 grid such as B&G's
//! 16×8 it is two such curves side by side, each from its bottom-left to its bottom-right corner,
//! exactly as in their figure; for other sizes it stays continuous, which a power-of-two curve
//! with absent cells skipped would not — except for one diagonal step when the long side is odd
//! and the short one even, where the two end squares have the same checkerboard colour and no
//! continuous path over the (even number of) squares can join them. Consecutive triangles share
//! an edge except where the curve turns between leftward/upward and rightward/downward moves:
//! there no walk over whole squares can keep an edge (see [`super::grid_walk`]) and they share a
//! vertex (51 such steps on 16×8, counted in the tests).
//!
//! Elsewhere (ours, not theirs): triangle centroids are snapped to cubic cells holding about one
//! triangle ([`super::centroid_grid`]) and sorted by their index along a Hilbert curve (Skilling
//! 2004, "Programming the Hilbert curve") of dimension 3, or 2 for a flat mesh (or 1 for a
//! line), so a planar mesh gets a planar curve rather than slices of a 3D one. Triangles in one
//! cell are drawn in id order.

use super::centroid_grid::CentroidGrid;
use super::grid_walk::RegularGrid;
use crate::error::Result;
use crate::mesh::Scene;
use crate::order::{Cost, Method, Order, Ordering, Orders, Params};

pub static METHOD: Method = Method {
    name: "hilbert",
    summary: "Hilbert curve over grid squares (elsewhere: our Hilbert curve over triangle centroids)",
    source: "Bogomjakov & Gotsman 2002, §2.1, Fig. 2(b); gilbert for any grid size; non-grid generalisation ours",
    peer: false,
    per_node: false,
    cost: Cost::Linear,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(Hilbert)
}

struct Hilbert;

impl Ordering for Hilbert {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        Ok(Orders::from(match RegularGrid::recognize(&scene.mesh) {
            Some(grid) => grid.emit(&gilbert(grid.w, grid.h)),
            None => centroid_hilbert(&CentroidGrid::new(&scene.mesh)),
        }))
    }
}

/// Every cell of a `w` × `h` rectangle along the generalised Hilbert curve, from (0, 0) to
/// (w − 1, 0) when w ≥ h, else to (0, h − 1).
fn gilbert(w: u32, h: u32) -> Vec<(u32, u32)> {
    let mut path = Vec::with_capacity(w as usize * h as usize);
    let (w, h) = (i64::from(w), i64::from(h));
    if w >= h {
        gilbert_block(&mut path, (0, 0), (w, 0), (0, h));
    } else {
        gilbert_block(&mut path, (0, 0), (0, h), (w, 0));
    }
    path
}

/// Fills the block at `origin` spanned by `major` (the direction the curve advances, its full
/// length) and `minor` (the other side), entering at `origin` and leaving at the far end of
/// `major`'s side. Long blocks (major > 1.5 × minor) are cut in two along the major axis; others
/// in three as the Hilbert curve does (a quarter turned towards the minor axis, the full-length
/// far half, a quarter coming back), with halves made even where possible so the pieces connect.
fn gilbert_block(path: &mut Vec<(u32, u32)>, origin: (i64, i64), major: (i64, i64), minor: (i64, i64)) {
    let ((x, y), (ax, ay), (bx, by)) = (origin, major, minor);
    let (w, h) = ((ax + ay).abs(), (bx + by).abs());
    let (dax, day, dbx, dby) = (ax.signum(), ay.signum(), bx.signum(), by.signum());
    if h == 1 || w == 1 {
        // A single row (or column): walk it.
        let (steps, dx, dy) = if h == 1 { (w, dax, day) } else { (h, dbx, dby) };
        for i in 0..steps {
            path.push(((x + i * dx) as u32, (y + i * dy) as u32));
        }
        return;
    }
    let (mut ax2, mut ay2, mut bx2, mut by2) = (ax / 2, ay / 2, bx / 2, by / 2);
    let (w2, h2) = ((ax2 + ay2).abs(), (bx2 + by2).abs());
    if 2 * w > 3 * h {
        if w2 % 2 == 1 && w > 2 {
            (ax2, ay2) = (ax2 + dax, ay2 + day);
        }
        gilbert_block(path, (x, y), (ax2, ay2), (bx, by));
        gilbert_block(path, (x + ax2, y + ay2), (ax - ax2, ay - ay2), (bx, by));
    } else {
        if h2 % 2 == 1 && h > 2 {
            (bx2, by2) = (bx2 + dbx, by2 + dby);
        }
        gilbert_block(path, (x, y), (bx2, by2), (ax2, ay2));
        gilbert_block(path, (x + bx2, y + by2), (ax, ay), (bx - bx2, by - by2));
        gilbert_block(
            path,
            (x + (ax - dax) + (bx2 - dbx), y + (ay - day) + (by2 - dby)),
            (-bx2, -by2),
            (-(ax - ax2), -(ay - ay2)),
        );
    }
}

/// Centroid cells sorted along a Hilbert curve over the axes that have more than one cell.
fn centroid_hilbert(grid: &CentroidGrid) -> Order {
    let axes: Vec<usize> = grid.axes_by_extent().into_iter().filter(|&a| grid.dims[a] > 1).collect();
    let largest = axes.first().map_or(1, |&a| grid.dims[a]);
    let bits = (u32::BITS - (largest - 1).leading_zeros()).max(1);
    grid.order_by(|cell| {
        let mut coords = [0u32; 3];
        for (k, &a) in axes.iter().enumerate() {
            coords[k] = cell[a];
        }
        hilbert_index(&mut coords[..axes.len()], bits)
    })
}

/// The distance along a `coords.len()`-dimensional Hilbert curve of side 2^`bits` of the cell
/// `coords` (each < 2^bits; `coords.len() · bits` ≤ 64). Skilling's transform to the
/// "transposed" index, then bit interleaving. `coords` is overwritten.
fn hilbert_index(coords: &mut [u32], bits: u32) -> u64 {
    let n = coords.len();
    if n == 0 {
        return 0;
    }
    let top = 1u32 << (bits - 1);
    // Inverse undo of the excess work.
    let mut q = top;
    while q > 1 {
        let p = q - 1;
        for i in 0..n {
            if coords[i] & q != 0 {
                coords[0] ^= p;
            } else {
                let t = (coords[0] ^ coords[i]) & p;
                coords[0] ^= t;
                coords[i] ^= t;
            }
        }
        q >>= 1;
    }
    // Gray encode.
    for i in 1..n {
        coords[i] ^= coords[i - 1];
    }
    let mut t = 0;
    let mut q = top;
    while q > 1 {
        if coords[n - 1] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    for c in coords.iter_mut() {
        *c ^= t;
    }
    // Interleave, most significant bit first, axis 0 first.
    let mut index = 0u64;
    for b in (0..bits).rev() {
        for &c in coords.iter() {
            index = (index << 1) | u64::from((c >> b) & 1);
        }
    }
    index
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adjacent(a: (u32, u32), b: (u32, u32)) -> bool {
        a.0.abs_diff(b.0) + a.1.abs_diff(b.1) == 1
    }

    #[test]
    fn gilbert_is_the_classical_curve_on_4x4() {
        let expected = [
            (0, 0),
            (1, 0),
            (1, 1),
            (0, 1),
            (0, 2),
            (0, 3),
            (1, 3),
            (1, 2),
            (2, 2),
            (2, 3),
            (3, 3),
            (3, 2),
            (3, 1),
            (2, 1),
            (2, 0),
            (3, 0),
        ];
        assert_eq!(gilbert(4, 4), expected);
    }

    #[test]
    fn gilbert_covers_every_rectangle_continuously() {
        for w in 1..=20 {
            for h in 1..=20 {
                let path = gilbert(w, h);
                let mut seen = vec![false; (w * h) as usize];
                for &(x, y) in &path {
                    assert!(x < w && y < h && !std::mem::replace(&mut seen[(y * w + x) as usize], true));
                }
                assert_eq!(path.len(), (w * h) as usize);
                let diagonal = path.windows(2).filter(|p| !adjacent(p[0], p[1])).count();
                // Continuous except for one diagonal step when the long side is odd and the short
                // one even: then both end squares have the same checkerboard colour, which no
                // continuous path over an even number of squares can join.
                let (long, short) = (w.max(h), w.min(h));
                let clash = long % 2 == 1 && short % 2 == 0;
                assert!(diagonal <= usize::from(clash), "{w}x{h}: {diagonal} jumps");
                if w.is_power_of_two() && (h == w || w == 2 * h) {
                    assert_eq!((diagonal, path[0], *path.last().unwrap()), (0, (0, 0), (w - 1, 0)));
                }
            }
        }
    }

    #[test]
    fn hilbert_index_visits_neighbours_in_turn() {
        for dims in 1..=3usize {
            let bits = 3;
            let side = 1u32 << bits;
            let mut cells: Vec<(u64, Vec<u32>)> = (0..side.pow(dims as u32))
                .map(|i| {
                    let c: Vec<u32> = (0..dims).map(|d| (i >> (bits * d as u32)) & (side - 1)).collect();
                    (hilbert_index(&mut c.clone(), bits), c)
                })
                .collect();
            cells.sort();
            for (k, pair) in cells.windows(2).enumerate() {
                assert_eq!(pair[0].0 + 1, pair[1].0);
                assert_eq!(k as u64 + 1, pair[1].0);
                let step: u32 = pair[0].1.iter().zip(&pair[1].1).map(|(a, b)| a.abs_diff(*b)).sum();
                assert_eq!(step, 1, "{dims}D: {:?} → {:?}", pair[0].1, pair[1].1);
            }
        }
    }
}
