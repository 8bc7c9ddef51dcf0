//! `translucent-coverage`: seed 003's "Coverage Sort": for every pair where one triangle is in
//! front of the other, the covering triangle's approximate form factor onto the covered one
//! ([`pairs::coverage`]: area, distance between centres, incidence angles); then a comparison
//! sort, the most covered triangles first (they are drawn first, behind what covers them).
//!
//! The pairs are those whose footprints overlap from some viewpoint ([`pairs::overlapping`]);
//! each is taken both ways, since the approximation itself says which one covers the other (it is
//! zero unless the covering triangle lies in front of the covered one and faces away from it).
//! O(n²) time and O(n) memory in the blog; here O(P + n log n) for the P overlapping pairs.

use super::super::{Cost, Method, Order, Ordering, Params};
use super::pair_sort;
use super::pairs;

pub static METHOD: Method = Method {
    name: "translucent-coverage",
    summary: "translucent: sorted by approximate coverage from overlapping pairs, most covered first",
    source: "Austin 2014, \"Update on Sorting Translucent Triangles\" (seed 003), coverage sort",
    peer: false,
    per_node: false,
    cost: Cost::Heavy,
    params: &[pair_sort::VIEWS, pair_sort::RES],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    pair_sort::build(params, sort)
}

/// Most covered first.
fn sort(facets: &[pairs::Facet], overlapping: &[pairs::Pair]) -> Order {
    let covered = covered(facets, overlapping);
    let mut order: Order = (0..facets.len() as u32).collect();
    order.sort_by(|&a, &b| covered[b as usize].total_cmp(&covered[a as usize]));
    order
}

/// Per triangle, how much the triangles it overlaps cover it.
pub fn covered(facets: &[pairs::Facet], overlapping: &[pairs::Pair]) -> Vec<f64> {
    let mut covered = vec![0.0; facets.len()];
    for p in overlapping {
        let (a, b) = (&facets[p.a as usize], &facets[p.b as usize]);
        covered[p.b as usize] += pairs::coverage(a, b);
        covered[p.a as usize] += pairs::coverage(b, a);
    }
    covered
}
