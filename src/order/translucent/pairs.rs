//! What the quadratic sorts of seed 003 share: the pairs of triangles that can cover one another,
//! the exact static predicates on a pair, and the coverage approximation.
//!
//! **Pruning.** The blog's topological sort and coverage peeling look at all n² pairs, which is
//! what ran out of memory on large meshes. Here only pairs whose projected footprints overlap
//! from some viewpoint are looked at: each triangle's front-facing fragments are rasterized from
//! an icosphere of viewpoints (orthographic, as the overdraw metric's views; `views` of them at
//! `res`² pixels), and every two triangles that share a pixel are a pair, with the number of
//! (view, pixel) samples they share as its weight. A pair no viewpoint sees overlap is never
//! drawn wrongly from those viewpoints, whatever its order; one that overlaps by less than a
//! pixel may be missed (the price of not paying n²). Per pixel at most [`MAX_LAYERS`] fragments,
//! the nearest, are paired: deeper layers are covered many times over anyway.
//!
//! **Predicates, for all views at once** (the static case of the blog). With `n_X` the unit
//! normal of triangle X and its plane through its corners:
//! - *X faces Y*: every corner of Y lies on the front side of X's plane or on it (signed distance
//!   ≥ −ε, ε = 10⁻⁹ of the unit frame), and some corner strictly in front (> ε).
//! - *A is in front of B* (A covers B): the pair overlaps from some viewpoint (above).
//!
//! If B faces A and A does not face B, then from every eye that sees both front faces, a ray that
//! meets both meets A first: the eye and A lie on B's front side, and a ray leaving B's plane
//! towards the back cannot come back to A; so A must be blended after B, and B → A is an arc of
//! the "draw before" digraph. (The blog words this as "A should be rendered before B"; for a
//! back-to-front blend the covering triangle is drawn last, so the arc points the other way
//! here.) Pairs that face each other (a concave fold) or cut each other's planes get no arc: which
//! one is in front depends on the view.
//!
//! **Coverage** of B by A, for the coverage sort and peeling: the blog approximates the form
//! factor "using area of covering triangle, distance between triangle centers, and incident
//! angles". Here: `area(A) · max(0, n_A·w) · max(0, n_B·w) / (π d²)`, clamped to 1, with `d` the
//! distance between the centroids and `w` the unit vector from B's centroid to A's (the form
//! factor of a small patch A seen from B, counted only when A lies in front of B and faces away
//! from it, i.e. when A can hide B).

use glam::DVec3;
use rayon::prelude::*;

use crate::error::Result;
use crate::mesh::Scene;
use crate::raster::cpu;
use crate::raster::views::{icosphere_directions, orthographic};

/// The most fragments per pixel that are paired, nearest first.
pub const MAX_LAYERS: usize = 8;

/// Tolerance of the plane tests, in the unit frame.
const EPSILON: f64 = 1e-9;

/// A pair of triangles `a < b` whose footprints overlap, and on how many samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pair {
    pub a: u32,
    pub b: u32,
    pub samples: u32,
}

/// Every pair of triangles of `scene` (a still) whose front faces share a pixel from some view of
/// an icosphere of `views` directions at `res`², with the samples they share.
pub fn overlapping(scene: &Scene, views: u32, res: u32) -> Result<Vec<Pair>> {
    let mesh = &scene.mesh;
    let framing = scene.frames.framing;
    let directions = icosphere_directions(views);
    let per_view = directions
        .par_iter()
        .map(|&d| {
            let mut fragments = Vec::new();
            cpu::fragments(&mesh.positions, &mesh.triangles, &orthographic(framing, d), res, &mut fragments)?;
            // Per pixel, its fragments nearest first.
            fragments.sort_unstable_by(|x, y| x.pixel.cmp(&y.pixel).then(x.depth.total_cmp(&y.depth)));
            let mut keys: Vec<u64> = Vec::new();
            for pixel in fragments.chunk_by(|x, y| x.pixel == y.pixel) {
                let layers = &pixel[..pixel.len().min(MAX_LAYERS)];
                for (i, x) in layers.iter().enumerate() {
                    for y in &layers[i + 1..] {
                        let (a, b) = (x.triangle.min(y.triangle), x.triangle.max(y.triangle));
                        if a != b {
                            keys.push(u64::from(a) << 32 | u64::from(b));
                        }
                    }
                }
            }
            keys.sort_unstable();
            Ok(keys)
        })
        .collect::<Result<Vec<Vec<u64>>>>()?;
    let mut all: Vec<u64> = per_view.into_iter().flatten().collect();
    all.par_sort_unstable();
    Ok(all
        .chunk_by(|x, y| x == y)
        .map(|run| Pair { a: (run[0] >> 32) as u32, b: run[0] as u32, samples: run.len() as u32 })
        .collect())
}

/// A triangle's plane and shape in the unit frame, for the predicates.
#[derive(Debug, Clone, Copy)]
pub struct Facet {
    pub corners: [DVec3; 3],
    pub normal: DVec3,
    pub centroid: DVec3,
    pub area: f64,
}

/// Every triangle of `scene` as a [`Facet`] in its unit frame (f64).
pub fn facets(scene: &Scene) -> Vec<Facet> {
    let framing = scene.frames.framing;
    let unit: Vec<DVec3> = scene.mesh.positions.iter().map(|&p| framing.to_unit64(p)).collect();
    scene
        .mesh
        .triangles
        .iter()
        .map(|t| {
            let corners = t.map(|v| unit[v as usize]);
            let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            Facet {
                corners,
                normal: cross.normalize_or_zero(),
                centroid: (corners[0] + corners[1] + corners[2]) / 3.0,
                area: cross.length() / 2.0,
            }
        })
        .collect()
}

/// Whether `x` faces `y`: `y` on the front side of `x`'s plane (touching allowed), not within it.
pub fn faces(x: &Facet, y: &Facet) -> bool {
    let distance = |p: DVec3| (p - x.corners[0]).dot(x.normal);
    let d = y.corners.map(distance);
    x.normal != DVec3::ZERO && d.iter().all(|&v| v >= -EPSILON) && d.iter().any(|&v| v > EPSILON)
}

/// The arc of a pair, if the predicates give one: `(behind, in_front)`, drawn in that order.
pub fn arc(facets: &[Facet], pair: &Pair) -> Option<(u32, u32)> {
    let (a, b) = (&facets[pair.a as usize], &facets[pair.b as usize]);
    match (faces(a, b), faces(b, a)) {
        // B faces A, A does not face B: A covers B.
        (false, true) => Some((pair.b, pair.a)),
        (true, false) => Some((pair.a, pair.b)),
        _ => None,
    }
}

/// How much `a` covers `b` (the form-factor approximation above).
pub fn coverage(a: &Facet, b: &Facet) -> f64 {
    let between = a.centroid - b.centroid;
    let d2 = between.length_squared();
    if d2 == 0.0 {
        return 0.0;
    }
    let w = between / d2.sqrt();
    (a.area * a.normal.dot(w).max(0.0) * b.normal.dot(w).max(0.0) / (std::f64::consts::PI * d2)).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facet(corners: [[f64; 3]; 3]) -> Facet {
        let corners = corners.map(DVec3::from_array);
        let cross = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        Facet {
            corners,
            normal: cross.normalize(),
            centroid: (corners[0] + corners[1] + corners[2]) / 3.0,
            area: cross.length() / 2.0,
        }
    }

    #[test]
    fn a_layer_above_covers_the_one_below() {
        // Two parallel triangles facing +z, `top` at z = 1: top covers bottom from above.
        let bottom = facet([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        let top = facet([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]);
        assert!(faces(&bottom, &top) && !faces(&top, &bottom));
        let facets = [bottom, top];
        assert_eq!(arc(&facets, &Pair { a: 0, b: 1, samples: 1 }), Some((0, 1)), "bottom first, then top");
        assert!(coverage(&top, &bottom) > 0.0 && coverage(&bottom, &top) == 0.0);
        // Two faces of a convex solid (a roof ridge) never cover each other: no arc.
        let left = facet([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, -1.0]]);
        let right = facet([[0.0, 0.0, 0.0], [1.0, 0.0, -1.0], [0.0, 1.0, 0.0]]);
        assert!(!faces(&left, &right) && !faces(&right, &left));
        assert_eq!(arc(&[left, right], &Pair { a: 0, b: 1, samples: 1 }), None);
        // The same two seen from inside (a valley): they face each other, and still no arc.
        let (valley_left, valley_right) = (
            facet([[0.0, 0.0, 0.0], [-1.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
            facet([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, -1.0]]),
        );
        assert!(faces(&valley_left, &valley_right) && faces(&valley_right, &valley_left));
        assert_eq!(arc(&[valley_left, valley_right], &Pair { a: 0, b: 1, samples: 1 }), None);
    }
}
