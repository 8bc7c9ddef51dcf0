//! `cheap-cuts`: ours (issue 19, point 3). A vertex-cache order cut into pieces only where cutting
//! costs few cache hits and the surface turns, and the pieces ordered by a pairwise overdraw
//! graph estimated from the surface.
//!
//! Sander, Nehab & Barczak 2007 (§4–5) and meshoptimizer's `optimizeOverdraw` cut a cache order
//! into clusters wherever a cluster's own ACMR crosses a threshold, whatever the cut costs, and
//! sort the clusters by a dot rule, which needs many small clusters to approach what a view-based
//! order reaches with few (on dragon_vrip_res3, sander07's clusters at λ 0.85 give OVR 1.082 by
//! the dot rule and 1.007 ordered by Han–Sander's view graph). Here the cuts are priced and the
//! pieces ordered by an overdraw graph:
//!
//! 1. **Cache order**: `forsyth` with its tuned table at LRU `lru` (24; at 32 it loses 2–3% to
//!    meshoptimizer under the NVIDIA model, at 16 it loses under Intel's FIFO 128).
//! 2. **What each cut costs**, exactly, in one FIFO simulation of that order at `cache` (128
//!    entries by default, Intel's FIFO, the largest cache of the vendor models): drawing
//!    position `i` with a cold cache loses one hit per vertex that was loaded before `i` and is hit
//!    again at or after `i` while still cached. Each residency (load, last hit] of a vertex adds
//!    one to every cut position it spans: a difference array, O(n). (Cold-starting also shifts the
//!    FIFO's later evictions; ignored here, and measured instead: the ACMR of the result.)
//! 3. **Loose units in dot-rule order** ([`sort_loose_units`]): where a cold start costs nothing
//!    in every costed FIFO, the order falls into units that share no cached vertex, and any order
//!    of them costs the caches the same. Runs of units shorter than `min` (small parts, flat-shaded
//!    faces, unwelded triangles), which no cut can separate, are put in the order of Sander,
//!    Nehab & Barczak 2007's dot rule (§5) instead of whatever order the greedy's fallback found;
//!    in the graph of step 5 their pieces' patches are formed along a space-filling curve, as the
//!    triangles of such a piece lie anywhere. Where the whole mesh is one such run (Fox,
//!    RobotExpressive, RiggedFigure), the dot rule's order is returned as it is. Added after the
//!    held-out characters showed the need (see **Tuning**), with no parameter of its own.
//! 4. **Cuts**, by price: the hits a cut loses divided by how much the surface turns there (the
//!    angle between the mean normals of the `min` triangles on either side), since a cut between
//!    pieces that face the same way buys no overdraw. Cheapest first, a cut is taken while the
//!    lost hits sum to at most `budget` × the order's misses, no other cut is within `min`
//!    triangles (so that the costs add up independently and the graph stays small), and there
//!    are fewer than `clusters` pieces. With `far` below 1 the same cuts are also costed in a
//!    128-entry FIFO (Intel's) and held to `far` × its misses: a second budget, for a `cache`
//!    below 128 (at 128 it only lowers `budget`).
//! 5. **Pieces ordered** by the pairwise overdraw graph of Nehab, Barczak & Sander 2006 (§4),
//!    then the greedy feedback arc set (§5); each piece keeps its cache order inside. With
//!    `graph=patches` (the default) the graph is estimated without drawing ([`patch_arcs`]: the
//!    pieces cut into patches of consecutive triangles, each pair weighed by the area one hides of
//!    the other, integrated over view directions); with `graph=views` it is counted exactly, one
//!    raster pass per view ([`one_pass`]), over `views` icosahedral views at `res`². The defaults
//!    below were first tuned with the views; the estimate replaced them afterwards, with nothing
//!    tuned for it (see **Time**), and the retuning for Intel's FIFO (see **Tuning**) used it.
//! 6. **Successions kept** ([`Sequence::keep_successions`]): pieces that follow each other in the
//!    cache order are drawn together again wherever that puts no more arc weight backward, so
//!    those cuts cost no cache hits after all. Added after the tuning below, with no parameter of
//!    its own: on the five tuning models it lowered every measure (mean OVR by 0.0015–0.0074,
//!    FIFO-16 by 0.25–0.34%, Intel's FIFO 128 by 1.0–1.7%, NVIDIA and AMD by 0.2–0.5%).
//! 7. **Runs moved** ([`Sequence::move_runs`]): a local search after the greedy heuristic, on the
//!    weight it leaves backward. Each run of pieces drawn together is moved whole to the place
//!    where its arcs put the least weight backward, never into another run, while any move
//!    lowers it; so no succession of step 6 is broken, and the cuts cost what they were priced.
//!    Added after the tuning, with no parameter of its own, and the defaults not tuned again: on
//!    the five tuning models it lowered mean OVR by 0.0027–0.0119 with FIFO-16 unchanged or lower
//!    (by up to 0.08%), which widened the smallest margin to the targets there at the defaults
//!    from 0.34 to 0.61 points. Moving single pieces instead, before step 6, lowered the
//!    overdraw more but broke successions (FIFO-16 up 0.2–0.3%; smallest margin 0.58–0.60), and
//!    was dropped.
//! 8. **Runs redrawn** ([`redraw_runs`]): a run's slice of the cache order was drawn by a greedy
//!    that counted the triangles of the pieces around it and started from a cache the cut has
//!    emptied. Each run is redrawn by Forsyth's greedy (`lru`, tuned table) over its own
//!    triangles, from the cache the runs before it left, so that its border vertices are
//!    finished inside it; as that cache almost never holds one of its vertices, it starts at its
//!    best-scoring triangle, as the article's walk does when the cache offers nothing (one on
//!    the run's border). It keeps the redrawn order where it misses no more than its slice in
//!    any costed FIFO (`cache`, and 128 with `far` below 1). The runs' sequence is unchanged.
//!    Added after the held-out FIFO-16 misses below, with no parameter of its own and the
//!    defaults not tuned again; see **Tuning** for what it changed and what was tried on the way.
//!
//! **Tuning, and what it costs.** The defaults were chosen on five models only: bun_zipper,
//! dragon_vrip_res3, feline, horse and rocker-arm (the rest are held out; spot and
//! happy_buddha_100k were looked at once, with an earlier variant). There, with the defaults, FIFO-16
//! ACMR is within 1% of meshopt-vcache's, mean OVR (ico:162, 512²) at most meshopt-overdraw's, and
//! the NVIDIA, AMD and Intel models within 2% of the best ordering.
//!
//! The cuts were first priced in FIFO-16 (`cache=16`, with `budget` 0.01, `min` 64, `lru` 20),
//! and everything below up to the retuning was measured so; what was tried and dropped then: 12
//! views or 16–24 random ones (OVR up to 0.01 worse), a graph drawn from every second or third
//! triangle (worse), cuts priced by hits alone (worse on all five). What those cuts could not
//! keep was Intel's FIFO 128, where a cut costs up to 128 hits: 3–6% above the best ordering
//! there before step 6 (still 2–9% below meshopt-overdraw), 3.1–3.6% on the tuning models at
//! the end, and holding it within 2% with `far` cost the overdraw that beats meshopt-overdraw.
//! **Retuning for Intel's FIFO** (2026-12-06, `572fa2d`): pricing the cuts in that FIFO itself,
//! `cache=128`, had not been tried. On the five tuning models, with the estimated graph, a grid of
//! `cache` 128 or 192 × `budget` 0.015, 0.02, 0.025 or 0.03 × `lru` 20, 24 or 28 × `min` 48, 64 or
//! 96 was measured, and the setting with the largest smallest margin to all five targets (in points
//! of each target, against the best of cheap-cuts' peers) taken: `cache` 128, `budget` 0.02, `lru`
//! 24, `min` 48, whose smallest margin is 0.32 points (OVR on bun_zipper; the four targets other
//! than Intel had had 0.62, and Intel −1.55 on rocker-arm). Held out, measured after the choice:
//! Intel within 2% on 15 of the 18 welded meshes instead of 1 (missed on dragon_vrip_res4, 2.0%
//! above the best, Xbot 2.2%, CesiumMan 3.2%), but the main targets missed on six instead of two:
//! OVR on armadillo (1.0484 against 1.0476), bunny_2k and dragon_vrip_res4, FIFO-16 on Michelle
//! (1.5% above meshopt-vcache), and Fox and RiggedFigure as before. The overdraw margin the tuning
//! models keep is half what it was, and held out it did not always hold. Tried after the choice and
//! dropped, judged on the tuning models alone: each run's redraw judged in FIFO-16 too (smallest
//! margin 0.32 again, a tie); with both FIFOs costed (`cache=16` and `far`), a cut priced by the
//! share of each one's budget it uses (0.26 at best over 36 settings); runs moved beside the run
//! they share the most vertices with, at no more backward weight (Intel moved by 0.0003 at most: a
//! FIFO of 128 keeps too little of a run to reuse its border).
//! `experiments/cheap-cuts-intel-tradeoff.toml` draws both pricings' trade-offs, and
//! `experiments/cheap-cuts-front.toml` the sweeps on the held-out misses.
//! `experiments/cheap-cuts-vendor-tradeoff.toml` sweeps `lru` from 16 to 40, beside Forsyth's
//! own order at each LRU: on the scans of 20,000 triangles and more a longer LRU lowers Intel's
//! ACMR and raises NVIDIA's along a front (at 32 NVIDIA's target fails on six of the eleven
//! scans), while on smaller meshes and Xbot both orders' Intel ACMR scatters by up to 3% between
//! neighbouring LRUs, and 24 happens to be a high draw on CesiumMan and Xbot, the held-out Intel
//! misses (Intel's target is met on both at 28 and 32). On the tuning models only 24 meets every target, so it stays; a finer look there, `lru`
//! 22 or 26 at budgets 0.015–0.025 (scratch `triorder eval` runs, five settings), left smallest
//! margins of −0.41 to 0.18 points against the defaults' 0.32.
//!
//! Before the retuning, held out, one of the two main targets failed on two of seventeen
//! meshes: OVR on Fox and RiggedFigure (all loose parts, which no pricing changes: the dot rule
//! alone, 1.0231 and 1.0245 against meshoptimizer's 1.0209 and 1.0244; keyed against
//! meshoptimizer's mesh centre, the mean of the index buffer's vertex positions, instead of the
//! area-weighted centroid, they come out at exactly meshoptimizer's values, and RobotExpressive
//! worse, 1.0809 against 1.0786: not adopted, as only held-out meshes tell the two apart).
//! Armadillo's OVR missed too (1.0483 against 1.0476) until step 7, FIFO-16 on Xbot (+1.6%) and
//! Michelle (+1.4%) until step 8, and FIFO-16 on spot (+1.45%, +1.07% after step 8; its cache
//! order alone is 0.7% above meshopt-vcache's) until a run redrawn from a cache holding none of
//! its vertices began to start at its best-scoring triangle (then +0.70%, and Xbot +0.68%,
//! Michelle +0.49%). Step 8 came from
//! those misses: of three variants measured on the 18 welded meshes, redrawing every run lowered
//! the smallest margin to the targets on the tuning models from 0.61 to 0.20 points (FIFO-16
//! rose on most meshes: the slice is the better order of some runs); keeping the better order
//! per run raised it to 0.62, the same whether a dead end resumes at the run's first triangle
//! left or, as kept, by Forsyth's own rule (the former would have passed spot: +0.97%). Where a
//! cold run starts was changed after spot's miss was looked at again: at its first triangle in
//! the cache order before, at its best-scoring one, Forsyth's own rule, since. The smallest margin
//! on the tuning models stayed 0.62 (their FIFO-16 from 0.04% lower to 0.14% higher); over the 18
//! welded meshes FIFO-16 is 0.12% lower (geometric mean; lower on 15) and the other measures move
//! by 0.04% or less. A tie on the tuning models, decided as the dead-end rule was, for Forsyth's
//! walk, with the held-out results seen. A mesh no cut fits, one piece, was returned as its cache
//! order until then; it is one run, and is now redrawn like any other (decided for that reason
//! before RiggedSimple, the one such shared mesh, was measured, though in the hope that it would
//! help there, as it did; no tuning model is one piece). Step 8 gave up a little of Intel's FIFO
//! 128 (armadillo 4.8% to 5.5% above the best), and brought Xbot's AMD within 2%. Step 3 was
//! added after those characters and Soldier showed what the greedy's fallback order cost them (mean
//! OVR, ico:162 at 512²: Soldier 1.2383 to 1.1684, RobotExpressive 1.1777 to 1.0786, RiggedFigure
//! 1.0772 to 1.0245, Fox 1.0420 to 1.0231; on the tuning models at most 0.0002; all before step
//! 7). paper-figures/README.md has the table, and the fronts: on each held-out miss of the
//! defaults some swept setting wins both main targets but on RiggedFigure, where none does now.
//! Judged on every target at once (both main ones, the three vendor models, time), some swept
//! setting meets them all on four of the eight held-out misses (armadillo, Xbot, Michelle,
//! CesiumMan; no one setting on all four), and none on bunny_2k, dragon_vrip_res4, Fox and
//! RiggedFigure: on the two small scans the overdraw needs cuts that Intel's FIFO 128 prices high.
//!
//! **Time.** Drawn from 42 views, the graph cost every triangle's setup in every view: by
//! `triorder bench` at `0d608d2` cheap-cuts took 1.75–2.9× meshopt-overdraw's time from 11k
//! triangles up but three characters, 3.3–4.8× on six more and 17–33× on the small
//! characters. The estimate ([`patch_arcs`], the default since, with nothing tuned for it) puts
//! it at 0.83–1.7× on the 23 meshes `triorder bench` times (at `7454984`, median of 11, AMD
//! EPYC), at about the views' overdraw: within 0.0024 of it on the tuning models (lower on three),
//! within 0.0011 on the welded held-out models but the pirate (1.145 against 1.070), and 0.013–0.069
//! higher on three layered characters (lower on Soldier and CesiumMan), still below
//! meshopt-overdraw's there (`experiments/cheap-cuts-graphs.toml`). A mesh no cut fits
//! (RiggedSimple) is one piece and one run, redrawn without a graph. Step 8 is a second Forsyth
//! pass: it made cheap-cuts 1.3–1.6× slower on the meshes it cuts: 1.20–2.74× meshopt-overdraw's
//! time at `63dd992` (Xbot highest, then BrainStem at 2.51×). Steps 6 and 7 on a dense matrix of
//! the graph's weights, and each turning window normalised once, brought that to 1.22–2.38× at
//! `369cc21` (Xbot 2.38×, BrainStem 2.04×), with the same orders. Redrawing a mesh of one piece
//! as one run took RiggedSimple from 1.3× to 2.5× (`fa5a74a`: 37 µs against 15 µs). With the
//! cuts priced in Intel's FIFO (`572fa2d`): 1.18–2.44× (RiggedSimple 2.44×, Xbot 2.17×,
//! BrainStem 1.85×, the rest at most 1.79×).

use std::ops::Range;

use glam::{DVec3, Vec3};

mod redraw;
mod sequence;

use super::forsyth::{Scores, forsyth};
use super::nehab::feedback_arc_set::greedy_order;
use super::nehab::overdraw_graph::{ClusteredDraw, one_pass};
use super::nehab::patch_graph::patch_arcs;
use super::sander07::{Facing, dot_rule_sort};
use super::{Cost, Method, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::mesh::{Framing, Scene};
use redraw::redraw_runs;
use sequence::Sequence;
use crate::raster::{ViewSet, naming_mesh};

const BUDGET: ParamInfo = ParamInfo {
    name: "budget",
    default: "0.02",
    kind: ParamKind::Float { min: 0.0, max: 1.0 },
    help: "cache misses the cuts may add in the `cache` FIFO, as a share of the cache order's (0.02 = 2%)",
};

const MIN: ParamInfo = ParamInfo {
    name: "min",
    default: "48",
    kind: ParamKind::Int { min: 1, max: 1 << 20 },
    help: "fewest triangles between two cuts",
};

const CLUSTERS: ParamInfo = ParamInfo {
    name: "clusters",
    default: "512",
    kind: ParamKind::Int { min: 1, max: 4096 },
    help: "most pieces the order is cut into",
};

const VIEWS: ParamInfo = ParamInfo {
    name: "views",
    default: "42",
    kind: ParamKind::Choice(&["12", "42", "162", "642"]),
    help: "icosahedral views the overdraw graph is drawn from, with graph=views",
};

const RES: ParamInfo = ParamInfo {
    name: "res",
    default: "64",
    kind: ParamKind::Int { min: 8, max: 4096 },
    help: "resolution of the overdraw graph's views, with graph=views",
};

/// The second FIFO the cuts are costed in: Intel's 128 entries (Kapoulkine 2017, the `intel`
/// model), the largest cache of the vendor models, where a cut loses the most.
const FAR: u32 = 128;

const FAR_BUDGET: ParamInfo = ParamInfo {
    name: "far",
    default: "1",
    kind: ParamKind::Float { min: 0.0, max: 1.0 },
    help: "misses the cuts may add in a 128-entry FIFO (Intel's), as a share of the order's, for a `cache` below 128 (1: no limit)",
};

const GRAPH: ParamInfo = ParamInfo {
    name: "graph",
    default: "patches",
    kind: ParamKind::Choice(&["patches", "views"]),
    help: "the pieces' overdraw graph: estimated from surface patches, or drawn from `views` views at `res`²",
};

const LRU: ParamInfo = ParamInfo {
    name: "lru",
    default: "24",
    kind: ParamKind::Int { min: 4, max: 1024 },
    help: "LRU size the Forsyth scores model, in the cache order and in each run's redraw (longer: on closed scans fewer misses in Intel's FIFO 128 and more under NVIDIA's batches)",
};

const CACHE: ParamInfo = ParamInfo {
    name: "cache",
    default: "128",
    kind: ParamKind::Int { min: 3, max: 1024 },
    help: "FIFO size whose hits the cuts are costed in (128: Intel's), and each run's order (redrawn or not) chosen by",
};

pub static METHOD: Method = Method {
    name: "cheap-cuts",
    summary: "ours: Forsyth order cut where the FIFO loses least, pieces (and loose parts) ordered for overdraw, runs redrawn",
    source: "ours (issue 19); graph and ordering after Nehab, Barczak & Sander 2006, §4-5",
    peer: false,
    per_node: false,
    cost: Cost::Heavy,
    params: &[BUDGET, FAR_BUDGET, MIN, CLUSTERS, VIEWS, RES, GRAPH, CACHE, LRU],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(CheapCuts {
        budget: params.float(&BUDGET),
        far: params.float(&FAR_BUDGET),
        min: params.int(&MIN) as usize,
        clusters: params.int(&CLUSTERS) as usize,
        graph: match params.word(&GRAPH) {
            "views" => Graph::Views {
                views: params.word(&VIEWS).parse().expect("the schema lists only numbers"),
                res: params.int(&RES) as u32,
            },
            _ => Graph::Patches,
        },
        cache: params.int(&CACHE) as u32,
        lru: params.int(&LRU) as usize,
    })
}

/// How the pieces' overdraw graph is found (`graph=`): estimated, or drawn from `views` views at
/// `res`².
#[derive(Clone, Copy)]
enum Graph {
    Patches,
    Views { views: u32, res: u32 },
}

struct CheapCuts {
    budget: f64,
    far: f64,
    min: usize,
    clusters: usize,
    graph: Graph,
    cache: u32,
    lru: usize,
}

impl Ordering for CheapCuts {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let mut order = forsyth(&mesh.triangles, &scene.topology.vertex_triangles, self.lru, Scores::Tuned);
        // The far FIFO is simulated only when it is limited, and not at all when it is the first
        // (the default `cache`): there `far` only lowers the budget.
        let (far, budget) =
            if self.cache == FAR { (false, self.budget.min(self.far)) } else { (self.far < 1.0, self.budget) };
        let caches = [(self.cache, budget), (FAR, self.far)];
        let mut costs: Vec<(CutCosts, f64)> = caches[..if far { 2 } else { 1 }]
            .iter()
            .map(|&(size, budget)| (cut_costs(&mesh.triangles, &order, mesh.vertex_count(), size), budget))
            .collect();
        let loose = sort_loose_units(&mut order, &mut costs, &mesh.positions, &mesh.triangles, self.min);
        // Every unit loose (nothing welded beyond a few faces: Fox, RobotExpressive,
        // RiggedFigure): the dot rule has ordered parts that share nothing, and pieces cut from
        // that order would be bands of it, each scattered over the mesh. Ordered by the graph,
        // they came out within 0.0016 of the rule's own mean OVR (better on none), at 1.9–2.9
        // times the time (`triorder bench`): the rule's order is kept.
        if loose.first() == Some(&(0..order.len())) {
            return Ok(order.into());
        }
        let turn = turning(&mesh.positions, &mesh.triangles, &order, self.min);
        let starts = cheapest_cuts(&costs, &turn, self.min, self.clusters);
        // One piece is one run, redrawn as step 8 redraws every run, without a graph, which would
        // be built for nothing (RiggedSimple's 188 triangles: drawing 42 views at 64² was about
        // 96% of the time). It used to be returned as its cache order.
        let costed: Vec<u32> = caches[..costs.len()].iter().map(|&(size, _)| size).collect();
        if starts.len() == 2 {
            return Ok(redraw_runs(&mesh.triangles, &scene.topology.vertex_triangles, &[&order], self.lru, &costed).into());
        }
        let triangles = mesh.triangles_in_order(&order);
        let draw = ClusteredDraw { positions: &mesh.positions, triangles: &triangles, starts: &starts };
        let arcs = match self.graph {
            Graph::Patches => patch_arcs(&mesh.positions, &triangles, &starts, &loose),
            Graph::Views { views, res } => {
                let cameras = ViewSet::Ico(views).cameras(Framing::of(&mesh.positions), 0);
                one_pass(draw, &cameras, res).map_err(|e| naming_mesh(&mesh.name, e))?.arcs()
            }
        };
        let mut pieces = Sequence::new(greedy_order(draw.cluster_count(), &arcs), &arcs);
        pieces.keep_successions();
        pieces.move_runs();
        let runs: Vec<&[u32]> = pieces
            .sequence
            .chunk_by(|&a, &b| b == a + 1)
            .map(|run| &order[starts[run[0] as usize]..starts[run[run.len() - 1] as usize + 1]])
            .collect();
        Ok(redraw_runs(&mesh.triangles, &scene.topology.vertex_triangles, &runs, self.lru, &costed).into())
    }
}

/// Step 3: the cache order's loose units put in dot-rule order; the ranges of `order` so sorted,
/// in increasing order.
///
/// Where a cold start costs no hit in any costed cache, nothing drawn before is reused after: the
/// order falls there into units that share no cached vertex, and any order of the units costs the
/// cache the same. Forsyth's greedy walks a welded surface as a few large units, but a mesh of
/// many small parts (Soldier's straps, BrainStem's tubes) or one whose faces carry their own
/// vertices (RobotExpressive's flat-shaded quads, Fox's unwelded triangles) is hundreds of units
/// shorter than `min`, which the cuts cannot separate: their order was whatever the greedy's
/// fallback (input order) gave, and each piece cut from them mixed far-apart parts. So each run
/// of two or more consecutive units shorter than `min` is put in the order of Sander, Nehab &
/// Barczak 2007's dot rule ([`dot_rule_sort`], keyed against the whole mesh's centroid), which
/// draws outward-facing parts first at no cost to any cache. Larger units stay where they are.
fn sort_loose_units(
    order: &mut Vec<u32>,
    costs: &mut [(CutCosts, f64)],
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    min: usize,
) -> Vec<Range<usize>> {
    let n = order.len();
    let mut bounds = vec![0];
    bounds.extend((1..n).filter(|&i| costs.iter().all(|(c, _)| c.lost[i] == 0)));
    bounds.push(n);
    let units = bounds.len() - 1;
    let loose = |u: usize| bounds[u + 1] - bounds[u] < min;
    if !(1..units).any(|u| loose(u - 1) && loose(u)) {
        return Vec::new();
    }
    let unit_triangles: Vec<&[u32]> = bounds.windows(2).map(|w| &order[w[0]..w[1]]).collect();
    // Every unit is keyed, so that the dot rule's centroid is the whole mesh's.
    let mut rank = vec![0; units];
    for (r, u) in dot_rule_sort(positions, triangles, &unit_triangles, Facing::Mean).into_iter().enumerate() {
        rank[u] = r;
    }
    let (mut units_in_order, mut ranges) = (Vec::with_capacity(units), Vec::new());
    let mut u = 0;
    while u < units {
        let end = if loose(u) { (u..units).find(|&e| !loose(e)).unwrap_or(units) } else { u + 1 };
        let run = units_in_order.len();
        units_in_order.extend(u..end);
        if end - u > 1 {
            units_in_order[run..].sort_by_key(|&v| rank[v]);
            ranges.push(bounds[u]..bounds[end]);
        }
        u = end;
    }
    // Each unit carries its cut costs along: they count only hits within the unit. (Two units
    // that share a vertex beyond the cache's reach may now meet; the hits that gains are not
    // priced, as none of the cache order's were lost.)
    let moved = |values: &[u32]| -> Vec<u32> {
        let mut moved = Vec::with_capacity(n);
        units_in_order.iter().for_each(|&v| moved.extend_from_slice(&values[bounds[v]..bounds[v + 1]]));
        moved
    };
    *order = moved(order);
    for (cost, _) in costs.iter_mut() {
        cost.lost = moved(&cost.lost);
    }
    ranges
}

/// What cutting a cache order costs at each position, under a FIFO.
struct CutCosts {
    /// `lost[i]`: hits lost if position `i` is drawn with a cold cache (`lost[0]` is 0).
    lost: Vec<u32>,
    /// The order's misses, uncut.
    misses: u64,
}

/// One FIFO simulation of `order` (a permutation of `triangles`' ids) with `cache` entries.
fn cut_costs(triangles: &[[u32; 3]], order: &[u32], vertex_count: usize, cache: u32) -> CutCosts {
    // Per vertex: the miss count at its last load (its FIFO stamp), the position that loaded it,
    // and its last hit since (equal to the load: none).
    const NEVER: u32 = u32::MAX;
    let mut stamp = vec![0u32; vertex_count];
    let mut loaded = vec![NEVER; vertex_count];
    let mut last_hit = vec![0u32; vertex_count];
    let mut delta = vec![0i32; order.len() + 1];
    let mut close = |loaded: u32, last_hit: u32| {
        if loaded != NEVER && last_hit > loaded {
            delta[loaded as usize + 1] += 1;
            delta[last_hit as usize + 1] -= 1;
        }
    };
    let mut misses = 0u32;
    for (i, &t) in order.iter().enumerate() {
        for v in triangles[t as usize] {
            let v = v as usize;
            if loaded[v] != NEVER && misses - stamp[v] <= cache {
                last_hit[v] = i as u32;
            } else {
                close(loaded[v], last_hit[v]);
                misses += 1;
                stamp[v] = misses - 1;
                loaded[v] = i as u32;
                last_hit[v] = i as u32;
            }
        }
    }
    for v in 0..vertex_count {
        close(loaded[v], last_hit[v]);
    }
    let mut running = 0i32;
    let lost = delta[..order.len()]
        .iter()
        .map(|&d| {
            running += d;
            running as u32
        })
        .collect();
    CutCosts { lost, misses: u64::from(misses) }
}

/// Cluster starts (from 0, ending with the order's length): cut positions taken in increasing
/// price, the hits lost in the first cache divided by how much the surface turns there (plus
/// [`TURN_FLOOR`]), each while every cache's lost hits stay within its budget share of its
/// misses, no two cuts (nor a cut and either end) are closer than `min`, and there are fewer than
/// `most` pieces. Ties go to the earlier position.
fn cheapest_cuts(costs: &[(CutCosts, f64)], turn: &[f64], min: usize, most: usize) -> Vec<usize> {
    let n = turn.len();
    let price = |i: usize| f64::from(costs[0].0.lost[i]) / (turn[i] + TURN_FLOOR);
    // Prices are finite and at least +0.0 (hits ≥ 0 over a turn ≥ 0 plus the floor), and for
    // such numbers the order of their bits is their order. The radix sort is stable, so ties
    // keep the positions' increasing order: the comparison sort it replaced, a sixth of
    // cheap-cuts' own time on BrainStem (61k triangles), gave the same order.
    let mut candidates: Vec<(u64, usize)> =
        (min.max(1)..=n.saturating_sub(min)).map(|i| (price(i).to_bits(), i)).collect();
    radsort::sort_by_key(&mut candidates, |c| c.0);
    let allowed: Vec<f64> = costs.iter().map(|(c, budget)| budget * c.misses as f64).collect();
    let mut spent = vec![0.0; costs.len()];
    let mut cuts = Vec::new();
    // Positions closer than `min` to a cut taken: marked as each cut is taken, so a candidate
    // is checked in one read.
    let mut blocked = vec![false; n + 1];
    for (_, i) in candidates {
        if cuts.len() + 1 >= most {
            break;
        }
        let fits = costs.iter().zip(&spent).zip(&allowed).all(|(((c, _), s), a)| s + f64::from(c.lost[i]) <= *a);
        if fits && !blocked[i] {
            cuts.push(i);
            blocked[(i + 1).saturating_sub(min)..(i + min).min(n + 1)].fill(true);
            costs.iter().zip(&mut spent).for_each(|((c, _), s)| *s += f64::from(c.lost[i]));
        }
    }
    cuts.sort_unstable();
    std::iter::once(0).chain(cuts).chain(std::iter::once(n)).collect()
}

/// Added to every turn, so that a cut between pieces facing the same way is dear but not
/// infinitely so.
const TURN_FLOOR: f64 = 0.05;

/// How much the surface turns at each cut position of `order`: 1 − cos of the angle between the
/// area-weighted normals of the `window` triangles before and after it (0 on a plane, 2 where the
/// two sides face apart), rounded to 1/1024 so that a copy of the mesh in other units, whose
/// coordinates differ in the last bit, prices its cuts the same. Prefix sums of the normals: O(n).
/// A cut there separates pieces that face different ways, which is what lets the overdraw graph
/// order them.
fn turning(positions: &[Vec3], triangles: &[[u32; 3]], order: &[u32], window: usize) -> Vec<f64> {
    let mut prefix = Vec::with_capacity(order.len() + 1);
    prefix.push(DVec3::ZERO);
    for &t in order {
        let [a, b, c] = triangles[t as usize].map(|v| positions[v as usize].as_dvec3());
        prefix.push(prefix.last().unwrap() + (b - a).cross(c - a));
    }
    let n = order.len();
    // The normal of the window that ends at each position, normalized once: it is the `before`
    // of that position and the `after` of the one a window earlier.
    let ending: Vec<DVec3> =
        (0..=n).map(|end| (prefix[end] - prefix[end.saturating_sub(window)]).normalize_or_zero()).collect();
    (0..n)
        .map(|i| {
            let after = match ending.get(i + window) {
                Some(&after) => after,
                None => (prefix[n] - prefix[i]).normalize_or_zero(),
            };
            ((1.0 - ending[i].dot(after)) * 1024.0).round() / 1024.0
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of quads along x: triangles (2i, 2i+1) share vertices with their neighbours.
    fn strip(quads: u32) -> Vec<[u32; 3]> {
        (0..quads).flat_map(|i| [[2 * i, 2 * i + 1, 2 * i + 2], [2 * i + 1, 2 * i + 3, 2 * i + 2]]).collect()
    }

    /// On a strip in order, a cold start at triangle `i > 0` reloads the two vertices it shares
    /// with triangle `i − 1`; a large enough FIFO also loses the third one the triangle after it
    /// reuses. Position 0 costs nothing, and every hit the uncut order makes is counted once.
    #[test]
    fn cut_costs_count_the_hits_a_cold_start_loses() {
        let tris = strip(10);
        let order: Vec<u32> = (0..tris.len() as u32).collect();
        let costs = cut_costs(&tris, &order, 22, 16);
        assert_eq!(costs.misses, 22);
        assert_eq!(costs.lost[0], 0);
        assert!(costs.lost[1..].iter().all(|&l| l == 2 || l == 3), "{:?}", costs.lost);
        // With a FIFO of 1, a vertex is gone at the next miss: fewer hits to lose.
        let small = cut_costs(&tris, &order, 22, 1);
        assert!(small.misses > costs.misses);
        assert!(small.lost.iter().zip(&costs.lost).all(|(s, c)| s <= c));
        // A cold start right after a jump to a separate strip loses nothing.
        let mut two = strip(3);
        two.extend(strip(3).iter().map(|t| t.map(|v| v + 100)));
        let order: Vec<u32> = (0..two.len() as u32).collect();
        assert_eq!(cut_costs(&two, &order, 200, 16).lost[6], 0);
    }

    /// Where no cut is taken (a mesh shorter than two spacings, or `clusters=1`), the mesh is one
    /// piece and one run, ordered without a graph: step 8 keeps the cache order or its redraw
    /// from the best-scoring triangle, whichever misses less in the `cache` FIFO (the redraw on a
    /// tie). Checked at the defaults' `lru` and `cache`.
    #[test]
    fn one_piece_is_one_run_redrawn() {
        use crate::measure::cache::{CacheModel, simulate};
        use crate::mesh::{Scene, procedural};
        use crate::order::forsyth::Redraw;
        let cases = [
            ("grid:6x6", "cheap-cuts"),
            ("sphere:2000", "cheap-cuts:clusters=1"),
            ("helix:3", "cheap-cuts:min=100000"),
            // Where the redraw misses less at the defaults (225 against 230 in the FIFO of 128);
            // on the others the two miss the same.
            ("disk:400", "cheap-cuts:clusters=1"),
        ];
        let (lru, fifo) = (LRU.default.parse().unwrap(), CACHE.default.parse().unwrap());
        let mut redrawn_kept = 0;
        for (spec, method) in cases {
            let scene = Scene::still(procedural::generate(spec, 3).unwrap().unwrap());
            let (mesh, adjacency) = (&scene.mesh, &scene.topology.vertex_triangles);
            let cheap = crate::order::run(&crate::order::resolve(method, 0).unwrap(), &scene).unwrap();
            let cache = forsyth(&mesh.triangles, adjacency, lru, Scores::Tuned);
            let mut redrawn = Vec::new();
            Redraw::new(&mesh.triangles, adjacency, &cache, lru, Scores::Tuned).redraw(&cache, &[], &mut redrawn);
            let misses = |order: &[u32]| {
                simulate(CacheModel::Fifo(fifo), &mesh.triangles_in_order(order), mesh.vertex_count()).misses
            };
            let kept = if misses(&redrawn) <= misses(&cache) { &redrawn } else { &cache };
            let one = cheap.single().expect("one buffer");
            assert_eq!(&one.order, kept, "{spec}");
            assert_eq!(one.starts, [0, cache.len()], "{spec}");
            redrawn_kept += usize::from(*kept != cache);
        }
        assert!(redrawn_kept > 0, "no case keeps a redrawn order: the test tells nothing from the cache order");
    }

    /// At the default `cache`, Intel's FIFO, `far` is no second FIFO but a lower budget in the
    /// same one: the same order as that budget, with fewer cuts than the default's.
    #[test]
    fn far_at_the_far_cache_is_a_budget() {
        use crate::mesh::{Scene, procedural};
        let scene = Scene::still(procedural::generate("helix:8", 3).unwrap().unwrap());
        let run = |spec: &str| crate::order::run(&crate::order::resolve(spec, 0).unwrap(), &scene).unwrap();
        let (far, budget, default) = (run("cheap-cuts:far=0.001"), run("cheap-cuts:budget=0.001"), run("cheap-cuts"));
        assert_eq!(far.buffers, budget.buffers);
        assert_ne!(far.buffers, default.buffers, "the lower budget changes nothing here: the test tells nothing");
    }

    /// Three unit squares of their own vertices, given in the order inward (at −x, facing +x),
    /// outward (at +x, facing +x), upward (at +y, facing +y): the cache order draws them as they
    /// come, each square a unit no cut costs anything to separate, and the three (all shorter
    /// than `min`) are put in dot-rule order against their common centroid (0, 1, 0): keys 3
    /// (outward), 2 (upward), −3 (inward). Each square stays whole, and the cut costs move with
    /// it, so that a unit still starts where a cold start costs nothing.
    #[test]
    fn loose_units_are_put_in_dot_rule_order() {
        let (mut positions, mut triangles) = (Vec::new(), Vec::new());
        let (inward, outward, upward) =
            ((-3.0 * Vec3::X, Vec3::Y, Vec3::Z), (3.0 * Vec3::X, Vec3::Y, Vec3::Z), (3.0 * Vec3::Y, Vec3::Z, Vec3::X));
        let squares = [inward, outward, upward];
        for (centre, u, v) in squares {
            let o = positions.len() as u32;
            let (a, b) = (0.5 * (u + v), 0.5 * (u - v));
            positions.extend([centre - a, centre + b, centre + a, centre - b]);
            triangles.extend([[o, o + 1, o + 2], [o, o + 2, o + 3]]);
        }
        let adjacency = crate::mesh::topology::vertex_triangles(&crate::mesh::Mesh {
            name: "squares".into(),
            positions: positions.clone(),
            triangles: triangles.clone(),
            attributes: Default::default(),
        });
        let mut order = forsyth(&triangles, &adjacency, 20, Scores::Tuned);
        assert_eq!(order, [0, 1, 2, 3, 4, 5], "the cache order draws the squares as given");
        let mut costs = vec![(cut_costs(&triangles, &order, positions.len(), 16), 0.01)];
        let lost_inside = costs[0].0.lost[1];
        assert!(lost_inside > 0, "a cut inside a square costs hits");
        let loose = sort_loose_units(&mut order, &mut costs, &positions, &triangles, 64);
        assert_eq!(loose, vec![0..order.len()]);
        assert_eq!(order, [2, 3, 4, 5, 0, 1]);
        assert_eq!(costs[0].0.lost, [0, lost_inside, 0, lost_inside, 0, lost_inside]);
        // With `min` 2 each square is a unit long enough to be cut off: nothing moves.
        let mut order = forsyth(&triangles, &adjacency, 20, Scores::Tuned);
        let mut costs = vec![(cut_costs(&triangles, &order, positions.len(), 16), 0.01)];
        assert!(sort_loose_units(&mut order, &mut costs, &positions, &triangles, 2).is_empty());
        assert_eq!(order, [0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn cuts_keep_their_budget_their_spacing_and_their_count() {
        // Costs 5 everywhere except free cuts at 30 and 60; a flat surface (no turn anywhere).
        let mut lost = vec![5u32; 100];
        lost[0] = 0;
        lost[30] = 0;
        lost[60] = 0;
        let costs = |budget| vec![(CutCosts { lost: lost.clone(), misses: 100 }, budget)];
        let flat = vec![0.0; 100];
        assert_eq!(cheapest_cuts(&costs(0.0), &flat, 10, 64), [0, 30, 60, 100]);
        // A budget of 10 misses buys two cuts of 5, the earliest that keep 10 apart from the others.
        assert_eq!(cheapest_cuts(&costs(0.1), &flat, 10, 64), [0, 10, 20, 30, 60, 100]);
        // At most three pieces: the two free cuts only.
        assert_eq!(cheapest_cuts(&costs(1.0), &flat, 10, 3), [0, 30, 60, 100]);
        // Where the surface turns, a paid cut is cheaper: it is taken first.
        let mut turn = flat.clone();
        turn[75] = 1.0;
        assert_eq!(cheapest_cuts(&costs(0.05), &turn, 10, 64), [0, 30, 60, 75, 100]);
        // Shorter than two spacings: no cut.
        assert_eq!(cheapest_cuts(&costs(1.0), &flat[..15], 10, 64), [0, 15]);
    }
}
