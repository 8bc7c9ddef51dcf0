//! `translucent-dist-angle`: seed 003's "Sort by Distance and Angle to Center": every triangle
//! sorted by the dot product of its unit normal with the vector from the mesh's centre to the
//! triangle's centroid, smallest first.
//!
//! The blog calls it "a cheapo algorithm that works pretty well on convex shapes": on a closed
//! convex mesh every front face is in front of every other face it overlaps, and a triangle that
//! faces the centre or lies inward of it (a negative or small product: the inside of a cup, the
//! far wall of a fold) is drawn before the outward-facing surface that covers it. Its errors come
//! "across entire slabs" rather than per triangle, which the translucency metric's error images
//! show. O(n log n). The centre is the middle of the bounding box, as the unit frame's
//! ([`Framing`]); the products are taken relative to the box, so a moved copy, or one scaled by a
//! power of two, sorts the same; ties keep the input order.

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
        // Relative to the bounding box's centre and divided by its largest side: a copy moved,
        // or scaled by a power of two, gives the same numbers, and a tiny or huge mesh neither
        // underflows nor overflows in the cross product (which squares the scale). Only the
        // first corner is centred, in f64 and then rounded to f32 (the centre is exact in f64);
        // the edges are differences of the input's coordinates, which a moved or doubled copy
        // (`tests/scale_invariance.rs`) leaves exact, and the centroid is the first corner plus
        // a third of the two edges. One centring per triangle rather than a pass over the
        // vertices, so an unwelded mesh (three vertices a triangle, as in many glTF assets)
        // centres a third as many points. On a copy rounded by a decimal rescale, triangles whose
        // keys were equal (a symmetric mesh has many) may split either way: the test lists it.
        let (lo, hi) = Framing::bounds_of(&mesh.positions);
        let center = (lo + hi) * 0.5;
        let side = (hi - lo).max_element();
        let scale = if side > 0.0 { 1.0 / side } else { 1.0 };
        let scale32 = scale as f32;
        let positions = &mesh.positions;
        // Each key above its triangle's id, ready for the sort.
        let words: Vec<u64> = mesh
            .triangles
            .iter()
            .enumerate()
            .map(|(id, t)| {
                let [a, b, c] = t.map(|v| positions[v as usize]);
                let first = ((a.as_dvec3() - center) * scale).as_vec3();
                let (u, v) = ((b - a) * scale32, (c - a) * scale32);
                let normal = u.cross(v);
                let length = normal.length();
                // (The centroid's 1/3 is common to every key: left out.)
                let key = sortable(if length > 0.0 { normal.dot(3.0 * first + u + v) / length } else { 0.0 });
                u64::from(key) << 32 | id as u64
            })
            .collect();
        Ok(Orders::from(radix_order(words)))
    }
}

/// `x`'s bits, reordered so that unsigned comparison orders them as the numbers are ordered.
fn sortable(x: f32) -> u32 {
    let bits = x.to_bits();
    if bits >> 31 == 1 { !bits } else { bits | 0x8000_0000 }
}

/// The ids in the low halves of `words` sorted by the keys in their high halves, ties in id
/// order: a least-significant-digit radix sort of the words, three passes of 11 bits with the
/// three histograms counted in one sweep (linear where a comparison sort is not); small inputs
/// are sorted as integers.
fn radix_order(mut words: Vec<u64>) -> Order {
    const BITS: u32 = 11;
    const BUCKETS: usize = 1 << BITS;
    // Below one bucket per word the histograms cost more than the sort (measured on Fox's 576
    // triangles; on RobotExpressive's 3,237 the radix passes win): sort the words (the id in
    // their low bits breaks ties as the radix sort does).
    if words.len() < BUCKETS {
        words.sort_unstable();
        return words.into_iter().map(|w| w as u32).collect();
    }
    let mut scratch = vec![0u64; words.len()];
    let digit = |w: u64, pass: u32| ((w >> (32 + BITS * pass)) as usize) & (BUCKETS - 1);
    let mut counts = vec![[0usize; BUCKETS]; 3];
    for &w in &words {
        for (pass, count) in counts.iter_mut().enumerate() {
            count[digit(w, pass as u32)] += 1;
        }
    }
    for (pass, count) in counts.iter_mut().enumerate() {
        let mut start = 0;
        for slot in count.iter_mut() {
            (*slot, start) = (start, start + *slot);
        }
        for &w in &words {
            let d = digit(w, pass as u32);
            scratch[count[d]] = w;
            count[d] += 1;
        }
        std::mem::swap(&mut words, &mut scratch);
    }
    words.into_iter().map(|w| w as u32).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radix_order_sorts_by_key_and_keeps_ties_in_order() {
        let few = [0.5f32, -2.0, 0.5, 1e-30, -0.0, 0.0, f32::MAX, -1e-30];
        // Enough values for the radix passes, with repeats for ties.
        let many: Vec<f32> = (0..20_000).map(|i| ((i * 7919) % 1000) as f32 * 0.37 - 150.0).collect();
        for values in [&few[..], &many[..]] {
            let words: Vec<u64> =
                values.iter().enumerate().map(|(id, &v)| u64::from(sortable(v)) << 32 | id as u64).collect();
            let mut expected: Vec<u32> = (0..values.len() as u32).collect();
            expected.sort_by(|&a, &b| values[a as usize].total_cmp(&values[b as usize]));
            assert_eq!(radix_order(words), expected);
        }
    }
}
