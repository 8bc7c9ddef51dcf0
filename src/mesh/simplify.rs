//! Lower resolutions of a mesh, made by meshoptimizer's edge-collapse simplifier (the `meshopt`
//! crate), for ACMR against mesh resolution (Bogomjakov & Gotsman 2002, Fig. 8b and 8d: every
//! resolution is ordered from scratch). Their models' intermediate resolutions came from their
//! own simplifier; ours differ in shape but not in what the figure asks, which is how an
//! ordering's ACMR behaves as the triangle count falls.
//!
//! A model source `PATH@N` (e.g. `models/bun_zipper.ply@20000`, see [`super::source`]) names the
//! model at N triangles.

use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// How far from the requested count a result may land: the simplifier collapses edges in
/// batches, so it may pass the target by a few triangles, and stops short when no collapse is left.
const TOLERANCE: f64 = 0.02;

/// `mesh` simplified to about `target` triangles (within 2%), unused vertices dropped and
/// the rest numbered in order of first use. Attributes follow their vertices; the simplifier
/// keeps attribute seams (vertices with equal positions but different attributes) in place.
pub fn simplify(mesh: &Mesh, target: usize) -> Result<Mesh> {
    let name = format!("{}@{target}", mesh.name);
    if target >= mesh.triangle_count() {
        return Err(Error::input(
            &name,
            format!("asks for {target} triangles but the model has only {}", mesh.triangle_count()),
        ));
    }
    let indices = mesh.index_buffer();
    // Error limit 1.0 (the whole model's extent): the triangle count alone decides where to stop.
    let simplified =
        meshopt::simplify(&indices, &mesh.meshopt_positions(), 3 * target, 1.0, meshopt::SimplifyOptions::None, None);
    let reached = simplified.len() / 3;
    if (reached as f64 - target as f64).abs() > target as f64 * TOLERANCE {
        return Err(Error::input(
            &name,
            format!("the simplifier stopped at {reached} triangles, not within 2% of the {target} asked for"),
        ));
    }
    let triangles: Vec<[u32; 3]> = simplified.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    Ok(Mesh { name, triangles, ..mesh.clone() }.without_unused_vertices())
}
