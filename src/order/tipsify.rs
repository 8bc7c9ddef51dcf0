//! `tipsify`: Sander, Nehab & Barczak 2007, "Fast triangle reordering for vertex locality and
//! reduced overdraw", §3 (Tipsify), our own implementation (ALGORITHMS.md §2).
//!
//! Tipsify emits triangles as fans around one vertex at a time. After a fan it moves to the
//! neighbouring vertex that will still be in a FIFO of `cache` entries once its own fan has been
//! drawn — the oldest such vertex, so the cache is used before it is lost — and when no neighbour
//! has triangles left it backs up along a dead-end stack of recently used vertices, then scans the
//! vertex ids. It needs only vertex→triangle adjacency, so it works on non-manifold meshes, and it
//! does O(1) work per triangle corner whatever the cache size.
//!
//! The paper's pitfalls, as we resolve them: the fan test is `s − C[v] + 2·L[v] ≤ k` (the
//! pseudo-code's `≤`, not the text's `>`); the best priority starts at −1 so that any live
//! candidate beats a dead end; priorities use the timestamp `s` after the fan has been emitted;
//! the start vertex is 0 and the cursor runs over vertex ids in order, so the result depends on
//! vertex numbering, as in the paper.

use super::{Cost, Method, Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::mesh::Scene;
use crate::mesh::topology::Csr;

pub static METHOD: Method = Method {
    name: "tipsify",
    summary: "Tipsify: vertex fans steered by a FIFO cache model, O(F)",
    source: "Sander, Nehab & Barczak 2007, §3 (Tipsify)",
    peer: false,
    per_node: false,
    cost: Cost::Linear,
    params: &[FIFO_CACHE],
    build,
};

/// The FIFO size parameter, shared with the `meshopt-fifo` peer so the two always take the same
/// values and compare like for like.
pub(super) const FIFO_CACHE: ParamInfo = ParamInfo {
    name: "cache",
    default: "16",
    kind: ParamKind::Int { min: 3, max: 1 << 16 },
    help: "FIFO size the order is tuned for",
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(Tipsify { cache: params.int(&FIFO_CACHE) as u32 })
}

struct Tipsify {
    cache: u32,
}

impl Ordering for Tipsify {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        Ok(Orders::from(tipsify(&scene.mesh.triangles, &scene.topology.vertex_triangles, self.cache).0))
    }
}

/// Marks "no vertex" in the fan-vertex search.
const NONE: u32 = u32::MAX;

/// Tipsify with a FIFO of `cache` entries over `triangles`, whose vertex→triangle adjacency is
/// `vertex_triangles` (as [`crate::mesh::topology::vertex_triangles`] builds it). Returns the order and
/// the positions in it where a dead end forced a jump (the first triangle of each run that did
/// not continue from the previous fan's neighbourhood; position 0 included). Those are the hard
/// cluster boundaries of the paper's fast linear clustering (§4), which `sander07` will cut at.
pub(crate) fn tipsify(triangles: &[[u32; 3]], vertex_triangles: &Csr, cache: u32) -> (Order, Vec<usize>) {
    let offsets = vertex_triangles.offsets();
    let adjacent = vertex_triangles.items();
    let n = triangles.len();
    let mut fans = Fans {
        triangles,
        vertices: offsets.windows(2).map(|w| Vertex { live: w[1] - w[0], stamp: 0 }).collect(),
        emitted: vec![false; n],
        dead_end: vec![0; 2 * n],
        top: 0,
        order: vec![0; n],
        count: 0,
        now: cache + 1,
        cache,
    };
    let mut dead_ends = Vec::new();
    let mut cursor = 0usize;
    // Start of the current fan's corners on the stack: the candidates for the next fan vertex.
    let mut candidates_from = 0;
    loop {
        let mut fan = next_neighbour(&fans.dead_end[candidates_from..fans.top], &fans.vertices, fans.now, cache);
        if fan == NONE {
            // Every triangle is out: stop here rather than pop the rest of the stack and scan the
            // remaining vertex ids only to find them all dead.
            if fans.count == n {
                break;
            }
            fan = next_after_dead_end(&fans.dead_end, &mut fans.top, &mut cursor, &fans.vertices);
            if fan == NONE {
                break;
            }
            dead_ends.push(fans.count);
        }
        candidates_from = fans.top;
        fans.emit(fan, &adjacent[offsets[fan as usize] as usize..offsets[fan as usize + 1] as usize]);
    }
    (fans.order, dead_ends)
}

/// Tipsify's state. Emitted corners are pushed on `dead_end[..top]`; the part pushed by the
/// current fan doubles as the candidate set for the next fan vertex, so no separate set is kept.
/// The fan vertex itself is not pushed: once its fan is drawn it has no live triangle left, so it
/// can be neither a candidate nor a dead-end restart, and leaving it out takes a third of the
/// entries off both scans (which skip dead vertices one unpredictable test at a time). Each
/// triangle pushes exactly its two corners other than the fan vertex, so `top <= 2 * count` and
/// the buffers are sized once and written by index, with no allocation or growth check per step.
struct Fans<'a> {
    triangles: &'a [[u32; 3]],
    vertices: Vec<Vertex>,
    emitted: Vec<bool>,
    dead_end: Vec<u32>,
    top: usize,
    order: Order,
    /// Triangles emitted so far: `order[..count]`.
    count: usize,
    /// The FIFO's timestamp `s`.
    now: u32,
    cache: u32,
}

impl Fans<'_> {
    /// Emits the live triangles of `row`, the adjacency row of vertex `fan`, in order (keeping
    /// each one's corners as given), updating live counts and the FIFO. Inlined into the main
    /// loop, which saves a call and a reload of the state per fan (a fan is about two triangles);
    /// the buffers are resliced to lengths derived from `n`, so that one bounds check covers the
    /// arrays indexed by triangle and fewer lengths compete for registers.
    #[inline(always)]
    fn emit(&mut self, fan: u32, row: &[u32]) {
        let Fans { triangles, vertices, emitted, dead_end, order, cache, .. } = self;
        let n = triangles.len();
        let (emitted, order, dead_end) = (&mut emitted[..n], &mut order[..n], &mut dead_end[..2 * n]);
        let (mut top, mut count, mut now) = (self.top, self.count, self.now);
        // Stop once the fan's live triangles are all out rather than test the rest of its row,
        // counting them off instead of reloading the fan's live count at every entry. (A triangle
        // with a repeated corner counts twice in the live count but is emitted once; the row then
        // just runs to its end.)
        let last = count + vertices[fan as usize].live as usize;
        for &t in row {
            let flag = &mut emitted[t as usize];
            if *flag {
                continue;
            }
            *flag = true;
            order[count] = t;
            count += 1;
            // The two corners other than the fan, in triangle order. Always two, so `top` advances
            // by a constant and the next scan's bounds and these stores' addresses do not wait on
            // the corner tests (faster than pushing a variable count; docs/performance.md has
            // the measurement). A degenerate triangle may push the fan vertex itself, or one corner twice:
            // the fan vertex is dead whenever the stack is read, and a repeat wins no tie it would
            // not have won alone, so the order is the same.
            let [a, b, c] = triangles[t as usize];
            dead_end[top] = if a == fan { b } else { a };
            dead_end[top + 1] = if c == fan { b } else { c };
            top += 2;
            for v in [a, b, c] {
                let vertex = &mut vertices[v as usize];
                vertex.live -= 1;
                if now - vertex.stamp > *cache {
                    vertex.stamp = now;
                    now += 1;
                }
            }
            if count == last {
                break;
            }
        }
        (self.top, self.count, self.now) = (top, count, now);
    }
}

/// What Tipsify tracks per vertex, side by side so one memory access serves both: `live` =
/// triangles not yet emitted (a triangle with a repeated corner counts per corner, as the CSR
/// lists it per corner, so the two agree), and `stamp` = its FIFO timestamp (ALGORITHMS.md
/// preamble: v is cached iff `now - stamp <= cache`).
#[derive(Clone, Copy)]
struct Vertex {
    live: u32,
    stamp: u32,
}

/// The candidate that is still cached after its fan is drawn, preferring the oldest (largest
/// `now - stamp`); a live candidate that would fall out scores 0; dead ones are skipped. Ties go
/// to the first candidate, i.e. the earliest emitted corner.
fn next_neighbour(candidates: &[u32], vertices: &[Vertex], now: u32, cache: u32) -> u32 {
    let mut best = NONE;
    let mut best_priority = -1i64;
    for &v in candidates {
        let Vertex { live, stamp } = vertices[v as usize];
        if live == 0 {
            continue;
        }
        let age = now - stamp;
        // u64: 2·L can exceed u32 on a huge fan; it cannot exceed u64.
        let priority = if u64::from(age) + 2 * u64::from(live) <= u64::from(cache) { i64::from(age) } else { 0 };
        if priority > best_priority {
            // `cold_path` keeps this a branch rather than a conditional move, so that the next fan
            // vertex comes from branch prediction and the CPU can start on its fan before this
            // scan is done; with a conditional move each fan waits for the previous scan's last
            // candidate. That pays where the predictor learns the branches (a small mesh ordered
            // repeatedly) and costs little where it does not (docs/performance.md).
            std::hint::cold_path();
            best = v;
            best_priority = priority;
        }
    }
    best
}

/// Dead end: the most recently used vertex that still has live triangles (popping the stack,
/// `dead_end[..top]`, as we go), else the next vertex id with live triangles, else [`NONE`]
/// (all emitted).
fn next_after_dead_end(dead_end: &[u32], top: &mut usize, cursor: &mut usize, vertices: &[Vertex]) -> u32 {
    while *top > 0 {
        *top -= 1;
        let v = dead_end[*top];
        if vertices[v as usize].live > 0 {
            return v;
        }
    }
    while *cursor < vertices.len() {
        if vertices[*cursor].live > 0 {
            return *cursor as u32;
        }
        *cursor += 1;
    }
    NONE
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::topology::vertex_triangles;
    use crate::mesh::{Mesh, procedural};

    #[test]
    fn dead_ends_mark_the_jumps() {
        // Two disjoint triangles: vertex 0's fan is the first, nothing neighbours it, so the
        // second starts after a dead end at position 1.
        let positions = vec![glam::Vec3::ZERO; 6];
        let mesh = Mesh::new("two", positions, vec![[3, 4, 5], [0, 1, 2]], Default::default()).unwrap();
        let (order, dead_ends) = tipsify(&mesh.triangles, &vertex_triangles(&mesh), 16);
        assert_eq!(order, vec![1, 0]);
        assert_eq!(dead_ends, vec![0, 1]);
    }

    #[test]
    fn draws_the_same_order_as_meshoptimizer_even_with_repeated_corners() {
        // The same algorithm with the same tie-breaks: the same index buffer, at every cache size.
        // Repeated corners exercise the fan's early stop (a degenerate triangle counts twice in
        // its live count) and the fan vertex left off the stack (it may fill two corners).
        let mut mesh = procedural::generate("disk:600", 3).unwrap().unwrap();
        let n = mesh.vertex_count() as u32;
        for t in (0..mesh.triangles.len()).step_by(7) {
            let [a, b, _] = mesh.triangles[t];
            mesh.triangles[t] = if t % 2 == 0 { [a, a, b] } else { [a, b, b] };
        }
        mesh.triangles.push([n - 1, n - 1, n - 1]);
        let indices: Vec<u32> = mesh.triangles.as_flattened().to_vec();
        for cache in [3, 8, 16, 32] {
            let (order, _) = tipsify(&mesh.triangles, &vertex_triangles(&mesh), cache);
            let ours: Vec<u32> = mesh.triangles_in_order(&order).as_flattened().to_vec();
            let theirs = meshopt::optimize_vertex_cache_fifo(&indices, mesh.vertex_count(), cache);
            assert_eq!(ours, theirs, "cache {cache}");
        }
    }

    #[test]
    fn a_grid_has_few_dead_ends() {
        let mesh = procedural::generate("grid:32x32", 0).unwrap().unwrap();
        let (order, dead_ends) = tipsify(&mesh.triangles, &vertex_triangles(&mesh), 16);
        assert_eq!(order.len(), mesh.triangle_count());
        assert_eq!(dead_ends[0], 0);
        assert!(dead_ends.windows(2).all(|w| w[0] < w[1]));
        assert!(dead_ends.len() < mesh.triangle_count() / 16, "{} dead ends", dead_ends.len());
    }
}
