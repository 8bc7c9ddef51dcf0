//! Post-transform vertex-cache simulators: FIFO, LRU and meshoptimizer's batch model.
//!
//! ACMR = misses / triangles (Hoppe 1999; Bogomjakov & Gotsman 2002 §1: between 0.5 and 3).
//! ATVR = misses / distinct vertices referenced (1 is optimal), the denominator meshoptimizer
//! uses; DirectXMesh divides by all vertices instead, which differs only when some are unused.
//!
//! Each simulator is one O(n) pass over the index stream with O(1) work per index, for any
//! cache size: FIFO keeps per-vertex timestamps (a vertex is cached iff it entered among the last
//! k misses), LRU keeps an intrusive doubly linked list over vertex ids, and the batch model is
//! FIFO plus the flush rules of meshoptimizer's `analyzeVertexCache` (ALGORITHMS.md §9).

use std::fmt;
use std::str::FromStr;

use rayon::prelude::*;

use super::{CacheColumn, Draws, MeasureOptions, Metric, Name, Value};
use super::vendor::Vendor;
use crate::error::{Error, Result};

/// A vertex-cache model, written `fifo:16`, `lru:32`, `batch:CACHE,WARP,PRIMGROUP`, or a GPU
/// vendor's model from published measurements: `nvidia`, `amd` or `intel` ([`Vendor`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CacheModel {
    /// First in, first out: a miss pushes the vertex and evicts the oldest; a hit changes nothing.
    Fifo(u32),
    /// Least recently used: a hit also moves the vertex to the front.
    Lru(u32),
    /// meshoptimizer's model of a GPU: a FIFO of `cache` entries, flushed (a new batch starts)
    /// before a triangle whose missing vertices would overflow `warp` vertices or when the batch
    /// already holds `primgroup` triangles; 0 turns a limit off.
    Batch { cache: u32, warp: u32, primgroup: u32 },
    /// A GPU vendor's batches and reuse, as measured ([`super::vendor`]).
    Vendor(Vendor),
}

/// Largest cache we simulate: timestamps are u32 and must not wrap within a mesh.
const MAX_CACHE: u32 = 1 << 24;

impl CacheModel {
    /// The cache capacity in vertices.
    pub fn size(&self) -> u32 {
        match *self {
            CacheModel::Fifo(k) | CacheModel::Lru(k) => k,
            CacheModel::Batch { cache, .. } => cache,
            CacheModel::Vendor(vendor) => vendor.size(),
        }
    }

    /// The model's family name: `fifo`, `lru`, `batch`, or the vendor's.
    pub fn kind(&self) -> &'static str {
        match self {
            CacheModel::Fifo(_) => "fifo",
            CacheModel::Lru(_) => "lru",
            CacheModel::Batch { .. } => "batch",
            CacheModel::Vendor(vendor) => vendor.name(),
        }
    }
}

impl fmt::Display for CacheModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CacheModel::Fifo(k) => write!(f, "fifo:{k}"),
            CacheModel::Lru(k) => write!(f, "lru:{k}"),
            CacheModel::Batch { cache, warp, primgroup } => write!(f, "batch:{cache},{warp},{primgroup}"),
            CacheModel::Vendor(vendor) => write!(f, "{vendor}"),
        }
    }
}

impl FromStr for CacheModel {
    type Err = Error;

    fn from_str(text: &str) -> Result<CacheModel> {
        let bad = |why: &str| {
            Error::usage(format!(
                "cache model `{text}` {why} (expected fifo:K, lru:K, batch:CACHE,WARP,PRIMGROUP, nvidia, amd or intel, e.g. fifo:16, batch:32,32,32; `triorder methods` describes them)"
            ))
        };
        if let Some(vendor) = Vendor::parse(text) {
            return Ok(CacheModel::Vendor(vendor));
        }
        let (kind, args) = text
            .split_once(':')
            .ok_or_else(|| bad(if ["fifo", "lru", "batch"].contains(&text) { "has no size" } else { "is of an unknown kind" }))?;
        let numbers: Vec<u32> = args
            .split(',')
            .map(|a| a.trim().parse::<u32>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| bad("has a size that is not a non-negative integer"))?;
        let model = match (kind, numbers.as_slice()) {
            ("fifo", &[k]) => CacheModel::Fifo(k),
            ("lru", &[k]) => CacheModel::Lru(k),
            ("batch", &[cache, warp, primgroup]) => {
                if warp != 0 && warp < 3 {
                    return Err(bad("has a warp below 3 (a triangle must fit)"));
                }
                CacheModel::Batch { cache, warp, primgroup }
            }
            ("fifo" | "lru" | "batch", _) => return Err(bad("has the wrong number of sizes")),
            _ => return Err(bad("is of an unknown kind")),
        };
        if !(1..=MAX_CACHE).contains(&model.size()) {
            return Err(bad(&format!("has a size outside 1..={MAX_CACHE}")));
        }
        Ok(model)
    }
}

/// What one simulation counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CacheStats {
    pub triangles: usize,
    /// Distinct vertices the index stream references.
    pub vertices: usize,
    /// Vertices transformed (cache misses).
    pub misses: u64,
    /// Batches (warps) executed; only the batch model and the NVIDIA and AMD models (batches and
    /// waves) count them, 0 otherwise.
    pub batches: u64,
}

impl CacheStats {
    /// Average cache miss ratio: misses per triangle.
    pub fn acmr(&self) -> f64 {
        self.misses as f64 / self.triangles.max(1) as f64
    }

    /// Average transform to vertex ratio: misses per distinct referenced vertex.
    pub fn atvr(&self) -> f64 {
        self.misses as f64 / self.vertices.max(1) as f64
    }
}

/// Simulates `model` over `triangles` (already in draw order) whose indices are < `vertex_count`.
pub fn simulate(model: CacheModel, triangles: &[[u32; 3]], vertex_count: usize) -> CacheStats {
    run(model, triangles, vertex_count, |_| {})
}

/// What happened at one corner (a triangle's use of a vertex) in a simulation: the picture of
/// Bogomjakov & Gotsman 2002, Figs. 10 and 11, where each corner is coloured by the misses of its
/// vertex. `Miss(1)` is the vertex's first load (every referenced vertex has exactly one), `Miss(n)`
/// its (n−1)-th reload; a reload is the waste an ordering is judged by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    Hit,
    /// The n-th time this vertex is transformed (saturating at 255).
    Miss(u8),
}

/// Simulates `model` and classifies every corner: `result[t][c]` is corner `c` of the `t`-th
/// triangle drawn. Counts agree with [`simulate`] (the same simulators run).
pub fn corners(model: CacheModel, triangles: &[[u32; 3]], vertex_count: usize) -> (CacheStats, Vec<[Corner; 3]>) {
    let mut classes = vec![[Corner::Hit; 3]; triangles.len()];
    let mut loads = vec![0u8; vertex_count];
    let stats = run(model, triangles, vertex_count, |corner| {
        let (t, c) = (corner / 3, corner % 3);
        let n = &mut loads[triangles[t][c] as usize];
        *n = n.saturating_add(1);
        classes[t][c] = Corner::Miss(*n);
    });
    (stats, classes)
}

/// Runs the simulator of `model`, calling `on_miss(3·t + c)` for each missing corner `c` of the
/// `t`-th triangle (a no-op closure compiles away, so [`simulate`] pays nothing for it).
fn run(model: CacheModel, triangles: &[[u32; 3]], vertex_count: usize, on_miss: impl FnMut(usize)) -> CacheStats {
    match model {
        CacheModel::Fifo(k) => fifo(k, triangles, vertex_count, on_miss),
        CacheModel::Lru(k) => lru(k, triangles, vertex_count, on_miss),
        CacheModel::Batch { cache, warp, primgroup } => batch(cache, warp, primgroup, triangles, vertex_count, on_miss),
        CacheModel::Vendor(vendor) => vendor.simulate(triangles, vertex_count, on_miss),
    }
}

/// FIFO by timestamps: `stamp[v]` is the miss count when v last entered; v is cached iff fewer
/// than k misses happened since. Stamps start at k+1 so an untouched vertex (stamp 0) misses, and
/// a non-zero stamp marks a referenced vertex.
pub(crate) fn fifo(k: u32, triangles: &[[u32; 3]], vertex_count: usize, mut on_miss: impl FnMut(usize)) -> CacheStats {
    let mut stamp = vec![0u32; vertex_count];
    let mut now = k + 1;
    for (t, tri) in triangles.iter().enumerate() {
        for (c, &v) in tri.iter().enumerate() {
            // A select and an add rather than a jump around the update: 1.14–1.86× meshoptimizer's
            // speed on the 24 shared meshes, where the jump measured 1.04–1.21× on the large ones.
            let s = &mut stamp[v as usize];
            let miss = now - *s > k;
            *s = if miss { now } else { *s };
            now += u32::from(miss);
            if miss {
                on_miss(3 * t + c);
            }
        }
    }
    CacheStats {
        triangles: triangles.len(),
        vertices: stamp.iter().filter(|&&s| s != 0).count(),
        misses: u64::from(now - (k + 1)),
        batches: 0,
    }
}

/// The batch model, defined as meshoptimizer's `analyzeVertexCache` defines it: before each
/// triangle, its corners are tested against the cache; if the batch already holds `primgroup`
/// triangles, or its vertices plus those missing corners would exceed `warp`, the batch is
/// submitted and the cache emptied. A repeated corner counts once per corner in that test, as
/// there.
///
/// Faster than meshoptimizer's loop on large meshes and small (`triorder bench`), for three
/// reasons. The corners are updated without a branch: on a large mesh whether a corner hits is
/// data, not a pattern a predictor learns. The flush test's count of missing corners, a second
/// pass over the corners, is taken only within three vertices of the warp limit or at the
/// triangle limit, since three more vertices always fit otherwise. And when the cache holds a
/// whole warp (`cache ≥ warp`, as in the usual 32/32/32), no vertex can be evicted within a batch,
/// so a vertex hits exactly when the current batch loaded it ([`BatchLocal`]): its stamp is the
/// batch's number, a constant between flushes, instead of a miss count that every miss advances,
/// which chains each corner's test to the one before.
fn batch(
    k: u32,
    warp: u32,
    primgroup: u32,
    triangles: &[[u32; 3]],
    vertex_count: usize,
    on_miss: impl FnMut(usize),
) -> CacheStats {
    // A disabled limit becomes one no batch can reach, which keeps the loop free of extra tests.
    let off_is_max = |limit: u32| if limit == 0 { u32::MAX } else { limit };
    let (warp, primgroup) = (off_is_max(warp), off_is_max(primgroup));
    if k >= warp {
        batches(BatchLocal { batch: 1 }, warp, primgroup, triangles, vertex_count, on_miss)
    } else {
        batches(Fifo { k, now: k + 1 }, warp, primgroup, triangles, vertex_count, on_miss)
    }
}

/// When a vertex stamped `stamp` is still cached, for [`batches`]. A stamp of 0 is a vertex never
/// loaded, and must read as not cached.
trait Residency {
    fn cached(&self, stamp: u32) -> bool;
    /// The stamp of a vertex after a corner referenced it (`miss`: it was loaded), and the
    /// corner's effect on the rule.
    fn referenced(&mut self, stamp: u32, miss: bool) -> u32;
    /// The cache is emptied.
    fn flush(&mut self);
}

/// A FIFO of `k` entries by timestamps: a vertex is cached iff it entered among the last `k`
/// misses (see [`fifo`]).
struct Fifo {
    k: u32,
    now: u32,
}

impl Residency for Fifo {
    fn cached(&self, stamp: u32) -> bool {
        self.now - stamp <= self.k
    }

    fn referenced(&mut self, stamp: u32, miss: bool) -> u32 {
        let stamp = if miss { self.now } else { stamp };
        self.now += u32::from(miss);
        stamp
    }

    fn flush(&mut self) {
        self.now += self.k + 1;
    }
}

/// A cache that holds everything the current batch loaded: stamps are batch numbers.
struct BatchLocal {
    batch: u32,
}

impl Residency for BatchLocal {
    fn cached(&self, stamp: u32) -> bool {
        stamp == self.batch
    }

    fn referenced(&mut self, _: u32, _: bool) -> u32 {
        self.batch
    }

    fn flush(&mut self) {
        self.batch += 1;
    }
}

/// The batch model's loop ([`batch`]) over a cache `rule`; `warp` and `primgroup` are limits
/// (`u32::MAX`: none).
fn batches(
    mut rule: impl Residency,
    warp: u32,
    primgroup: u32,
    triangles: &[[u32; 3]],
    vertex_count: usize,
    mut on_miss: impl FnMut(usize),
) -> CacheStats {
    let mut stamp = vec![0u32; vertex_count];
    let (mut misses, mut batches) = (0u64, 0u64);
    let (mut in_warp, mut in_group) = (0u32, 0u32);
    for (t, tri) in triangles.iter().enumerate() {
        // The flush test needs the triangle's missing corners only near a limit: three more
        // vertices fit otherwise. Far from one (most triangles) only the corners are updated.
        if in_group == primgroup || in_warp.saturating_add(3) > warp {
            let missing: u32 = tri.iter().map(|&v| u32::from(!rule.cached(stamp[v as usize]))).sum();
            if in_group == primgroup || in_warp.saturating_add(missing) > warp {
                batches += u64::from(in_warp > 0);
                misses += u64::from(in_warp);
                in_warp = 0;
                in_group = 0;
                rule.flush();
            }
        }
        for (corner, &v) in tri.iter().enumerate() {
            let s = &mut stamp[v as usize];
            let miss = !rule.cached(*s);
            *s = rule.referenced(*s, miss);
            in_warp += u32::from(miss);
            if miss {
                on_miss(3 * t + corner);
            }
        }
        in_group += 1;
    }
    batches += u64::from(in_warp > 0);
    misses += u64::from(in_warp);
    CacheStats { triangles: triangles.len(), vertices: stamp.iter().filter(|&&s| s != 0).count(), misses, batches }
}

/// LRU as an intrusive doubly linked list over vertex ids (front = most recent), so a hit's
/// move-to-front and a miss's eviction are O(1) whatever the cache size.
fn lru(k: u32, triangles: &[[u32; 3]], vertex_count: usize, mut on_miss: impl FnMut(usize)) -> CacheStats {
    const NIL: u32 = u32::MAX;
    let mut prev = vec![NIL; vertex_count];
    let mut next = vec![NIL; vertex_count];
    let mut cached = vec![false; vertex_count];
    let mut referenced = vec![false; vertex_count];
    let (mut head, mut tail, mut len) = (NIL, NIL, 0u32);
    let mut misses = 0u64;
    for (t, tri) in triangles.iter().enumerate() {
        for (c, &v) in tri.iter().enumerate() {
            let vi = v as usize;
            if cached[vi] {
                if head == v {
                    continue;
                }
                // Unlink v (it has a predecessor since it is not the head).
                let (p, n) = (prev[vi], next[vi]);
                next[p as usize] = n;
                if n == NIL {
                    tail = p;
                } else {
                    prev[n as usize] = p;
                }
            } else {
                misses += 1;
                on_miss(3 * t + c);
                referenced[vi] = true;
                cached[vi] = true;
                len += 1;
                if len > k {
                    let old = tail;
                    tail = prev[old as usize];
                    cached[old as usize] = false;
                    len -= 1;
                    if tail == NIL {
                        head = NIL;
                    } else {
                        next[tail as usize] = NIL;
                    }
                }
            }
            // Push v at the front.
            prev[vi] = NIL;
            next[vi] = head;
            if head != NIL {
                prev[head as usize] = v;
            }
            head = v;
            if tail == NIL {
                tail = v;
            }
        }
    }
    CacheStats { triangles: triangles.len(), vertices: referenced.iter().filter(|&&r| r).count(), misses, batches: 0 }
}

/// How many distinct vertices `triangles` reference (the ATVR denominator).
pub fn referenced(triangles: &[[u32; 3]], vertex_count: usize) -> usize {
    let mut seen = vec![false; vertex_count];
    triangles.iter().flatten().for_each(|&v| seen[v as usize] = true);
    seen.iter().filter(|&&s| s).count()
}

/// ACMR and ATVR over the draws of an evaluation: the misses of every draw over its triangles
/// (or referenced vertices), each draw counting its buffer's misses. For one buffer that is the
/// buffer's ratio exactly; for several, the mean of the per-draw ratios, since every buffer of a
/// frame has the same triangles and vertices.
pub fn over_draws(per_buffer: impl IntoIterator<Item = (u64, CacheStats)>) -> (f64, f64) {
    let (mut misses, mut triangles, mut vertices) = (0u64, 0u64, 0u64);
    for (uses, stats) in per_buffer {
        misses += uses * stats.misses;
        triangles += uses * stats.triangles as u64;
        vertices += uses * stats.vertices as u64;
    }
    (misses as f64 / triangles.max(1) as f64, misses as f64 / vertices.max(1) as f64)
}

/// The simulated vertex caches of the options: `acmr` and `atvr` per model.
pub struct Simulated;

pub static METRIC: Simulated = Simulated;

static NAMES: &[Name] = &[
    Name { name: "acmr", label: "ACMR (vertex-cache misses per triangle)", needs: "`caches`", optimum: None },
    Name { name: "atvr", label: "ATVR (misses per referenced vertex)", needs: "`caches`", optimum: Some(1.0) },
];

impl Metric for Simulated {
    fn names(&self) -> &'static [Name] {
        NAMES
    }

    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str> {
        if options.caches.is_empty() { Vec::new() } else { vec!["acmr", "atvr"] }
    }

    /// The cache models are simulated in parallel: each simulation is sequential and
    /// deterministic, so the values are those of simulating them one by one, and sweeps of many
    /// sizes (31 in `bg02-fig8-acmr-vs-cache`) no longer leave a core idle.
    fn measure(&self, draws: &Draws) -> Result<Vec<Value>> {
        let buffers: Vec<(u64, Vec<[u32; 3]>)> = draws.used().map(|(b, n)| (n, draws.triangles(b))).collect();
        let vertices = draws.scene.mesh.vertex_count();
        let ratios: Vec<(f64, f64)> = draws
            .options
            .caches
            .par_iter()
            .map(|&model| over_draws(buffers.iter().map(|(n, triangles)| (*n, simulate(model, triangles, vertices)))))
            .collect();
        let mut values = Vec::new();
        for (&model, (acmr, atvr)) in draws.options.caches.iter().zip(ratios) {
            let cache = Some(CacheColumn::from(model));
            values.push(Value { cache: cache.clone(), ..Value::new("acmr", acmr) });
            values.push(Value { cache, ..Value::new("atvr", atvr) });
        }
        Ok(values)
    }

    /// The orders in parallel too (see [`Simulated::measure`]).
    fn measure_many(&self, many: &[Draws]) -> Result<Vec<Vec<Value>>> {
        many.par_iter().map(|draws| self.measure(draws)).collect()
    }

    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        acmr_atvr_columns(values, |cache| format!("ACMR/ATVR {cache}"))
    }
}

/// One `ACMR/ATVR` column per cache, titled by `title(cache name)`.
pub(super) fn acmr_atvr_columns(values: &[&Value], title: impl Fn(&str) -> String) -> Vec<(String, String)> {
    values
        .chunks(2)
        .filter_map(|pair| match pair {
            [acmr, atvr] => {
                let cache = acmr.cache.as_ref().map_or("", |c| c.name.as_str());
                Some((title(cache), format!("{:.4}/{:.4}", acmr.value, atvr.value)))
            }
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bogomjakov & Gotsman 2002, Fig. 1: 14 vertices, 16 triangles (1-based in the paper).
    const FIG1: [[u32; 3]; 16] = [
        [1, 2, 4],
        [1, 4, 5],
        [4, 5, 14],
        [2, 3, 4],
        [3, 4, 12],
        [3, 11, 12],
        [9, 11, 12],
        [9, 10, 11],
        [7, 9, 13],
        [7, 8, 9],
        [6, 7, 13],
        [6, 13, 14],
        [9, 12, 13],
        [4, 12, 14],
        [12, 13, 14],
        [5, 6, 14],
    ];

    fn misses(model: &str, tris: &[[u32; 3]], n: usize) -> u64 {
        simulate(model.parse().unwrap(), tris, n).misses
    }

    #[test]
    fn bogomjakov_gotsman_figure_1() {
        let tris: Vec<_> = FIG1.iter().map(|t| t.map(|v| v - 1)).collect();
        assert_eq!(misses("fifo:4", &tris, 14), 25);
        assert_eq!(misses("fifo:16", &tris, 14), 14);
        let s = simulate(CacheModel::Fifo(4), &tris, 14);
        assert!((s.acmr() - 1.5625).abs() < 1e-12 && s.vertices == 14);
        // LRU by hand: the one extra hit is vertex 4 at triangle 4, refreshed by triangle 3.
        assert_eq!(misses("lru:4", &tris, 14), 24);
        assert_eq!(misses("lru:16", &tris, 14), 14);
    }

    #[test]
    fn corners_classify_every_miss() {
        let tris: Vec<_> = FIG1.iter().map(|t| t.map(|v| v - 1)).collect();
        for model in ["fifo:4", "lru:4", "batch:4,6,3", "fifo:16"] {
            let model: CacheModel = model.parse().unwrap();
            let (stats, classes) = corners(model, &tris, 14);
            assert_eq!(stats, simulate(model, &tris, 14));
            let missed = classes.iter().flatten().filter(|c| **c != Corner::Hit).count();
            assert_eq!(missed as u64, stats.misses, "{model}");
            // Every vertex has exactly one first load (Bogomjakov & Gotsman Fig. 10's green corner).
            let mut first = [0; 14];
            for (tri, cls) in tris.iter().zip(&classes) {
                for (&v, c) in tri.iter().zip(cls) {
                    first[v as usize] += usize::from(*c == Corner::Miss(1));
                }
            }
            assert_eq!(first, [1; 14], "{model}");
        }
        // Fig. 1 at FIFO-4 by hand: after (1,2,4), (1,4,5), (4,5,14) the cache holds 2,4,5,14 (1
        // evicted by 14); (2,3,4) then hits 4, loads 3 first, and 2, still cached, is a hit; 3 evicts
        // 2. Triangle 5 (3,4,12) hits 3 and 4 and loads 12, evicting 4.
        let (_, classes) = corners(CacheModel::Fifo(4), &tris, 14);
        assert_eq!(classes[0], [Corner::Miss(1); 3]);
        assert_eq!(classes[1], [Corner::Hit, Corner::Hit, Corner::Miss(1)]);
        assert_eq!(classes[3], [Corner::Hit, Corner::Miss(1), Corner::Hit]);
        assert_eq!(classes[4], [Corner::Hit, Corner::Hit, Corner::Miss(1)]);
    }

    #[test]
    fn fifo_and_lru_differ_on_refresh() {
        // Cache 2: a b | a c | a d. FIFO evicts a at "c" although it was just used; LRU keeps it.
        let tris = [[0, 1, 0], [0, 2, 0], [0, 3, 0]];
        assert_eq!(misses("fifo:2", &tris, 4), 5);
        assert_eq!(misses("lru:2", &tris, 4), 4);
    }

    #[test]
    fn tiny_caches_and_huge_caches() {
        let tris: Vec<_> = FIG1.iter().map(|t| t.map(|v| v - 1)).collect();
        // Cache 1: a vertex hits only when it repeats the previous index; never here.
        assert_eq!(misses("fifo:1", &tris, 14), 48);
        assert_eq!(misses("lru:1", &tris, 14), 48);
        assert_eq!(misses("fifo:1000000", &tris, 14), 14);
    }

    #[test]
    fn batch_flushes_on_primgroup_and_warp() {
        let tris = [[0, 1, 2], [0, 1, 2], [0, 1, 2]];
        // primgroup 2: third triangle starts a new batch with an empty cache.
        let s = simulate("batch:16,0,2".parse().unwrap(), &tris, 3);
        assert_eq!((s.misses, s.batches), (6, 2));
        // warp 3: second triangle adds no vertices, so it fits.
        let s = simulate("batch:16,3,0".parse().unwrap(), &tris, 3);
        assert_eq!((s.misses, s.batches), (3, 1));
        let s = simulate("batch:16,4,0".parse().unwrap(), &[[0, 1, 2], [3, 4, 5]], 6);
        assert_eq!((s.misses, s.batches), (6, 2));
    }

    #[test]
    fn parse_and_display_round_trip() {
        for text in ["fifo:16", "lru:32", "batch:32,32,32", "batch:16,0,0"] {
            assert_eq!(text.parse::<CacheModel>().unwrap().to_string(), text);
        }
        for bad in ["fifo", "fifo:0", "fifo:x", "lru:1,2", "batch:32,2,0", "mru:4", "fifo:-3", "fifo:99999999"] {
            let err = bad.parse::<CacheModel>().unwrap_err().to_string();
            assert!(err.contains(bad), "{err}");
        }
    }
}
