//! `forsyth`: Tom Forsyth 2006, "Linear-Speed Vertex Cache Optimisation" (the whole article: the
//! vertex scoring function and the greedy loop), our own implementation (ALGORITHMS.md §3).
//!
//! Greedy: always draw the live triangle whose three vertices score highest. A vertex scores for
//! being in a simulated LRU cache of `cache` entries — 0.75 if it was used by the last triangle
//! (deliberately below the next places, so strips do not run on forever), then
//! `(1 − (p − 3)/(k − 3))^1.5` falling with its place `p` — plus a valence boost
//! `2 · live^−0.5` that favours vertices with few triangles left, so that no lone triangles are
//! stranded to cost three misses later. The score table is Forsyth's, tuned for an LRU of 32;
//! it is cache-size oblivious in practice (his FIFO figures: 0.715 at 16, 0.672 at 32 on a sphere).
//!
//! Linear time as the article asks: after each triangle only the cached vertices change score,
//! so only they and their live triangles are updated, and the next triangle is sought only among
//! those. Unlike the article's loop (and meshoptimizer's), which tracks the best triangle while
//! still adding up score changes, we pick it once every change is in: a triangle with two cached
//! corners is otherwise compared with a half-updated score, and when its second corner lowers it,
//! the stale maximum picks a triangle that is not the best. When no cached vertex has a live
//! triangle left, the article takes the best remaining triangle globally; scanning every triangle
//! there would make the method quadratic, so we keep the candidates that can score highest at
//! hand instead (see [`Evicted`]), and fall back to input order only when no vertex that has been
//! touched has triangles left (a fresh component).

use super::{Method, Order, OrderInput, Ordering, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::topology::Csr;

pub static METHOD: Method = Method {
    name: "forsyth",
    summary: "Forsyth: greedy by vertex scores (LRU position + valence boost), linear time",
    source: "Forsyth 2006, Linear-Speed Vertex Cache Optimisation",
    peer: false,
    params: &[ParamInfo {
        name: "cache",
        default: "32",
        kind: ParamKind::Int { min: 4, max: 1024 },
        help: "LRU size the scores model (Forsyth: 32)",
    }],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(Forsyth { cache: params.int("cache") as usize })
}

struct Forsyth {
    cache: usize,
}

impl Ordering for Forsyth {
    fn order(&self, input: &OrderInput) -> Result<Order> {
        Ok(forsyth(&input.mesh.triangles, &input.topology.vertex_triangles, self.cache))
    }
}

/// Forsyth's constants (the article's `FindVertexScore`).
const LAST_TRIANGLE_SCORE: f32 = 0.75;
const CACHE_DECAY_POWER: f32 = 1.5;
const VALENCE_BOOST_SCALE: f32 = 2.0;
const VALENCE_BOOST_POWER: f32 = 0.5;

/// Marks "no triangle".
const NONE: u32 = u32::MAX;

/// Vertices with live triangles that fell out of the cache, bucketed by their live count, newest
/// last. An uncached vertex's live count cannot change (emitting one of its triangles caches it),
/// so an entry is current exactly while the vertex still has the live count it was filed with.
/// When the cache has nothing left to draw, every live triangle scores by valence alone, and the
/// best ones are those at a vertex with the fewest live triangles: the leftovers of the region
/// just drawn, which the article's global search would also pick. Lowest bucket, newest entry
/// first, so the jump is short.
struct Evicted {
    buckets: [Vec<(u32, u32)>; EVICTED_BUCKETS],
}

/// Live counts 1..EVICTED_BUCKETS get a bucket each; larger ones share the last.
const EVICTED_BUCKETS: usize = 8;

impl Evicted {
    fn push(&mut self, vertex: u32, live: u32) {
        if live == 0 {
            return;
        }
        self.buckets[(live as usize).min(EVICTED_BUCKETS) - 1].push((vertex, live));
    }

    /// The current vertex with the fewest live triangles (newest first), removed from the list.
    fn pop(&mut self, vertices: &[Vertex]) -> Option<u32> {
        for bucket in &mut self.buckets {
            while let Some((v, l)) = bucket.pop() {
                if vertices[v as usize].live == l {
                    return Some(v);
                }
            }
        }
        None
    }
}

/// Forsyth's greedy order of `triangles` for an LRU of `cache` entries; `vertex_triangles` is
/// their vertex→triangle adjacency (as [`crate::topology::vertex_triangles`] builds it).
pub(crate) fn forsyth(triangles: &[[u32; 3]], vertex_triangles: &Csr, cache: usize) -> Order {
    let mut state = State::new(triangles, vertex_triangles, cache);
    let mut evicted = Evicted { buckets: Default::default() };
    let mut order: Order = Vec::with_capacity(triangles.len());
    let mut cursor = 0usize;
    let mut current = 0u32;
    while (current as usize) < triangles.len() {
        order.push(current);
        state.draw(current);
        let candidates = state.rescore(current);
        for &v in state.evicted() {
            evicted.push(v, state.vertices[v as usize].live);
        }
        current = match best_of(&state.candidates[..candidates], &state.triangle_score) {
            NONE => match evicted.pop(&state.vertices) {
                Some(v) => best_of(state.live_triangles(v), &state.triangle_score),
                None => {
                    while cursor < triangles.len() && state.triangle_score[cursor] == EMITTED {
                        cursor += 1;
                    }
                    cursor as u32
                }
            },
            best => best,
        };
        state.settle();
    }
    order
}

/// Everything the greedy loop updates, so that each step's work is a method with only what it
/// needs in registers.
struct State<'a> {
    triangles: &'a [[u32; 3]],
    /// Each vertex's row of the vertex→triangle adjacency keeps its live triangles first: a drawn
    /// triangle is swapped behind them, so updates and searches walk live triangles only.
    adjacent: Vec<u32>,
    vertices: Vec<Vertex>,
    /// Kept current by adding each corner's change of score; [`EMITTED`] once drawn.
    triangle_score: Vec<f32>,
    /// Score for each LRU place; places from `cache` on are the entries just pushed out, which
    /// score as uncached.
    place_score: Vec<f32>,
    /// Valence boost for each live count.
    live_score: Vec<f32>,
    cache: usize,
    /// The LRU, and the one being built, with explicit lengths: `cache` entries plus room for
    /// the three a triangle can push out.
    lru: Vec<u32>,
    lru_len: usize,
    next: Vec<u32>,
    next_len: usize,
    /// The live triangles of the cache's vertices, listed as their scores are updated (twice for
    /// a triangle with two cached corners): the candidates for the next triangle. Sized once for
    /// the most there can be, so the hot loop writes by index and never grows it.
    candidates: Vec<u32>,
}

/// Per vertex, side by side so that one memory access serves the step that touches it.
#[derive(Clone, Copy)]
struct Vertex {
    /// Where its adjacency row starts.
    start: u32,
    /// How many live triangles lead its row.
    live: u32,
    /// The valence part of its score; it changes only when one of its triangles is drawn.
    valence: f32,
    score: f32,
    /// The triangle whose drawing last put it in front of the LRU: while that triangle's LRU is
    /// being built, its corners are recognised by this alone.
    placed: u32,
}

/// The score of a drawn triangle, below every live one (those are positive). A drawn triangle
/// has left every adjacency row, so no update reaches it again.
const EMITTED: f32 = f32::NEG_INFINITY;

impl<'a> State<'a> {
    fn new(triangles: &'a [[u32; 3]], vertex_triangles: &Csr, cache: usize) -> State<'a> {
        let offsets = vertex_triangles.offsets();
        let place_score = (0..cache + 3)
            .map(|p| match p {
                0..3 => LAST_TRIANGLE_SCORE,
                p if p < cache => (1.0 - (p - 3) as f32 / (cache - 3) as f32).powf(CACHE_DECAY_POWER),
                _ => 0.0,
            })
            .collect();
        let max_live = offsets.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0) as usize;
        let live_score: Vec<f32> =
            (0..=max_live).map(|l| VALENCE_BOOST_SCALE * (l.max(1) as f32).powf(-VALENCE_BOOST_POWER)).collect();
        let vertices: Vec<Vertex> = offsets
            .windows(2)
            .map(|w| {
                let valence = live_score[(w[1] - w[0]) as usize];
                Vertex { start: w[0], live: w[1] - w[0], valence, score: valence, placed: NONE }
            })
            .collect();
        let triangle_score = triangles.iter().map(|t| t.iter().map(|&v| vertices[v as usize].score).sum()).collect();
        State {
            triangles,
            adjacent: vertex_triangles.items().to_vec(),
            vertices,
            triangle_score,
            place_score,
            live_score,
            cache,
            lru: vec![0; cache + 3],
            lru_len: 0,
            next: vec![0; cache + 3],
            next_len: 0,
            candidates: vec![0; ((cache + 3) * max_live).min(3 * triangles.len())],
        }
    }

    /// The live triangles of vertex `v`.
    fn live_triangles(&self, v: u32) -> &[u32] {
        let Vertex { start, live, .. } = self.vertices[v as usize];
        &self.adjacent[start as usize..(start + live) as usize]
    }

    /// Takes triangle `t` out of play: out of its corners' live rows, their valence re-scored.
    fn draw(&mut self, t: u32) {
        self.triangle_score[t as usize] = EMITTED;
        for v in self.triangles[t as usize] {
            let vertex = &mut self.vertices[v as usize];
            let live_part = &mut self.adjacent[vertex.start as usize..(vertex.start + vertex.live) as usize];
            if let Some(at) = live_part.iter().position(|&u| u == t) {
                live_part.swap(at, live_part.len() - 1);
                vertex.live -= 1;
                vertex.valence = self.live_score[vertex.live as usize];
            }
        }
    }

    /// Builds the LRU after triangle `drawn` (its distinct corners in front, then the rest in
    /// order) and re-scores each vertex as it is placed — only the cache's vertices change score:
    /// an uncached vertex keeps its live count, and those pushed out past `cache` are re-scored as
    /// uncached. Each change is passed on to the vertex's live triangles, which are listed as
    /// candidates; returns how many. (A vertex with no live triangle left gets a meaningless
    /// score, never read: no live triangle has it as a corner.) Out of line, so that its loops
    /// get the registers.
    #[inline(never)]
    fn rescore(&mut self, drawn: u32) -> usize {
        let State { triangles, adjacent, vertices, triangle_score, place_score, lru, next, candidates, .. } = self;
        let (mut len, mut count) = (0, 0);
        // One body for both loops below, inlined in each (a closure here is not inlined).
        macro_rules! place {
            ($v:expr, $vertex:expr) => {
                next[len] = $v;
                let score = place_score[len] + $vertex.valence;
                let diff = score - $vertex.score;
                $vertex.score = score;
                for &t in &adjacent[$vertex.start as usize..($vertex.start + $vertex.live) as usize] {
                    triangle_score[t as usize] += diff;
                    candidates[count] = t;
                    count += 1;
                }
                len += 1;
            };
        }
        for v in triangles[drawn as usize] {
            let vertex = &mut vertices[v as usize];
            if vertex.placed != drawn {
                vertex.placed = drawn;
                place!(v, vertex);
            }
        }
        for &v in &lru[..self.lru_len] {
            let vertex = &mut vertices[v as usize];
            if vertex.placed != drawn {
                place!(v, vertex);
            }
        }
        self.next_len = len;
        count
    }

    /// The entries the last [`State::rescore`] pushed out of the cache.
    fn evicted(&self) -> &[u32] {
        self.next.get(self.cache..self.next_len).unwrap_or_default()
    }

    /// Makes the LRU built by [`State::rescore`] the current one.
    fn settle(&mut self) {
        std::mem::swap(&mut self.lru, &mut self.next);
        self.lru_len = self.next_len.min(self.cache);
    }
}

/// The best-scoring of `candidates` (the first on ties), or [`NONE`] if there are none. Out of
/// line, so that its loop has the registers to itself.
#[inline(never)]
fn best_of(candidates: &[u32], triangle_score: &[f32]) -> u32 {
    let mut best = NONE;
    let mut best_score = f32::NEG_INFINITY;
    for &t in candidates {
        let score = triangle_score[t as usize];
        if score > best_score {
            best_score = score;
            best = t;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;
    use crate::topology::vertex_triangles;

    /// Replays `order` with nothing incremental: before each triangle, every live triangle with a
    /// corner among the cache's entries (the three just pushed out included) is scored from
    /// scratch by the article's formula; the triangle drawn must score the highest of them (to
    /// float rounding; ties may go either way). Returns how many choices had such candidates.
    fn check_greedy(triangles: &[[u32; 3]], vertex_count: usize, cache: usize, order: &[u32]) -> usize {
        let adjacency = {
            let mut rows = vec![Vec::new(); vertex_count];
            for (t, tri) in triangles.iter().enumerate() {
                tri.iter().for_each(|&v| rows[v as usize].push(t));
            }
            rows
        };
        let mut live: Vec<u32> = adjacency.iter().map(|r| r.len() as u32).collect();
        let mut emitted = vec![false; triangles.len()];
        let mut lru: Vec<u32> = Vec::new();
        let mut checked = 0;
        for &drawn in order {
            let vertex_score = |v: u32| {
                let cached = match lru.iter().position(|&u| u == v) {
                    Some(p) if p < 3 => LAST_TRIANGLE_SCORE,
                    Some(p) if p < cache => (1.0 - (p - 3) as f32 / (cache - 3) as f32).powf(CACHE_DECAY_POWER),
                    _ => 0.0,
                };
                cached + VALENCE_BOOST_SCALE * (live[v as usize] as f32).powf(-VALENCE_BOOST_POWER)
            };
            let score = |t: usize| triangles[t].iter().map(|&v| vertex_score(v)).sum::<f32>();
            let candidates: Vec<usize> =
                lru.iter().flat_map(|&v| adjacency[v as usize].iter().copied()).filter(|&t| !emitted[t]).collect();
            if let Some(best) = candidates.iter().map(|&t| score(t)).reduce(f32::max) {
                assert!(candidates.contains(&(drawn as usize)), "triangle {drawn} drawn with cached candidates left");
                let drawn_score = score(drawn as usize);
                assert!(drawn_score >= best - 1e-4, "triangle {drawn} scores {drawn_score}, the best {best}");
                checked += 1;
            }
            emitted[drawn as usize] = true;
            let corners = triangles[drawn as usize];
            corners.iter().for_each(|&v| live[v as usize] -= 1);
            // The entries pushed past `cache` last time only counted for this choice.
            lru.truncate(cache);
            let mut front: Vec<u32> = Vec::new();
            corners.iter().for_each(|v| {
                if !front.contains(v) {
                    front.push(*v)
                }
            });
            lru.retain(|v| !front.contains(v));
            lru.splice(0..0, front);
        }
        checked
    }

    #[test]
    fn every_choice_is_the_best_scoring_cached_triangle() {
        for (spec, cache) in [("grid:16x8", 32), ("sphere:2000", 32), ("disk:400", 8), ("helix:3", 4)] {
            let mesh = procedural::generate(spec, 3).unwrap().unwrap();
            let order = forsyth(&mesh.triangles, &vertex_triangles(&mesh), cache);
            let checked = check_greedy(&mesh.triangles, mesh.vertex_count(), cache, &order);
            assert!(checked > mesh.triangle_count() * 9 / 10, "{spec}: only {checked} choices checked");
        }
    }
}
