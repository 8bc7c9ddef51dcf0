//! `translucent-topo`: seed 003's "Topological Sort": build the digraph of which triangle must be
//! drawn before which, break its cycles, sort it depth first.
//!
//! Arcs: for each pair of triangles whose footprints overlap from some viewpoint, B → A (B drawn
//! first) when B faces A and A does not face B ([`pairs`]: then A covers B from every view that
//! sees both), weighted by the samples on which they overlap. Pairs that face each other or cut
//! each other's planes give no arc.
//!
//! Cycles: the blog says only that they "must be broken, ideally using a heuristic that minimizes
//! visual errors". Here the arcs that point backwards in the greedy minimum feedback arc set order
//! of Eades, Lin & Smyth (IPL 47, 1993) are dropped: sinks go last and sources first as they
//! appear; when only cycles remain, the triangle whose outgoing weight most exceeds its incoming
//! goes first. So each cycle loses light arcs (rarely seen overlaps), not heavy ones. With a
//! lazy max-heap this is O(E log V). The remaining digraph is acyclic and is sorted by a
//! depth-first traversal (reverse post-order), the blog's last step; triangles with no arc keep
//! their input order relative to each other as far as the traversal allows (roots are visited
//! in input order).
//!
//! O(n²) in the blog (all pairs, and memory for all arcs); here O(P log P) for the P overlapping
//! pairs the viewpoints find.

use std::collections::BinaryHeap;

use super::super::{Cost, Method, Order, Ordering, Params};
use super::pair_sort;
use super::pairs::{self, Facet, Pair};

pub static METHOD: Method = Method {
    name: "translucent-topo",
    summary: "translucent: \"draw before\" digraph of overlapping pairs, cycles broken, depth-first sort",
    source: "Austin 2014, \"Update on Sorting Translucent Triangles\" (seed 003), topological sort",
    peer: false,
    per_node: false,
    cost: Cost::Heavy,
    params: &[pair_sort::VIEWS, pair_sort::RES],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    pair_sort::build(params, |facets, overlapping| sort(facets.len(), &arcs(facets, overlapping)))
}

/// The weighted arcs `(from, to, weight)` the predicates give.
fn arcs(facets: &[Facet], pairs: &[Pair]) -> Vec<(u32, u32, u64)> {
    pairs.iter().filter_map(|p| pairs::arc(facets, p).map(|(from, to)| (from, to, u64::from(p.samples)))).collect()
}

/// A topological order of `0..n` after dropping the arcs that a greedy feedback arc set order
/// points backwards.
pub fn sort(n: usize, arcs: &[(u32, u32, u64)]) -> Order {
    let greedy = feedback_order(n, arcs);
    let mut position = vec![0usize; n];
    for (i, &v) in greedy.iter().enumerate() {
        position[v as usize] = i;
    }
    let kept: Vec<(u32, u32)> = arcs
        .iter()
        .filter(|(a, b, _)| position[*a as usize] < position[*b as usize])
        .map(|&(a, b, _)| (a, b))
        .collect();
    depth_first(n, &kept)
}

/// Eades, Lin & Smyth's greedy order: as few arc weight pointing backwards as it finds.
fn feedback_order(n: usize, arcs: &[(u32, u32, u64)]) -> Vec<u32> {
    let (out, into) = (adjacency(n, arcs, false), adjacency(n, arcs, true));
    let (mut out_degree, mut in_degree) = (vec![0usize; n], vec![0usize; n]);
    let mut balance = vec![0i64; n];
    for &(a, b, w) in arcs {
        out_degree[a as usize] += 1;
        in_degree[b as usize] += 1;
        balance[a as usize] += w as i64;
        balance[b as usize] -= w as i64;
    }
    let mut placed = vec![false; n];
    let (mut front, mut back) = (Vec::with_capacity(n), Vec::new());
    let mut sinks: Vec<u32> = (0..n as u32).rev().filter(|&v| out_degree[v as usize] == 0).collect();
    let mut sources: Vec<u32> =
        (0..n as u32).rev().filter(|&v| in_degree[v as usize] == 0 && out_degree[v as usize] > 0).collect();
    let mut heap: BinaryHeap<(i64, std::cmp::Reverse<u32>)> =
        (0..n as u32).map(|v| (balance[v as usize], std::cmp::Reverse(v))).collect();
    while front.len() + back.len() < n {
        let (node, to_back) = if let Some(v) = sinks.pop() {
            (v, true)
        } else if let Some(v) = sources.pop() {
            (v, false)
        } else {
            match heap.pop() {
                Some((b, std::cmp::Reverse(v))) if !placed[v as usize] && b == balance[v as usize] => (v, false),
                Some(_) => continue,
                None => break,
            }
        };
        if placed[node as usize] {
            continue;
        }
        placed[node as usize] = true;
        if to_back {
            back.push(node)
        } else {
            front.push(node)
        }
        for &(to, w) in &out[node as usize] {
            let t = to as usize;
            if placed[t] {
                continue;
            }
            in_degree[t] -= 1;
            balance[t] += w as i64;
            if in_degree[t] == 0 && out_degree[t] > 0 {
                sources.push(to);
            }
            heap.push((balance[t], std::cmp::Reverse(to)));
        }
        for &(from, w) in &into[node as usize] {
            let f = from as usize;
            if placed[f] {
                continue;
            }
            out_degree[f] -= 1;
            balance[f] -= w as i64;
            if out_degree[f] == 0 {
                sinks.push(from);
            }
            heap.push((balance[f], std::cmp::Reverse(from)));
        }
    }
    front.extend(back.into_iter().rev());
    front
}

/// Per node, its arcs' other ends and weights: outgoing, or incoming when `incoming`.
fn adjacency(n: usize, arcs: &[(u32, u32, u64)], incoming: bool) -> Vec<Vec<(u32, u64)>> {
    let mut lists = vec![Vec::new(); n];
    for &(a, b, w) in arcs {
        let (from, to) = if incoming { (b, a) } else { (a, b) };
        lists[from as usize].push((to, w));
    }
    lists
}

/// A topological order of the acyclic `arcs` over `0..n`: reverse post-order of a depth-first
/// traversal from the roots in input order (iterative: no recursion depth limit).
fn depth_first(n: usize, arcs: &[(u32, u32)]) -> Order {
    // Post-order of the reversed graph is a topological order of the original directly.
    let mut into: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &(a, b) in arcs {
        into[b as usize].push(a);
    }
    let mut visited = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut stack: Vec<(u32, usize)> = Vec::new();
    for root in 0..n as u32 {
        if visited[root as usize] {
            continue;
        }
        visited[root as usize] = true;
        stack.push((root, 0));
        while let Some((v, next)) = stack.last_mut() {
            let v = *v;
            if let Some(&u) = into[v as usize].get(*next) {
                *next += 1;
                if !visited[u as usize] {
                    visited[u as usize] = true;
                    stack.push((u, 0));
                }
            } else {
                order.push(v);
                stack.pop();
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    fn position(order: &[u32], v: u32) -> usize {
        order.iter().position(|&x| x == v).unwrap()
    }

    #[test]
    fn acyclic_arcs_are_all_kept() {
        let arcs = [(3, 1, 5), (1, 0, 1), (2, 0, 1), (3, 2, 1)];
        let order = sort(4, &arcs);
        for (a, b, _) in arcs {
            assert!(position(&order, a) < position(&order, b), "{a} before {b} in {order:?}");
        }
    }

    #[test]
    fn a_cycle_loses_its_lightest_arc() {
        // 0 → 1 → 2 → 0 with the last arc light: it is the one drawn backwards.
        let arcs = [(0, 1, 10), (1, 2, 10), (2, 0, 1)];
        let order = sort(3, &arcs);
        assert!(position(&order, 0) < position(&order, 1) && position(&order, 1) < position(&order, 2), "{order:?}");
    }
}
