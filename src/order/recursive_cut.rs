//! `recursive-cut`: the recursive cut algorithm of Bogomjakov & Gotsman 2002, §2.1–2.2 and
//! Fig. 3 — the Hilbert construction generalised to irregular meshes. The dual graph is bisected
//! into two halves of (nearly) equal size with a small edge cut (METIS, as in the paper); the
//! first half is drawn (recursively), then the second. Where the two meet, a *gate* — one edge of
//! the cut — fixes the exit of the first half and the entry of the second, so the sequence steps
//! across the cut between neighbours instead of jumping. Most cache misses happen along the cuts,
//! and the sum of the cut sizes over the recursion gives ACMR = 0.5 + O(1/k) for every cache
//! size k (their §2.2), hence a *universal* sequence.
//!
//! The rules the paper leaves open, ours (ALGORITHMS.md §6):
//!
//! * **Which half first.** The one holding the required entry; without an entry, the one not
//!   holding the required exit; without either, METIS's part 0.
//! * **The gate** (Fig. 3: "the topological distances d1 and d2 are maximised"): over the cut
//!   edges (a, b), a in the first half, b in the second, with d1 = BFS distance inside the first
//!   half from its entry to a and d2 = BFS distance inside the second half from b to its exit,
//!   pick the largest d1 + d2, then the largest min(d1, d2), then the first in triangle order
//!   (max-sum beat max-min by 0.005–0.01 ACMR at FIFO 10–16 on the bunny, horse and dragon).
//!   An unreachable end (halves need not be connected) counts as −1, so a reachable gate wins.
//!   Keeping the gate far from both ends leaves each half room to wander before leaving.
//! * **Unset ends.** A set without a required entry (a component, or a half with no cut to the
//!   other) starts at the triangle of its first half farthest from the cut; without a required
//!   exit the second half ends at its triangle farthest from the cut (from a pseudo-peripheral
//!   triangle when there is no cut): the gate then lies between them, as the paper's picture has.
//! * **Entry and exit in one half.** METIS does not know the ends; when it puts both in the same
//!   half we bisect instead by how much nearer each triangle is to the entry than to the exit
//!   (breadth-first distances), the nearer half first, so the cut crosses the route between
//!   them as a Hilbert quadrant's does and no end is lost — provided that cut is at most
//!   [`MAX_CUT_GROWTH`] times METIS's (a long cut costs misses at every cache size, a lost end
//!   only a short jump). Otherwise, or when the exit cannot be reached from the entry (a set in
//!   pieces), METIS's cut is kept and the exit given up: the second half then ends at its
//!   triangle nearest to the lost exit.
//! * **Leaves.** Sets of at most [`LEAF`] triangles are ordered exactly: among paths from the
//!   entry to the exit through all of them, one that loads the fewest new vertices from each
//!   triangle to the next (3 minus the vertices shared; dynamic programming over subsets), so
//!   an unavoidable step between non-neighbours at least stays on a shared vertex.
//!
//! Each connected component is ordered on its own and drawn contiguously, in component order, so
//! non-manifold meshes and meshes of many pieces are handled like any other. METIS bisects each
//! set's own sub-graph (built in time linear in the set, so a level of the recursion costs O(F)
//! and the whole O(F log F) plus METIS); it is seeded (`seed`), and METIS keeps its random state
//! in a global, so calls are serialised to keep the order a pure function of mesh and seed.

use std::collections::VecDeque;
use std::sync::Mutex;

use super::{Cost, Method, Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::Scene;
use crate::mesh::topology::{Csr, Topology};

pub static METHOD: Method = Method {
    name: "recursive-cut",
    summary: "recursive METIS bisection of the dual graph with gate edges (universal sequence)",
    source: "Bogomjakov & Gotsman 2002, §2.1-2.2, Fig. 3",
    peer: false,
    per_node: false,
    cost: Cost::Heaviest,
    params: &[ParamInfo { name: "seed", default: "", kind: ParamKind::Seed, help: "METIS random seed" }],
    build,
};

/// Sets this small are ordered exactly instead of being cut further.
pub(crate) const LEAF: usize = 8;

/// How much larger than METIS's cut the entry/exit-separating cut may be (see the module
/// comment). Measured: always separating (no limit) raised ACMR at FIFO 10 on the horse from
/// 0.87 to 0.96 (a few very long cuts); never separating left it at 0.87; a limit of 1.5–3 gave
/// 0.84–0.85 there and on the bunny and dragon, 2 the best of them.
const MAX_CUT_GROWTH: usize = 2;

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(RecursiveCut { seed: params.seed() })
}

struct RecursiveCut {
    seed: u64,
}

impl Ordering for RecursiveCut {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        recursive_cut(&scene.mesh, &scene.topology, self.seed).map(Orders::from)
    }
}

/// METIS's random generator is a process-wide global, reseeded at the start of every call:
/// concurrent calls would interleave its draws and make the result depend on timing.
static METIS: Mutex<()> = Mutex::new(());

/// The recursive-cut order of `mesh` (whose topology is `topology`), deterministic for `seed`.
pub(crate) fn recursive_cut(mesh: &Mesh, topology: &Topology, seed: u64) -> Result<Order> {
    let origin = mesh.name.as_str();
    let graph = &topology.neighbors;
    let n = graph.rows();
    if i32::try_from(graph.items().len()).is_err() || i32::try_from(n).is_err() {
        return Err(Error::input(origin, "recursive-cut: the dual graph is too large for METIS (32-bit indices)"));
    }
    let mut cutter = Cutter {
        graph,
        triangles: &mesh.triangles,
        // METIS takes a 32-bit seed: fold the high half in so that nearby seeds stay distinct.
        seed: ((seed ^ (seed >> 32)) & 0x7fff_ffff) as i32,
        origin,
        stamp: vec![0; n],
        local: vec![0; n],
        next_stamp: 0,
        order: Vec::with_capacity(n),
    };
    let mut stack: Vec<Task> =
        by_component(topology).into_iter().rev().map(|tris| Task { tris, entry: None, exit: None }).collect();
    while let Some(task) = stack.pop() {
        if task.tris.len() <= LEAF {
            cutter.leaf(&task);
        } else {
            let (first, second) = cutter.split(task)?;
            stack.push(second);
            stack.push(first);
        }
    }
    Ok(cutter.order)
}

/// The triangles of each connected component, in id order, components in order.
pub(crate) fn by_component(topology: &Topology) -> Vec<Vec<u32>> {
    let mut components = vec![Vec::new(); topology.component_count];
    for (t, &c) in topology.component.iter().enumerate() {
        components[c as usize].push(t as u32);
    }
    components
}

/// A set of triangles to draw, with the triangle it must start with and the one it must end with.
struct Task {
    tris: Vec<u32>,
    entry: Option<u32>,
    exit: Option<u32>,
}

/// Distance marker for "not reached".
const FAR: u32 = u32::MAX;

struct Cutter<'a> {
    graph: &'a Csr,
    triangles: &'a [[u32; 3]],
    seed: i32,
    origin: &'a str,
    /// Per triangle: the set it was last indexed in, and its index there.
    stamp: Vec<u32>,
    local: Vec<u32>,
    next_stamp: u32,
    order: Order,
}

/// A set's own dual graph, in METIS's CSR form, over local indices.
struct SubGraph {
    xadj: Vec<i32>,
    adjncy: Vec<i32>,
}

impl SubGraph {
    fn row(&self, i: usize) -> &[i32] {
        &self.adjncy[self.xadj[i] as usize..self.xadj[i + 1] as usize]
    }

    /// Breadth-first distances from `sources`, moving only between nodes where `inside` holds.
    fn bfs(&self, sources: &[usize], inside: impl Fn(usize) -> bool) -> Vec<u32> {
        let mut dist = vec![FAR; self.xadj.len() - 1];
        let mut queue = VecDeque::new();
        for &s in sources {
            if dist[s] == FAR {
                dist[s] = 0;
                queue.push_back(s);
            }
        }
        while let Some(i) = queue.pop_front() {
            for &j in self.row(i) {
                let j = j as usize;
                if dist[j] == FAR && inside(j) {
                    dist[j] = dist[i] + 1;
                    queue.push_back(j);
                }
            }
        }
        dist
    }
}

/// The node with the largest finite distance (the first such), if any is reached.
fn farthest(dist: &[u32], inside: impl Fn(usize) -> bool) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, &d) in dist.iter().enumerate() {
        if d != FAR && inside(i) && best.is_none_or(|b| d > dist[b]) {
            best = Some(i);
        }
    }
    best
}

impl Cutter<'_> {
    /// Numbers `tris` 0, 1, … (see [`Self::local_of`]) and returns the set's stamp.
    fn index(&mut self, tris: &[u32]) -> u32 {
        self.next_stamp += 1;
        for (i, &t) in tris.iter().enumerate() {
            self.stamp[t as usize] = self.next_stamp;
            self.local[t as usize] = i as u32;
        }
        self.next_stamp
    }

    /// Indexes `tris` locally and builds their induced sub-graph, in O(|tris| + its edges).
    fn subgraph(&mut self, tris: &[u32]) -> SubGraph {
        let stamp = self.index(tris);
        let mut xadj = Vec::with_capacity(tris.len() + 1);
        let mut adjncy = Vec::new();
        xadj.push(0);
        for &t in tris {
            for &u in self.graph.row(t as usize) {
                if self.stamp[u as usize] == stamp {
                    adjncy.push(self.local[u as usize] as i32);
                }
            }
            xadj.push(adjncy.len() as i32);
        }
        SubGraph { xadj, adjncy }
    }

    fn local_of(&self, t: u32) -> usize {
        self.local[t as usize] as usize
    }

    /// Bisects the task's set and fixes the ends of both halves (see the module comment).
    fn split(&mut self, task: Task) -> Result<(Task, Task)> {
        let sub = self.subgraph(&task.tris);
        let entry = task.entry.map(|t| self.local_of(t));
        let exit = task.exit.map(|t| self.local_of(t)).filter(|&x| Some(x) != entry);
        let mut part = self.bisect(&sub, entry)?;
        if let (Some(e), Some(x)) = (entry, exit)
            && part[e] == part[x]
            && let Some(between) = split_between(&sub, e, x)
            && cut_size(&sub, &between) <= MAX_CUT_GROWTH * cut_size(&sub, &part)
        {
            part = between;
        }
        let first_part = match (entry, exit) {
            (Some(e), _) => part[e],
            (None, Some(x)) => !part[x],
            (None, None) => false,
        };
        let in_a = |i: usize| part[i] == first_part;
        let in_b = |i: usize| part[i] != first_part;

        let cut: Vec<(usize, usize)> = (0..sub.xadj.len() - 1)
            .filter(|&i| in_a(i))
            .flat_map(|i| sub.row(i).iter().map(move |&j| (i, j as usize)))
            .filter(|&(_, j)| in_b(j))
            .collect();
        let mut a_side: Vec<usize> = cut.iter().map(|&(i, _)| i).collect();
        let mut b_side: Vec<usize> = cut.iter().map(|&(_, j)| j).collect();
        a_side.sort_unstable();
        a_side.dedup();
        b_side.sort_unstable();
        b_side.dedup();

        // The first half's entry: the required one, else its triangle farthest from the cut.
        let entry_a = entry.or_else(|| end_far_from(&sub, &a_side, in_a));
        // The second half's exit: the required one if it is there; if it fell in the first half,
        // the second half's triangle nearest to it; else the one farthest from the cut.
        let exit_b = match exit {
            Some(x) if in_b(x) => Some(x),
            Some(x) => {
                let dist = sub.bfs(&[x], |_| true);
                (0..dist.len()).filter(|&i| in_b(i) && dist[i] != FAR).min_by_key(|&i| dist[i])
            }
            None => None,
        }
        .or_else(|| end_far_from(&sub, &b_side, in_b));

        let gate = if cut.is_empty() {
            None
        } else {
            let from_entry = sub.bfs(&entry_a.into_iter().collect::<Vec<_>>(), in_a);
            let to_exit = sub.bfs(&exit_b.into_iter().collect::<Vec<_>>(), in_b);
            let signed = |d: u32| if d == FAR { -1 } else { i64::from(d) };
            let mut best = cut[0];
            let mut best_score = (i64::MIN, i64::MIN);
            for &(i, j) in &cut {
                let (d1, d2) = (signed(from_entry[i]), signed(to_exit[j]));
                let score = (d1 + d2, d1.min(d2));
                if score > best_score {
                    (best, best_score) = ((i, j), score);
                }
            }
            Some(best)
        };

        let (mut tris_a, mut tris_b) = (Vec::new(), Vec::new());
        for (i, &t) in task.tris.iter().enumerate() {
            if in_a(i) { tris_a.push(t) } else { tris_b.push(t) }
        }
        let global = |i: Option<usize>| i.map(|i| task.tris[i]);
        Ok((
            Task { tris: tris_a, entry: global(entry_a), exit: global(gate.map(|g| g.0)) },
            Task { tris: tris_b, entry: global(gate.map(|g| g.1)), exit: global(exit_b) },
        ))
    }

    /// METIS bisection of `sub`: true for part 1. Falls back to halving a breadth-first order
    /// (from `entry`, else node 0) should METIS leave a part empty, so every split makes progress.
    fn bisect(&self, sub: &SubGraph, entry: Option<usize>) -> Result<Vec<bool>> {
        let n = sub.xadj.len() - 1;
        let mut part = vec![0; n];
        {
            let _serial = METIS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            let metis_error = |e: &dyn std::fmt::Display| {
                Error::input(self.origin, format!("recursive-cut: METIS failed to bisect {n} triangles: {e}"))
            };
            metis::Graph::new(1, 2, &sub.xadj, &sub.adjncy)
                .map_err(|e| metis_error(&e))?
                .set_option(metis::option::Seed(self.seed))
                .part_recursive(&mut part)
                .map_err(|e| metis_error(&e))?;
        }
        let ones = part.iter().filter(|&&p| p == 1).count();
        if part.iter().all(|&p| p == 0 || p == 1) && ones > 0 && ones < n {
            return Ok(part.into_iter().map(|p| p == 1).collect());
        }
        // Breadth-first order over the whole set (restarting in unreached pieces), halved.
        let mut rank = vec![usize::MAX; n];
        let mut next = 0;
        for start in entry.into_iter().chain(0..n) {
            if rank[start] != usize::MAX {
                continue;
            }
            let dist = sub.bfs(&[start], |j| rank[j] == usize::MAX);
            let mut reached: Vec<usize> = (0..n).filter(|&i| dist[i] != FAR && rank[i] == usize::MAX).collect();
            reached.sort_by_key(|&i| (dist[i], i));
            for i in reached {
                rank[i] = next;
                next += 1;
            }
        }
        Ok(rank.into_iter().map(|r| r >= n / 2).collect())
    }

    /// Orders a small set exactly: a path from the entry to the exit (when required) through all
    /// its triangles that loads the fewest new vertices from one triangle to the next.
    fn leaf(&mut self, task: &Task) {
        let m = task.tris.len();
        if m <= 1 {
            self.order.extend(&task.tris);
            return;
        }
        self.index(&task.tris);
        let tri = |i: usize| self.triangles[task.tris[i] as usize];
        let mut new_vertices = [[0u8; LEAF]; LEAF];
        for (i, row) in new_vertices.iter_mut().enumerate().take(m) {
            for (j, cost) in row.iter_mut().enumerate().take(m) {
                let shared = tri(i).iter().filter(|v| tri(j).contains(v)).count().min(3);
                *cost = (3 - shared) as u8;
            }
        }
        let entry = task.entry.map(|t| self.local_of(t));
        let exit = task.exit.map(|t| self.local_of(t)).filter(|&x| Some(x) != entry);
        let path = best_path(&new_vertices[..m], entry, exit);
        self.order.extend(path.into_iter().map(|i| task.tris[i]));
    }
}

/// A triangle of a half (`inside`) as far as possible from `sources` (its side of the cut), or,
/// with no sources, a pseudo-peripheral one (the farthest from the farthest from its first node).
fn end_far_from(sub: &SubGraph, sources: &[usize], inside: impl Fn(usize) -> bool + Copy) -> Option<usize> {
    if !sources.is_empty() {
        return farthest(&sub.bfs(sources, inside), inside);
    }
    let first = (0..sub.xadj.len() - 1).find(|&i| inside(i))?;
    let far = farthest(&sub.bfs(&[first], inside), inside)?;
    farthest(&sub.bfs(&[far], inside), inside)
}

/// A path through all `step.len()` ≤ [`LEAF`] nodes from `entry` to `exit` (either may be free)
/// of least total `step[from][to]` cost; ties go to smaller node ids. Dynamic programming over
/// (visited set, last node): 2^m·m² steps, nothing for m ≤ 8.
fn best_path(step: &[[u8; LEAF]], entry: Option<usize>, exit: Option<usize>) -> Vec<usize> {
    let m = step.len();
    let full = (1usize << m) - 1;
    const UNSET: u8 = u8::MAX;
    let mut cost = vec![UNSET; (full + 1) * m];
    let mut parent = vec![UNSET; (full + 1) * m];
    for s in 0..m {
        if entry.is_none_or(|e| e == s) && (exit != Some(s) || m == 1) {
            cost[(1 << s) * m + s] = 0;
        }
    }
    for mask in 1..=full {
        for last in 0..m {
            let c = cost[mask * m + last];
            if c == UNSET {
                continue;
            }
            for (next, &to_next) in step[last].iter().enumerate().take(m) {
                if mask & (1 << next) != 0 {
                    continue;
                }
                let grown = mask | (1 << next);
                // The exit may only come last.
                if exit == Some(next) && grown != full {
                    continue;
                }
                let total = c + to_next;
                let slot = grown * m + next;
                if total < cost[slot] {
                    cost[slot] = total;
                    parent[slot] = last as u8;
                }
            }
        }
    }
    let end = (0..m)
        .filter(|&last| exit.is_none_or(|x| x == last))
        .filter(|&last| cost[full * m + last] != UNSET)
        .min_by_key(|&last| cost[full * m + last])
        .expect("a path through all nodes always exists");
    let mut path = Vec::with_capacity(m);
    let (mut mask, mut last) = (full, end);
    loop {
        path.push(last);
        let p = parent[mask * m + last];
        if p == UNSET {
            break;
        }
        mask &= !(1 << last);
        last = p as usize;
    }
    path.reverse();
    path
}

/// The number of edges of `sub` between the two parts.
fn cut_size(sub: &SubGraph, part: &[bool]) -> usize {
    (0..part.len()).map(|i| sub.row(i).iter().filter(|&&j| part[j as usize] != part[i]).count()).sum::<usize>() / 2
}

/// A bisection of `sub` that separates `entry` (false) from `exit` (true), for when METIS's puts
/// them together: nodes sorted by how much nearer they are to the entry than to the exit
/// (d_entry − d_exit, then d_entry), the nearer half first. The cut then runs across the
/// entry–exit route, as a Hilbert quadrant's does. `None` if the exit is unreachable.
fn split_between(sub: &SubGraph, entry: usize, exit: usize) -> Option<Vec<bool>> {
    let (from_entry, from_exit) = (sub.bfs(&[entry], |_| true), sub.bfs(&[exit], |_| true));
    if from_entry[exit] == FAR {
        return None;
    }
    let n = from_entry.len();
    let key = |i: usize| {
        if from_entry[i] == FAR {
            (0, i64::MAX)
        } else {
            (i64::from(from_entry[i]) - i64::from(from_exit[i]), i64::from(from_entry[i]))
        }
    };
    let mut sorted: Vec<usize> = (0..n).collect();
    sorted.sort_by_key(|&i| (key(i), i));
    let mut part = vec![true; n];
    for &i in &sorted[..n / 2] {
        part[i] = false;
    }
    if !part[exit] {
        // Ties put the exit among the nearer half: trade it for the first node of the other.
        part[exit] = true;
        part[sorted[n / 2]] = false;
    }
    part[entry] = false;
    Some(part)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisect_survives_graphs_without_edges() {
        let graph = Topology::new(&crate::mesh::procedural::generate("layers:1", 0).unwrap().unwrap()).neighbors;
        let cutter = Cutter {
            graph: &graph,
            triangles: &[],
            seed: 1,
            origin: "test",
            stamp: Vec::new(),
            local: Vec::new(),
            next_stamp: 0,
            order: Vec::new(),
        };
        for n in [2, 9, 40] {
            let sub = SubGraph { xadj: vec![0; n + 1], adjncy: Vec::new() };
            let part = cutter.bisect(&sub, Some(n - 1)).unwrap();
            let ones = part.iter().filter(|&&p| p).count();
            assert!(ones > 0 && ones < n, "{n}: {part:?}");
        }
    }

    #[test]
    fn best_path_respects_ends_and_costs() {
        // A path 0–1–2–3: neighbours cost 1 (one new vertex), others 3.
        let mut step = [[3u8; LEAF]; LEAF];
        for i in 0..3 {
            step[i][i + 1] = 1;
            step[i + 1][i] = 1;
        }
        let step = &step[..4];
        assert_eq!(best_path(step, Some(0), Some(3)), vec![0, 1, 2, 3]);
        let free = best_path(step, None, None);
        assert!(free == [0, 1, 2, 3] || free == [3, 2, 1, 0], "{free:?}");
        assert_eq!(best_path(step, Some(3), None), vec![3, 2, 1, 0]);
        // A forced jump: start in the middle, end at an end.
        let p = best_path(step, Some(1), Some(3));
        assert_eq!((p[0], p[3]), (1, 3));
        assert_eq!(best_path(&[[3; LEAF]; 3], Some(2), Some(0)), vec![2, 1, 0]);
        assert_eq!(best_path(&[[3; LEAF]; 1], None, None), vec![0]);
    }
}
