//! Orders along space-filling curves over a grid: `snake` (boustrophedon rows, Bogomjakov &
//! Gotsman 2002, Fig. 2) and `hilbert`. Both walk the exact layout of `grid:WxH` when they
//! recognise it ([`grid_walk`]) and otherwise bin triangle centroids into cells holding about one
//! triangle each ([`centroid_grid`]).

mod centroid_grid;
mod grid_walk;
pub mod hilbert;
pub mod snake;
