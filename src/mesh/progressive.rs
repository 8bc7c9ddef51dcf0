//! A progressive mesh as Bogomjakov & Gotsman 2002 (§3) take it: a simplification history of
//! vertex removals, each recorded as an update record (the removed vertex, the n triangles around
//! it, the n − 2 that retriangulate the hole), applied least damage first.
//!
//! The paper's histories came from a commercial simplifier; meshoptimizer's does not expose its
//! history, so this is our own. Each removal is a *half-edge collapse*: vertex v moves onto a
//! neighbour u, its two triangles on the edge uv disappear and its other n − 2 triangles become
//! a fan from u (the same triangle with u for v). The collapse chosen next is the one of least
//! quadric error (Garland & Heckbert 1997: the sum of squared distances to the planes of the
//! triangles a vertex has absorbed, area-weighted, evaluated at u's position), kept in a priority
//! queue whose stale entries are skipped when popped (lazy invalidation), so a history of the
//! whole mesh costs O(n log n), not a rescan per removal.
//!
//! A vertex is removed only where the result stays a manifold without folds:
//! - v is interior and its triangles form one closed fan, consistently wound (boundary vertices,
//!   non-manifold vertices and those on duplicate or degenerate triangles are kept);
//! - v and u are not on an attribute seam (a position shared by several mesh vertices, whose
//!   attributes a collapse could not keep apart), so the collapse moves one mesh vertex onto one;
//! - the link condition holds: the vertices adjacent to both u and v are exactly the two opposite
//!   the edge uv (otherwise the collapse would pinch the surface or duplicate a triangle);
//! - no new triangle turns over (its normal keeps a positive dot product with the old one) or
//!   collapses to zero area.
//!
//! On a closed manifold mesh every removal takes one vertex, three edges and two triangles, so the
//! Euler characteristic is kept.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use super::Mesh;
use super::topology::Topology;

/// How a rendering sequence follows a progressive mesh's levels (Bogomjakov & Gotsman 2002, §3):
/// kept through the removals by the simple or the smart update (`order::levels`), or made anew
/// for each level by the method itself, the paper's reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Update {
    Simple,
    Smart,
    Reorder,
}

impl Update {
    pub fn name(self) -> &'static str {
        match self {
            Update::Simple => "simple",
            Update::Smart => "smart",
            Update::Reorder => "reorder",
        }
    }

    pub fn parse(text: &str) -> crate::Result<Update> {
        match text {
            "simple" => Ok(Update::Simple),
            "smart" => Ok(Update::Smart),
            "reorder" => Ok(Update::Reorder),
            other => Err(crate::Error::usage(format!("unknown update `{other}` (simple, smart or reorder)"))),
        }
    }
}

/// One vertex removal: `removed` was moved onto `kept`; the triangles `before` (ids into
/// [`History::triangles`]) were replaced by the triangles `after`.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    pub removed: u32,
    pub kept: u32,
    /// The n triangles around `removed`, in increasing id.
    pub before: Vec<u32>,
    /// The n − 2 triangles that fill the hole, each `before` triangle without the edge
    /// `removed`–`kept` with `kept` in place of `removed`, in the order of `before`.
    pub after: Range<u32>,
    /// The quadric error of the collapse, in squared model units.
    pub error: f64,
}

/// A mesh and the vertex removals that simplify it.
#[derive(Debug, Clone, PartialEq)]
pub struct History {
    /// Every triangle of some level: the mesh's own first, then those each record adds.
    pub triangles: Vec<[u32; 3]>,
    /// The mesh's triangle count: ids below it are the full-resolution mesh.
    pub initial: usize,
    pub records: Vec<Record>,
}

impl History {
    /// Removes vertices of `mesh` least damage first until it has at most `target` triangles
    /// or no vertex can be removed.
    pub fn build(mesh: &Mesh, topology: &Topology, target: usize) -> History {
        Simplifier::new(mesh, topology).run(target)
    }

    /// Triangles alive after the first `records` removals, in increasing id.
    pub fn level(&self, records: usize) -> Vec<u32> {
        let mut alive = vec![false; self.triangles.len()];
        alive[..self.initial].iter_mut().for_each(|a| *a = true);
        for r in &self.records[..records] {
            r.before.iter().for_each(|&t| alive[t as usize] = false);
            alive[r.after.start as usize..r.after.end as usize].iter_mut().for_each(|a| *a = true);
        }
        (0..self.triangles.len() as u32).filter(|&t| alive[t as usize]).collect()
    }

    /// Triangles alive after the first `records` removals: each takes n triangles out and puts
    /// n − 2 in.
    pub fn triangles_after(&self, records: usize) -> usize {
        self.records[..records].iter().fold(self.initial, |count, r| count + r.after.len() - r.before.len())
    }

    /// How many removals bring the mesh to at most `triangles` triangles (all of them if it never
    /// gets there).
    pub fn records_for(&self, triangles: usize) -> usize {
        let mut count = self.initial;
        for (i, r) in self.records.iter().enumerate() {
            if count <= triangles {
                return i;
            }
            count = count + r.after.len() - r.before.len();
        }
        self.records.len()
    }
}

/// Below this many triangles a vertex's fan cannot be closed.
const MIN_VALENCE: usize = 3;

/// A symmetric 4×4 quadric, upper triangle row by row.
#[derive(Debug, Clone, Copy, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    /// The squared distance to the plane through `p` with unit normal `n`, times `weight`.
    fn plane(n: DVec3, p: DVec3, weight: f64) -> Quadric {
        let d = -n.dot(p);
        let [a, b, c] = n.to_array();
        Quadric([a * a, a * b, a * c, a * d, b * b, b * c, b * d, c * c, c * d, d * d].map(|x| x * weight))
    }

    fn add(&mut self, other: &Quadric) {
        self.0.iter_mut().zip(other.0).for_each(|(x, y)| *x += y);
    }

    fn error(&self, p: DVec3) -> f64 {
        let [a2, ab, ac, ad, b2, bc, bd, c2, cd, d2] = self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        a2 * x * x
            + 2.0 * ab * x * y
            + 2.0 * ac * x * z
            + 2.0 * ad * x
            + b2 * y * y
            + 2.0 * bc * y * z
            + 2.0 * bd * y
            + c2 * z * z
            + 2.0 * cd * z
            + d2
    }
}

/// A collapse waiting in the queue: cheapest first; ties (as on a flat region, where every
/// error is zero) by the shorter edge, so that flat parts thin out evenly, then by vertex id.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Candidate {
    error: f64,
    length2: f64,
    vertex: u32,
    kept: u32,
    version: u32,
}

impl Eq for Candidate {}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        let key = |c: &Candidate| (c.error, c.length2, c.vertex);
        let (a, b) = (key(other), key(self));
        a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2))
    }
}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Buffers reused from one evaluation to the next.
#[derive(Default)]
struct Scratch {
    fan: Vec<(u32, u32, u32)>,
    ring_v: Vec<u32>,
    ring_u: Vec<u32>,
    options: Vec<Cost>,
}

/// A collapse as (quadric error, squared edge length, vertex kept).
type Cost = (f64, f64, u32);

struct Simplifier<'a> {
    positions: Vec<DVec3>,
    weld: &'a [u32],
    /// Mesh vertices per welded position: more than one is a seam.
    shared: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    alive: Vec<bool>,
    /// Per mesh vertex, its alive triangles.
    stars: Vec<Vec<u32>>,
    quadrics: Vec<Quadric>,
    /// Bumped whenever a vertex's queued collapse changes: queue entries of older versions are stale.
    version: Vec<u32>,
    /// Each vertex's collapse in the queue at its current version, if any.
    queued: Vec<Option<Cost>>,
    removed: Vec<bool>,
    queue: BinaryHeap<Candidate>,
    /// The model's extent squared, for the zero-area test.
    scale2: f64,
}

impl<'a> Simplifier<'a> {
    fn new(mesh: &Mesh, topology: &'a Topology) -> Simplifier<'a> {
        let positions: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        let n = positions.len();
        let mut shared = vec![0u32; n];
        topology.weld.iter().for_each(|&w| shared[w as usize] += 1);
        let mut stars = vec![Vec::new(); n];
        let mut quadrics = vec![Quadric::default(); n];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| positions[v as usize]);
            let cross = (b - a).cross(c - a);
            let area = 0.5 * cross.length();
            let plane = if area > 0.0 { Quadric::plane(cross / (2.0 * area), a, area) } else { Quadric::default() };
            for &v in tri {
                if !stars[v as usize].contains(&(t as u32)) {
                    stars[v as usize].push(t as u32);
                    quadrics[v as usize].add(&plane);
                }
            }
        }
        let (lo, hi) = mesh.bounds();
        let scale2 = (hi - lo).as_dvec3().length_squared().max(f64::MIN_POSITIVE);
        Simplifier {
            positions,
            weld: &topology.weld,
            shared,
            triangles: mesh.triangles.clone(),
            alive: vec![true; mesh.triangle_count()],
            stars,
            quadrics,
            version: vec![0; n],
            queued: vec![None; n],
            removed: vec![false; n],
            queue: BinaryHeap::new(),
            scale2,
        }
    }

    fn run(mut self, target: usize) -> History {
        let initial = self.triangles.len();
        // Every vertex's first option, on all cores: a tenth of the work, the rest is sequential.
        let this = &self;
        self.queued = (0..self.positions.len() as u32)
            .into_par_iter()
            .map_init(Scratch::default, |scratch, v| this.option(v, scratch))
            .collect();
        self.queue = self
            .queued
            .iter()
            .enumerate()
            .filter_map(|(v, o)| {
                o.map(|(error, length2, kept)| Candidate { error, length2, vertex: v as u32, kept, version: 0 })
            })
            .collect::<Vec<_>>()
            .into();
        let mut scratch = Scratch::default();
        let mut count = initial;
        let mut records = Vec::new();
        while count > target {
            let Some(c) = self.queue.pop() else { break };
            if self.removed[c.vertex as usize] || c.version != self.version[c.vertex as usize] {
                continue;
            }
            let record = self.collapse(c.vertex, c.kept, c.error, &mut scratch);
            count = count + record.after.len() - record.before.len();
            records.push(record);
        }
        History { triangles: self.triangles, initial, records }
    }

    fn welded(&self, v: u32) -> u32 {
        self.weld[v as usize]
    }

    /// Whether `v` lies on one position alone (no attribute seam).
    fn unshared(&self, v: u32) -> bool {
        self.shared[self.welded(v) as usize] == 1
    }

    /// `v`'s triangles rotated to start at `v`, as `(t, a, b)` for the triangle `v a b`, when they
    /// form one closed, consistently wound fan of at least three proper triangles; else `None`.
    fn fan(&self, v: u32, fan: &mut Vec<(u32, u32, u32)>) -> bool {
        fan.clear();
        let star = &self.stars[v as usize];
        if star.len() < MIN_VALENCE {
            return false;
        }
        for &t in star {
            let tri = self.triangles[t as usize];
            let Some(k) = tri.iter().position(|&x| x == v) else { return false };
            let (a, b) = (tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let w = [self.welded(v), self.welded(a), self.welded(b)];
            if w[0] == w[1] || w[1] == w[2] || w[2] == w[0] {
                return false;
            }
            fan.push((t, a, b));
        }
        // Walk the cycle: the triangle after `v a b` is the one whose first neighbour is b.
        let mut seen = 1;
        let mut current = fan[0];
        loop {
            let mut next = fan.iter().filter(|f| self.welded(f.1) == self.welded(current.2));
            let (Some(&after), None) = (next.next(), next.next()) else { return false };
            if after.0 == fan[0].0 {
                break;
            }
            seen += 1;
            if seen > fan.len() {
                return false;
            }
            current = after;
        }
        seen == fan.len()
    }

    /// The welded vertices around `v` (the ring), from its alive triangles.
    fn ring(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let wv = self.welded(v);
        for &t in &self.stars[v as usize] {
            for &x in &self.triangles[t as usize] {
                let w = self.welded(x);
                if w != wv && !out.contains(&w) {
                    out.push(w);
                }
            }
        }
    }

    /// Whether collapsing `v` onto its fan neighbour `u` keeps the mesh manifold and unfolded.
    fn valid(&self, v: u32, u: u32, fan: &[(u32, u32, u32)], ring_v: &[u32], ring_u: &mut Vec<u32>) -> bool {
        let wu = self.welded(u);
        // The two triangles on the edge uv and the vertices opposite it.
        let mut opposite = fan.iter().filter_map(|&(_, a, b)| {
            if self.welded(a) == wu {
                Some(self.welded(b))
            } else if self.welded(b) == wu {
                Some(self.welded(a))
            } else {
                None
            }
        });
        let (Some(o1), Some(o2), None) = (opposite.next(), opposite.next(), opposite.next()) else { return false };
        if o1 == o2 {
            return false;
        }
        self.ring(u, ring_u);
        let common = ring_v.iter().filter(|w| ring_u.contains(w)).count();
        if common != 2 || !ring_u.contains(&o1) || !ring_u.contains(&o2) {
            return false;
        }
        let p = self.positions[u as usize];
        fan.iter().filter(|&&(_, a, b)| self.welded(a) != wu && self.welded(b) != wu).all(|&(_, a, b)| {
            let (pa, pb, pv) = (self.positions[a as usize], self.positions[b as usize], self.positions[v as usize]);
            let before = (pa - pv).cross(pb - pv);
            let after = (pa - p).cross(pb - p);
            after.dot(before) > 0.0 && after.length_squared() > 1e-24 * self.scale2 * self.scale2
        })
    }

    /// `v`'s cheapest valid collapse, if it has one.
    fn option(&self, v: u32, scratch: &mut Scratch) -> Option<Cost> {
        if self.removed[v as usize] || !self.unshared(v) || !self.fan(v, &mut scratch.fan) {
            return None;
        }
        let Scratch { fan, ring_v, ring_u, options } = scratch;
        self.ring(v, ring_v);
        // Cheapest first (ties by vertex id), so that usually only one collapse is checked.
        options.clear();
        for &(_, u, _) in fan.iter() {
            if options.iter().any(|&(_, _, k)| k == u) || !self.unshared(u) {
                continue;
            }
            let mut q = self.quadrics[v as usize];
            q.add(&self.quadrics[u as usize]);
            let p = self.positions[u as usize];
            options.push((q.error(p).max(0.0), p.distance_squared(self.positions[v as usize]), u));
        }
        options.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)).then(a.2.cmp(&b.2)));
        options.iter().copied().find(|&(_, _, u)| self.valid(v, u, fan, ring_v, ring_u))
    }

    /// Requeues `v` when its cheapest collapse changed: a new version, the old entry left stale.
    fn requeue(&mut self, v: u32, scratch: &mut Scratch) {
        let option = self.option(v, scratch);
        if option == self.queued[v as usize] {
            return;
        }
        self.queued[v as usize] = option;
        self.version[v as usize] += 1;
        if let Some((error, length2, kept)) = option {
            self.queue.push(Candidate { error, length2, vertex: v, kept, version: self.version[v as usize] });
        }
    }

    /// Moves `v` onto `u`, records it, and requeues the vertices whose options changed.
    fn collapse(&mut self, v: u32, u: u32, error: f64, scratch: &mut Scratch) -> Record {
        let mut before = std::mem::take(&mut self.stars[v as usize]);
        before.sort_unstable();
        let start = self.triangles.len() as u32;
        for &t in &before {
            self.alive[t as usize] = false;
            for x in self.triangles[t as usize] {
                if x != v {
                    self.stars[x as usize].retain(|&s| s != t);
                }
            }
        }
        for &t in &before {
            let tri = self.triangles[t as usize];
            if tri.contains(&u) {
                continue;
            }
            let new = tri.map(|x| if x == v { u } else { x });
            let id = self.triangles.len() as u32;
            self.triangles.push(new);
            self.alive.push(true);
            new.iter().for_each(|&x| self.stars[x as usize].push(id));
        }
        self.removed[v as usize] = true;
        self.queued[v as usize] = None;
        let absorbed = self.quadrics[v as usize];
        self.quadrics[u as usize].add(&absorbed);
        let record = Record { removed: v, kept: u, before, after: start..self.triangles.len() as u32, error };
        // Every vertex around u now has other neighbours (and u another quadric).
        let mut touched: Vec<u32> = vec![u];
        for &t in &self.stars[u as usize] {
            for x in self.triangles[t as usize] {
                if !touched.contains(&x) {
                    touched.push(x);
                }
            }
        }
        for x in touched {
            self.requeue(x, scratch);
        }
        record
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    fn generated(spec: &str) -> Mesh {
        procedural::generate(spec, 1).unwrap().unwrap()
    }

    /// V − E + F over the welded vertices and edges of the alive triangles.
    fn euler(mesh: &Mesh, history: &History, records: usize) -> i64 {
        let topology = Topology::new(mesh);
        let alive = history.level(records);
        let mut vertices = std::collections::HashSet::new();
        let mut edges = std::collections::HashSet::new();
        for &t in &alive {
            let w = history.triangles[t as usize].map(|v| topology.weld[v as usize]);
            for k in 0..3 {
                vertices.insert(w[k]);
                edges.insert((w[k].min(w[(k + 1) % 3]), w[k].max(w[(k + 1) % 3])));
            }
        }
        vertices.len() as i64 - edges.len() as i64 + alive.len() as i64
    }

    #[test]
    fn a_closed_sphere_keeps_its_euler_characteristic_down_to_a_few_triangles() {
        let mesh = generated("sphere:2000");
        let history = History::build(&mesh, &Topology::new(&mesh), 100);
        let last = history.records.len();
        assert!(history.level(last).len() <= 100, "stopped at {}", history.level(last).len());
        for records in [0, last / 3, last] {
            assert_eq!(euler(&mesh, &history, records), 2, "after {records} removals");
        }
    }

    #[test]
    fn records_replace_n_triangles_by_n_minus_two_that_existed_and_keep_their_winding() {
        let mesh = generated("sphere:2000");
        let history = History::build(&mesh, &Topology::new(&mesh), 500);
        let mut alive: std::collections::HashSet<u32> = (0..mesh.triangle_count() as u32).collect();
        for r in &history.records {
            assert!(r.before.iter().all(|t| alive.contains(t)), "a removed triangle was not there");
            assert_eq!(r.after.len() + 2, r.before.len());
            let around: Vec<[u32; 3]> = r.before.iter().map(|&t| history.triangles[t as usize]).collect();
            assert!(around.iter().all(|t| t.contains(&r.removed)));
            assert_eq!(around.iter().filter(|t| t.contains(&r.kept)).count(), 2);
            // Each new triangle is an old one with `kept` for `removed`, corners in the same order.
            let replaced: Vec<[u32; 3]> = around
                .iter()
                .filter(|t| !t.contains(&r.kept))
                .map(|t| t.map(|x| if x == r.removed { r.kept } else { x }))
                .collect();
            assert_eq!(replaced, history.triangles[r.after.start as usize..r.after.end as usize]);
            r.before.iter().for_each(|t| {
                alive.remove(t);
            });
            alive.extend(r.after.clone());
            assert!(r.error.is_finite() && r.error >= 0.0);
        }
    }

    #[test]
    fn no_triangle_turns_over() {
        let mesh = generated("sphere:2000");
        let history = History::build(&mesh, &Topology::new(&mesh), 200);
        let positions: Vec<DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        // On a sphere centred at the origin every front face looks outward.
        for t in history.level(history.records.len()) {
            let [a, b, c] = history.triangles[t as usize].map(|v| positions[v as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "triangle {t} faces inward");
        }
    }

    #[test]
    fn boundary_and_seam_vertices_stay() {
        // The disk's boundary keeps every vertex: its outline is the mesh's shape.
        let disk = generated("disk:950");
        let topology = Topology::new(&disk);
        let history = History::build(&disk, &topology, 10);
        let on_boundary: std::collections::HashSet<u32> = {
            let mut count = std::collections::HashMap::new();
            for t in &disk.triangles {
                for k in 0..3 {
                    let e = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                    *count.entry(e).or_insert(0) += 1;
                }
            }
            count.into_iter().filter(|&(_, n)| n == 1).flat_map(|((a, b), _)| [a, b]).collect()
        };
        assert!(!history.records.is_empty());
        assert!(history.records.iter().all(|r| !on_boundary.contains(&r.removed)));
        // A seam: two mesh vertices at one position (a cube with split corners) are never removed.
        let mut seamed = generated("sphere:500");
        let copy = seamed.positions[0];
        seamed.positions.push(copy);
        let last = seamed.positions.len() as u32 - 1;
        let t = seamed.triangles.iter().position(|t| t.contains(&0)).unwrap();
        let k = seamed.triangles[t].iter().position(|&x| x == 0).unwrap();
        seamed.triangles[t][k] = last;
        let history = History::build(&seamed, &Topology::new(&seamed), 50);
        assert!(history.records.iter().all(|r| ![0, last].contains(&r.removed) && ![0, last].contains(&r.kept)));
    }

    #[test]
    fn levels_count_down_to_the_target() {
        let mesh = generated("sphere:2000");
        let history = History::build(&mesh, &Topology::new(&mesh), 400);
        for target in [2000, 1500, 1000, 400] {
            let records = history.records_for(target);
            let level = history.level(records);
            assert!(level.len() <= target, "{target}: {}", level.len());
            if records > 0 {
                assert!(history.level(records - 1).len() > target);
            }
        }
    }
}
