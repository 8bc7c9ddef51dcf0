//! Speed of our metrics against meshoptimizer's analyzers, timed in the same run on the same
//! index buffers, reported as ratios (meshopt time ÷ ours: above 1 means we are faster).
//!
//! What is compared, and how the definitions differ:
//! - FIFO-16 and batch 32/32/32: identical models (tests/cache_vs_meshopt.rs proves equal counts).
//! - Overdraw: meshopt's `analyzeOverdraw` rasterises 6 axis views at 256² without culling, front
//!   and back faces into separate depth buffers, ties passing. Ours culls back faces and tests
//!   LESS with the top-left rule, per view set. The closest equal workload is our `axis6` at 256²;
//!   the counts differ by definition, the work is comparable.

use std::time::Instant;

use crate::mesh::Mesh;
use crate::metrics::cache::{CacheModel, simulate};
use crate::peer;
use crate::raster::{Framing, RasterBackend, ViewSet, cpu::CpuRaster};

/// One timed comparison.
#[derive(Debug, Clone)]
pub struct BenchRow {
    pub mesh: String,
    pub triangles: usize,
    pub task: String,
    pub ours_seconds: f64,
    /// `None` where meshopt has no equivalent.
    pub meshopt_seconds: Option<f64>,
}

impl BenchRow {
    /// meshopt time ÷ our time.
    pub fn speedup(&self) -> Option<f64> {
        self.meshopt_seconds.map(|m| m / self.ours_seconds)
    }
}

/// Median wall time of `reps` calls of `f`.
pub fn median_seconds(reps: usize, mut f: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..reps.max(1))
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Times every comparison on `mesh`, drawn in meshoptimizer's vertex-cache order (the realistic
/// case: an optimised mesh being analysed).
pub fn compare(mesh: &Mesh, reps: usize) -> Vec<BenchRow> {
    let indices = meshopt::optimize_vertex_cache(&peer::index_buffer(mesh), mesh.vertex_count());
    let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let n = mesh.vertex_count();
    let row = |task: &str, ours: f64, theirs: Option<f64>| BenchRow {
        mesh: mesh.name.clone(),
        triangles: mesh.triangle_count(),
        task: task.to_string(),
        ours_seconds: ours,
        meshopt_seconds: theirs,
    };
    let mut rows = Vec::new();
    for (model, (c, w, p)) in
        [(CacheModel::Fifo(16), (16, 0, 0)), (CacheModel::Batch { cache: 32, warp: 32, primgroup: 32 }, (32, 32, 32))]
    {
        let ours = median_seconds(reps, || {
            std::hint::black_box(simulate(model, std::hint::black_box(&triangles), n));
        });
        let theirs = median_seconds(reps, || {
            std::hint::black_box(meshopt::analyze_vertex_cache(std::hint::black_box(&indices), n, c, w, p));
        });
        rows.push(row(&format!("cache {model}"), ours, Some(theirs)));
    }
    let lru = median_seconds(reps, || {
        std::hint::black_box(simulate(CacheModel::Lru(16), &triangles, n));
    });
    rows.push(row("cache lru:16", lru, None));

    let framing = Framing::of(&mesh.positions);
    let (positions, drawn) = (&mesh.positions, &triangles);
    let overdraw = |views: ViewSet, res: u32| {
        let cameras = views.cameras(framing, 0);
        move || {
            std::hint::black_box(CpuRaster.count(positions, drawn, &cameras, res).ok());
        }
    };
    let adapter = peer::positions(mesh);
    let theirs = median_seconds(reps, || {
        std::hint::black_box(meshopt::analyze_overdraw(&indices, &adapter));
    });
    // meshopt rasterises on one thread; compare like with like first, then our default.
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().map(|pool| {
        let mut time = overdraw(ViewSet::Axis6, 256);
        pool.install(|| median_seconds(reps, &mut time))
    });
    if let Ok(ours) = one_thread {
        rows.push(row("overdraw axis6@256, 1 thread (meshopt: 6 views@256)", ours, Some(theirs)));
    }
    let ours = median_seconds(reps, overdraw(ViewSet::Axis6, 256));
    let threads = rayon::current_num_threads();
    rows.push(row(&format!("overdraw axis6@256, {threads} threads"), ours, Some(theirs)));
    let ico = median_seconds(reps.min(5), overdraw(ViewSet::Ico(162), 512));
    rows.push(row("overdraw ico:162@512", ico, None));
    rows
}
