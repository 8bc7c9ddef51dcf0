//! Static sorts for translucent meshes (seed 003, Chad Austin, "Update on Sorting Translucent
//! Triangles", 2014): one index order that an engine draws back to front, with blending and no
//! depth writes, from every view. Measured by the translucency metric
//! (`measure::translucency`), which the blog's author judged by eye.

pub mod coverage;
pub mod dist_angle;
mod pair_sort;
pub mod pairs;
pub mod peeling;
pub mod per_view;
pub mod topo;
