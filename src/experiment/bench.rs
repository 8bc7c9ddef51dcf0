//! Speed of our metrics against meshoptimizer's analyzers, and of our orderings against the
//! meshoptimizer orderings they are peers of, timed in the same run on the same mesh, reported as
//! ratios (meshopt time ÷ ours: above 1 means we are faster).
//!
//! What is compared, and how the definitions differ:
//! - FIFO-16 and batch 32/32/32: identical models (tests/cache_vs_meshopt.rs proves equal counts).
//! - Overdraw: meshopt's `analyzeOverdraw` rasterises 6 axis views at 256² without culling, front
//!   and back faces into separate depth buffers, ties passing. Ours culls back faces and tests
//!   LESS with the top-left rule, per view set. The closest equal workload is our `axis6` at 256²;
//!   the counts differ by definition, the work is comparable.
//! - Orderings ([`compare_orderings`]): `tipsify:cache=16` against `optimizeVertexCacheFifo(16)`
//!   (the same algorithm) and `forsyth` (LRU 32, its default tuned score table) against
//!   `optimizeVertexCache` (a Forsyth-style greedy with meshoptimizer's own tuned score table and
//!   LRU 16), each with the ACMR of its order at FIFO-16. meshoptimizer builds its vertex→triangle
//!   adjacency inside the call; our orderings get it from the mesh's [`crate::mesh::Topology`], built once per
//!   mesh for every method. The first row of each pair times the ordering as triorder runs it; the
//!   `+ adjacency` row adds building that adjacency, the like-for-like comparison.
//!   `sander07` (Tipsify, fast linear clustering with λ = 0.85, dot-rule sort) is timed against
//!   `optimizeVertexCache` followed by `optimizeOverdraw` (threshold 1.05), meshoptimizer's take
//!   on the same paper; their overdraw is compared in the experiments (it needs rendering).
//!   `cheap-cuts` (ours, issue 19) is timed against the same pair, with its adjacency given and
//!   its default overdraw graph, estimated from surface patches on one thread (with
//!   `graph=views` its views are drawn on as many threads as `RAYON_NUM_THREADS` allows).
//! - Every timing calls each side twice a round on the same input, which is how it is done
//!   everywhere here. On the smallest meshes that also measures a branch predictor that has
//!   learnt the whole run: ordering RiggedSimple (188 triangles) takes meshoptimizer 12–19 µs
//!   on one input called over and over, and 26–35 µs when each call gets an input it has not
//!   seen (AMD EPYC, `triorder bench`, December 2026). So the two cache orderings also have a
//!   `fresh input` row ([`Fresh`]): the same mesh, its triangle list rotated to a different
//!   start each round, both sides given the same input just read into cache, and no warm-up
//!   call. That is what ordering a mesh once, as users do, costs. Its ACMR columns are the row
//!   above's, of the input as loaded.

use std::hint::black_box;
use std::time::Instant;

use crate::measure::cache::{CacheModel, simulate};
use crate::mesh::Framing;
use crate::mesh::progressive::History;
use crate::mesh::topology::{Csr, vertex_triangles};
use crate::mesh::{Mesh, Scene};
use crate::order::levels::Sequence;
use crate::order::{
    self,
    forsyth::{Scores, forsyth},
    sander07::sander07,
    tipsify::tipsify,
};
use rayon::prelude::*;

use crate::measure::translucency;
use crate::raster::{RasterBackend, ViewSet, cpu, cpu::CpuRaster};

/// One timed comparison.
#[derive(Debug, Clone)]
pub struct BenchRow {
    pub mesh: String,
    pub triangles: usize,
    pub task: String,
    pub ours_seconds: f64,
    /// `None` where meshopt has no equivalent.
    pub meshopt_seconds: Option<f64>,
    /// The lower and upper quartile of the per-round speedups (meshopt ÷ ours, timed in the same
    /// round), where meshopt has an equivalent: how far one round's ratio strays from another's.
    pub spread: Option<(f64, f64)>,
    /// For orderings: the ACMR at FIFO-16 of our order and of meshopt's.
    pub acmr: Option<(f64, f64)>,
}

impl BenchRow {
    /// meshopt time ÷ our time.
    pub fn speedup(&self) -> Option<f64> {
        self.meshopt_seconds.map(|m| m / self.ours_seconds)
    }
}

/// Median wall time of `reps` calls of `f`.
pub fn median_seconds(reps: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..reps.max(1))
            .map(|_| {
                let start = Instant::now();
                f();
                start.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

fn median(samples: Vec<f64>) -> f64 {
    quantile(samples, 0.5)
}

/// The `q`-quantile of `samples` (nearest rank; the middle one for 0.5 and an odd count).
fn quantile(mut samples: Vec<f64>, q: f64) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[((samples.len() - 1) as f64 * q).round() as usize]
}

/// The wall times of each of `fs` over `reps` rounds. The functions take turns within a round,
/// so that a change in machine load (other processes, clock boost) hits all of them alike; each
/// timed call follows an untimed call of the same function, so each is timed with its own data in
/// cache, as in a loop of calls, rather than with whatever the previous function left there.
pub fn interleaved<const N: usize>(reps: usize, mut fs: [&mut dyn FnMut(); N]) -> [Vec<f64>; N] {
    let mut times = [(); N].map(|_| Vec::with_capacity(reps.max(1)));
    for _ in 0..reps.max(1) {
        for (f, t) in fs.iter_mut().zip(&mut times) {
            f();
            let start = Instant::now();
            f();
            t.push(start.elapsed().as_secs_f64());
        }
    }
    times
}

/// Median wall time of each of `fs` over `reps` interleaved rounds ([`interleaved`]).
pub fn median_interleaved<const N: usize>(reps: usize, fs: [&mut dyn FnMut(); N]) -> [f64; N] {
    interleaved(reps, fs).map(median)
}

/// The median times of ours and meshopt's, and the quartiles of the per-round speedups.
fn against(ours: &[f64], theirs: &[f64]) -> (f64, f64, (f64, f64)) {
    let ratios: Vec<f64> = theirs.iter().zip(ours).map(|(t, o)| t / o).collect();
    (median(ours.to_vec()), median(theirs.to_vec()), (quantile(ratios.clone(), 0.25), quantile(ratios, 0.75)))
}

/// One timing of the two raster backends on the same work.
#[derive(Debug, Clone)]
pub struct BackendRow {
    pub mesh: String,
    pub triangles: usize,
    pub views: ViewSet,
    pub res: u32,
    pub cpu_seconds: f64,
    pub gpu_seconds: f64,
    /// The GPU backend as written into results (device and driver).
    pub device: String,
}

/// Times overdraw counting of `mesh` (in meshoptimizer's vertex-cache order) over `views` at
/// `res` on the CPU reference and on `gpu`, taking turns. The GPU time includes what a caller
/// pays: uploading the mesh, drawing, reading the counts back. Each backend counts once before
/// the timing, so one that refuses the mesh fails here instead of being timed failing.
pub fn compare_backends(
    mesh: &Mesh,
    gpu: &dyn RasterBackend,
    views: ViewSet,
    res: u32,
    reps: usize,
) -> crate::Result<BackendRow> {
    let indices = meshopt::optimize_vertex_cache(&mesh.index_buffer(), mesh.vertex_count());
    let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let cameras = views.cameras(Framing::of(&mesh.positions), 0);
    for backend in [&CpuRaster as &dyn RasterBackend, gpu] {
        backend.count(&mesh.positions, &triangles, &cameras, res)?;
    }
    let run = |backend: &dyn RasterBackend| black_box(backend.count(&mesh.positions, &triangles, &cameras, res).ok());
    let [cpu_seconds, gpu_seconds] = median_interleaved(reps, [&mut || drop(run(&CpuRaster)), &mut || drop(run(gpu))]);
    Ok(BackendRow {
        mesh: mesh.name.clone(),
        triangles: mesh.triangle_count(),
        views,
        res,
        cpu_seconds,
        gpu_seconds,
        device: gpu.describe(),
    })
}

/// Times every comparison on `mesh`, drawn in meshoptimizer's vertex-cache order (the realistic
/// case: an optimised mesh being analysed).
pub fn compare(mesh: &Mesh, reps: usize) -> Vec<BenchRow> {
    let indices = meshopt::optimize_vertex_cache(&mesh.index_buffer(), mesh.vertex_count());
    let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let n = mesh.vertex_count();
    let row = |task: &str, ours: f64, theirs: Option<(f64, (f64, f64))>| BenchRow {
        mesh: mesh.name.clone(),
        triangles: mesh.triangle_count(),
        task: task.to_string(),
        ours_seconds: ours,
        meshopt_seconds: theirs.map(|t| t.0),
        spread: theirs.map(|t| t.1),
        acmr: None,
    };
    let peer = |task: &str, [ours, theirs]: [Vec<f64>; 2]| {
        let (ours, theirs, spread) = against(&ours, &theirs);
        row(task, ours, Some((theirs, spread)))
    };
    let mut rows = Vec::new();
    for (model, (c, w, p)) in
        [(CacheModel::Fifo(16), (16, 0, 0)), (CacheModel::Batch { cache: 32, warp: 32, primgroup: 32 }, (32, 32, 32))]
    {
        let times = interleaved(
            reps,
            [&mut || _ = black_box(simulate(model, black_box(&triangles), n)), &mut || {
                _ = black_box(meshopt::analyze_vertex_cache(black_box(&indices), n, c, w, p))
            }],
        );
        rows.push(peer(&format!("cache {model}"), times));
    }
    let lru = median_seconds(reps, || _ = black_box(simulate(CacheModel::Lru(16), black_box(&triangles), n)));
    rows.push(row("cache lru:16", lru, None));

    let framing = Framing::of(&mesh.positions);
    let (positions, drawn) = (&mesh.positions, &triangles);
    let overdraw = |views: ViewSet, res: u32| {
        let cameras = views.cameras(framing, 0);
        move || drop(black_box(CpuRaster.count(positions, black_box(drawn), &cameras, res).ok()))
    };
    let adapter = mesh.meshopt_positions();
    let mut theirs = || _ = black_box(meshopt::analyze_overdraw(black_box(&indices), &adapter));
    // meshopt rasterises on one thread; compare like with like first, then our default.
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().map(|pool| {
        let mut ours = overdraw(ViewSet::Axis6, 256);
        pool.install(|| interleaved(reps, [&mut ours, &mut theirs]))
    });
    if let Ok(times) = one_thread {
        rows.push(peer("overdraw axis6@256, 1 thread (meshopt: 6 views@256)", times));
    }
    let threads = rayon::current_num_threads();
    let times = interleaved(reps, [&mut overdraw(ViewSet::Axis6, 256), &mut theirs]);
    rows.push(peer(&format!("overdraw axis6@256, {threads} threads"), times));
    let ico = median_seconds(reps.min(5), overdraw(ViewSet::Ico(162), 512));
    rows.push(row("overdraw ico:162@512", ico, None));
    // The translucency metric of the input order (issue 18: under 2 s on a 100k mesh).
    let ids: Vec<u32> = (0..drawn.len() as u32).collect();
    let cameras = ViewSet::Ico(162).cameras(framing, 0);
    let blend = median_seconds(reps.min(5), || {
        let errors: Vec<_> = cameras
            .par_iter()
            .map(|camera| {
                let mut fragments = Vec::new();
                cpu::fragments(positions, drawn, camera, 512, &mut fragments).ok();
                translucency::view_error(&fragments, &ids, 512)
            })
            .collect();
        black_box(errors);
    });
    rows.push(row("translucency ico:162@512 (blend vs exact)", blend, None));
    rows
}

/// One input per round of a timing, none repeated (see the module notes): the mesh's triangle list
/// rotated to `reps` evenly spaced starts, each with what either side takes.
struct Fresh {
    inputs: Vec<FreshInput>,
}

struct FreshInput {
    triangles: Vec<[u32; 3]>,
    /// Their vertex→triangle adjacency, given to ours as triorder gives it.
    adjacency: Csr,
    /// Their index buffer, for meshoptimizer.
    indices: Vec<u32>,
}

impl FreshInput {
    /// Reads every array once, so that neither side's call starts with the input out of cache.
    fn warm(&self) {
        let sum = |values: &[u32]| values.iter().fold(0u32, |s, &v| s.wrapping_add(v));
        black_box(
            sum(&self.indices)
                ^ sum(self.triangles.as_flattened())
                ^ sum(self.adjacency.items())
                ^ sum(self.adjacency.offsets()),
        );
    }
}

impl Fresh {
    fn of(mesh: &Mesh, reps: usize) -> Fresh {
        let count = reps.max(1);
        let inputs = (0..count)
            .map(|i| {
                let mut rotated = mesh.clone();
                rotated.triangles.rotate_left(i * mesh.triangle_count() / count);
                FreshInput {
                    adjacency: vertex_triangles(&rotated),
                    indices: rotated.index_buffer(),
                    triangles: rotated.triangles,
                }
            })
            .collect();
        Fresh { inputs }
    }

    /// Times of `theirs` and `ours`, taking turns as [`interleaved`] does but with no warm-up
    /// call: round k times each once on the k-th input, just read into cache.
    fn interleaved(&self, mut theirs: impl FnMut(&FreshInput), mut ours: impl FnMut(&FreshInput)) -> [Vec<f64>; 2] {
        let mut times = [Vec::with_capacity(self.inputs.len()), Vec::with_capacity(self.inputs.len())];
        for input in &self.inputs {
            for (f, t) in [&mut theirs as &mut dyn FnMut(&FreshInput), &mut ours].into_iter().zip(&mut times) {
                input.warm();
                let start = Instant::now();
                f(input);
                t.push(start.elapsed().as_secs_f64());
            }
        }
        times
    }
}

/// Times our cache orderings against their meshoptimizer peers on `mesh` (input order as loaded)
/// and measures each order's ACMR at FIFO-16. See the module notes for what each row includes.
pub fn compare_orderings(scene: &Scene, reps: usize) -> Vec<BenchRow> {
    let (mesh, topology) = (&scene.mesh, &scene.topology);
    let indices = mesh.index_buffer();
    let n = mesh.vertex_count();
    let fifo16 = |triangles: &[[u32; 3]]| simulate(CacheModel::Fifo(16), triangles, n).acmr();
    let ours_acmr = |spec: &str| {
        let resolved = order::resolve(spec, 0).expect("a registered method");
        order::run(&resolved, scene).map(|o| fifo16(&mesh.triangles_in_order(&o.buffers[0].order))).unwrap_or(f64::NAN)
    };
    let theirs_acmr =
        |indices: Vec<u32>| fifo16(&indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect::<Vec<_>>());
    let row = |task: &str, [theirs, ours]: [&Vec<f64>; 2], acmr: (f64, f64)| {
        let (ours, theirs, spread) = against(ours, theirs);
        BenchRow {
            mesh: mesh.name.clone(),
            triangles: mesh.triangle_count(),
            task: task.to_string(),
            ours_seconds: ours,
            meshopt_seconds: Some(theirs),
            spread: Some(spread),
            acmr: Some(acmr),
        }
    };
    let triangles = &mesh.triangles;

    let fifo_acmr = (ours_acmr("tipsify:cache=16"), theirs_acmr(meshopt::optimize_vertex_cache_fifo(&indices, n, 16)));
    let [fifo_theirs, ours, with_adjacency] = interleaved(
        reps,
        [
            &mut || drop(black_box(meshopt::optimize_vertex_cache_fifo(black_box(&indices), n, 16))),
            &mut || drop(black_box(tipsify(black_box(triangles), &topology.vertex_triangles, 16))),
            &mut || drop(black_box(tipsify(black_box(triangles), &vertex_triangles(mesh), 16))),
        ],
    );
    // Not a peer but the speed to match (issue 18): the O(n log n) translucent sort against
    // meshoptimizer's linear FIFO optimizer.
    let dist_angle = order::resolve("translucent-dist-angle", 0).expect("a registered method");
    let dist_acmr = (ours_acmr("translucent-dist-angle"), fifo_acmr.1);
    let [dist_theirs, dist_ours] = interleaved(
        reps,
        [&mut || drop(black_box(meshopt::optimize_vertex_cache_fifo(black_box(&indices), n, 16))), &mut || {
            drop(black_box(dist_angle.ordering.order(black_box(scene))))
        }],
    );
    let vcache_acmr = (ours_acmr("forsyth:cache=32"), theirs_acmr(meshopt::optimize_vertex_cache(&indices, n)));
    let [vcache_theirs, forsyth_ours, forsyth_with_adjacency] = interleaved(
        reps,
        [
            &mut || drop(black_box(meshopt::optimize_vertex_cache(black_box(&indices), n))),
            &mut || drop(black_box(forsyth(black_box(triangles), &topology.vertex_triangles, 32, Scores::Tuned))),
            &mut || drop(black_box(forsyth(black_box(triangles), &vertex_triangles(mesh), 32, Scores::Tuned))),
        ],
    );
    let fresh = Fresh::of(mesh, reps);
    let fresh_fifo = fresh.interleaved(
        |input| drop(black_box(meshopt::optimize_vertex_cache_fifo(black_box(&input.indices), n, 16))),
        |input| drop(black_box(tipsify(black_box(&input.triangles), &input.adjacency, 16))),
    );
    let fresh_vcache = fresh.interleaved(
        |input| drop(black_box(meshopt::optimize_vertex_cache(black_box(&input.indices), n))),
        |input| drop(black_box(forsyth(black_box(&input.triangles), &input.adjacency, 32, Scores::Tuned))),
    );
    drop(fresh);
    let positions = mesh.meshopt_positions();
    let overdraw_theirs = || {
        let mut indices = meshopt::optimize_vertex_cache(&indices, n);
        meshopt::optimize_overdraw_in_place(&mut indices, &positions, 1.05);
        indices
    };
    let overdraw_acmr = (ours_acmr("sander07:cache=16,lambda=0.85"), theirs_acmr(overdraw_theirs()));
    // Our own overdraw ordering (issue 19) against the same peer, its adjacency given.
    let cheap_cuts = order::resolve("cheap-cuts", 0).expect("a registered method");
    let cheap_acmr = (ours_acmr("cheap-cuts"), overdraw_acmr.1);
    let [cheap_theirs, cheap_ours] = interleaved(
        reps,
        [&mut || drop(black_box(overdraw_theirs())), &mut || {
            drop(black_box(cheap_cuts.ordering.order(black_box(scene))))
        }],
    );
    let [overdraw_theirs, sander_ours, sander_with_adjacency] = interleaved(
        reps,
        [
            &mut || drop(black_box(overdraw_theirs())),
            &mut || drop(black_box(sander07(black_box(mesh), &topology.vertex_triangles, 16, 0.85))),
            &mut || drop(black_box(sander07(black_box(mesh), &vertex_triangles(mesh), 16, 0.85))),
        ],
    );
    vec![
        row("tipsify:cache=16 vs optimizeVertexCacheFifo(16)", [&fifo_theirs, &ours], fifo_acmr),
        row("  the same, + adjacency", [&fifo_theirs, &with_adjacency], fifo_acmr),
        row("  the same, a fresh input each call", [&fresh_fifo[0], &fresh_fifo[1]], fifo_acmr),
        row("translucent-dist-angle vs optimizeVertexCacheFifo", [&dist_theirs, &dist_ours], dist_acmr),
        row("forsyth:cache=32 vs optimizeVertexCache", [&vcache_theirs, &forsyth_ours], vcache_acmr),
        row("  the same, + adjacency", [&vcache_theirs, &forsyth_with_adjacency], vcache_acmr),
        row("  the same, a fresh input each call", [&fresh_vcache[0], &fresh_vcache[1]], vcache_acmr),
        row("sander07 vs optimizeVertexCache+Overdraw(1.05)", [&overdraw_theirs, &sander_ours], overdraw_acmr),
        row("  the same, + adjacency", [&overdraw_theirs, &sander_with_adjacency], overdraw_acmr),
        row("cheap-cuts vs optimizeVertexCache+Overdraw(1.05)", [&cheap_theirs, &cheap_ours], cheap_acmr),
    ]
}

/// One timing of the progressive-mesh machinery (Bogomjakov & Gotsman 2002, §3).
#[derive(Debug, Clone)]
pub struct ProgressiveRow {
    pub task: String,
    pub triangles: usize,
    /// Vertex removals the task performs.
    pub removals: usize,
    pub ours_seconds: f64,
    /// meshoptimizer's simplifier to the same triangle count, where it is a peer.
    pub meshopt_seconds: Option<f64>,
}

/// Times, on `scene`'s mesh: the simplification history down to 1 % of the triangles against
/// `meshopt_simplify` to the same count (no error bound: both run to the count), and the simple and
/// smart updates of a sequence (Tipsify's, FIFO 16) through every removal of that history, which
/// meshoptimizer has no peer for. meshoptimizer's simplifier does edge collapses too, but keeps no
/// history and stops where its error bound says; ours records each removal for the updates.
pub fn compare_progressive(scene: &Scene, reps: usize) -> Vec<ProgressiveRow> {
    let mesh = &scene.mesh;
    let target = mesh.triangle_count() / 100;
    let indices = mesh.index_buffer();
    let positions = mesh.meshopt_positions();
    let simplify =
        || meshopt::simplify(&indices, &positions, target * 3, f32::MAX, meshopt::SimplifyOptions::None, None);
    let build = || History::build(mesh, &scene.topology, target);
    let [ours, theirs] =
        median_interleaved(reps, [&mut || drop(black_box(build())), &mut || drop(black_box(simplify()))]);
    let history = build();
    let (order, _) = tipsify(&mesh.triangles, &scene.topology.vertex_triangles, 16);
    let update = |smart: bool| {
        let mut sequence = Sequence::new(&history, &order);
        history.records.iter().for_each(|r| sequence.apply(&history, r, smart));
        sequence
    };
    let [simple, smart] =
        median_interleaved(reps, [&mut || drop(black_box(update(false))), &mut || drop(black_box(update(true)))]);
    let row = |task: &str, ours_seconds: f64, meshopt_seconds: Option<f64>| ProgressiveRow {
        task: task.to_string(),
        triangles: mesh.triangle_count(),
        removals: history.records.len(),
        ours_seconds,
        meshopt_seconds,
    };
    vec![
        row("history to 1% vs meshopt_simplify", ours, Some(theirs)),
        row("simple update, every removal", simple, None),
        row("smart update, every removal", smart, None),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    /// Every fresh input is the mesh's triangles from another start, with its own adjacency and
    /// index buffer, and no two start alike.
    #[test]
    fn fresh_inputs_are_distinct_rotations_of_the_mesh() {
        let mesh = procedural::generate("grid:8x4", 0).unwrap().unwrap();
        let fresh = Fresh::of(&mesh, 11);
        assert_eq!(fresh.inputs.len(), 11);
        let mut firsts: Vec<[u32; 3]> = fresh.inputs.iter().map(|input| input.triangles[0]).collect();
        firsts.sort_unstable();
        firsts.dedup();
        assert_eq!(firsts.len(), 11);
        for input in &fresh.inputs {
            let at = mesh.triangles.iter().position(|t| *t == input.triangles[0]).unwrap();
            let mut rotated = mesh.triangles.clone();
            rotated.rotate_left(at);
            assert_eq!(input.triangles, rotated);
            assert_eq!(input.indices, input.triangles.as_flattened());
            let mut with_these = mesh.clone();
            with_these.triangles = input.triangles.clone();
            assert_eq!(input.adjacency, vertex_triangles(&with_these));
        }
    }
}
