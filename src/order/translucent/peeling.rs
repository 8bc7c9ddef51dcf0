//! `translucent-peeling`: Jon Watte's "Coverage Peeling", as seed 003 describes it: pairwise
//! coverage ([`pairs::coverage`]) summed per triangle; then the least covered triangle is peeled
//! off, the coverage it cast on others is taken off their sums, and again, until none is left.
//!
//! The least covered triangle is the frontmost (nothing much lies in front of it), so triangles
//! come off front to back and the draw order is the peeling order reversed: the last peeled is
//! drawn first. Unlike a sort on the initial sums, peeling lets a triangle rise once what covered
//! it is gone, which is why it "works well, even in the presence of triangle cycles".
//!
//! The blog's version ran out of memory on large meshes: it kept all n² pairs. Here only the pairs
//! whose footprints overlap from some viewpoint are kept ([`pairs::overlapping`]), in a compact
//! adjacency (CSR) of who covers whom, with a lazy min-heap: O(P log P) for P such pairs. The
//! blog's open goal, a 60,000-triangle mesh "in a few seconds and under a few GB", is measured in
//! the gallery (`translucent-summary`).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::super::{Cost, Method, Order, Ordering, Params};
use super::pair_sort;
use super::pairs::{self, Facet, Pair};

pub static METHOD: Method = Method {
    name: "translucent-peeling",
    summary: "translucent: Watte's coverage peeling (least covered off first) over overlapping pairs",
    source: "Austin 2014, \"Update on Sorting Translucent Triangles\" (seed 003), Jon Watte's coverage peeling",
    peer: false,
    per_node: false,
    cost: Cost::Heavy,
    params: &[pair_sort::VIEWS, pair_sort::RES],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    pair_sort::build(params, peel)
}

/// The draw order coverage peeling gives over `overlapping` pairs.
pub fn peel(facets: &[Facet], overlapping: &[Pair]) -> Order {
    let n = facets.len();
    // Who each triangle covers, and by how much (CSR), and each triangle's total.
    let mut casts: Vec<(u32, u32, f64)> = Vec::with_capacity(2 * overlapping.len());
    for p in overlapping {
        let (a, b) = (&facets[p.a as usize], &facets[p.b as usize]);
        for (from, to, c) in [(p.a, p.b, pairs::coverage(a, b)), (p.b, p.a, pairs::coverage(b, a))] {
            if c > 0.0 {
                casts.push((from, to, c));
            }
        }
    }
    casts.sort_unstable_by_key(|&(from, to, _)| (from, to));
    let mut start = vec![0usize; n + 1];
    for &(from, ..) in &casts {
        start[from as usize + 1] += 1;
    }
    for v in 0..n {
        start[v + 1] += start[v];
    }
    let mut covered = vec![0.0f64; n];
    for &(_, to, c) in &casts {
        covered[to as usize] += c;
    }
    // A lazy min-heap of (coverage, id): stale entries are skipped. Coverage is non-negative, so
    // its bits order as the numbers do.
    let key = |c: f64| c.max(0.0).to_bits();
    let mut heap: BinaryHeap<Reverse<(u64, u32)>> =
        (0..n as u32).map(|v| Reverse((key(covered[v as usize]), v))).collect();
    let mut peeled = vec![false; n];
    let mut order = Vec::with_capacity(n);
    while let Some(Reverse((k, v))) = heap.pop() {
        if peeled[v as usize] || k != key(covered[v as usize]) {
            continue;
        }
        peeled[v as usize] = true;
        order.push(v);
        for &(_, to, c) in &casts[start[v as usize]..start[v as usize + 1]] {
            if !peeled[to as usize] {
                covered[to as usize] -= c;
                heap.push(Reverse((key(covered[to as usize]), to)));
            }
        }
    }
    order.reverse();
    order
}
