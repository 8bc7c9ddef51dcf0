//! `translucent-dist-angle`: seed 003's "Sort by Distance and Angle to Center": every triangle
//! sorted by the dot product of its unit normal with the vector from the mesh's centre to the
//! triangle's centroid, smallest first.
//!
//! The blog calls it "a cheapo algorithm that works pretty well on convex shapes": on a closed
//! convex mesh every front face is in front of every other face it overlaps, and a triangle that
//! faces the centre or lies inward of it (a negative or small product: the inside of a cup, the
//! far wall of a fold) is drawn before the outward-facing surface that covers it. Its errors come
//! "across entire slabs" rather than per triangle, which the translucency metric's error images
//! show. O(n log n). The centre is the bounding sphere's ([`Framing`]); the products are taken in
//! f64 in the unit frame, so a moved or scaled copy sorts the same; ties keep the input order.

use super::super::{Cost, Method, Order, Ordering, Orders, Params};
use crate::error::Result;
use crate::mesh::{Framing, Scene};

pub static METHOD: Method = Method {
    name: "translucent-dist-angle",
    summary: "translucent: sorted by normal · (centroid − mesh centre), inward-facing first",
    source: "Austin 2014, \"Update on Sorting Translucent Triangles\" (seed 003), distance and angle sort",
    peer: false,
    per_node: false,
    cost: Cost::Linear,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(DistAngle)
}

struct DistAngle;

impl Ordering for DistAngle {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let framing = Framing::of(&mesh.positions);
        let unit: Vec<_> = mesh.positions.iter().map(|&p| framing.to_unit64(p)).collect();
        let key: Vec<f64> = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| unit[v as usize]);
                let normal = (b - a).cross(c - a).normalize_or_zero();
                normal.dot((a + b + c) / 3.0)
            })
            .collect();
        let mut order: Order = (0..mesh.triangle_count() as u32).collect();
        order.sort_by(|&x, &y| key[x as usize].total_cmp(&key[y as usize]));
        Ok(Orders::from(order))
    }
}
