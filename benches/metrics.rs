//! Criterion benchmarks: our cache simulators (FIFO, batch, LRU) and rasterizer (on the default
//! threads and on one, as meshoptimizer runs) beside meshoptimizer's analyzers
//! on the same index buffers in the same run (`cargo bench`). `triorder bench` prints the same
//! comparison as a ratio table; this file gives criterion's confidence intervals.
//!
//! Uses the shared bunny (69,451 triangles) when ../shared/data exists, else a procedural sphere.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use triorder::measure::cache::{CacheModel, simulate};
use triorder::mesh::Framing;
use triorder::mesh::{Mesh, Source, source};
use triorder::raster::{RasterBackend, ViewSet, cpu::CpuRaster};

fn mesh() -> Mesh {
    let data = source::data_dir(None).or_else(|| Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data")));
    let open = |name: &str| Source::parse(name)?.mesh(data.as_deref(), 0);
    open("models/bun_zipper.ply").or_else(|_| open("sphere:70000")).expect("a benchmark mesh")
}

fn benches(c: &mut Criterion) {
    let mesh = mesh();
    let indices = meshopt::optimize_vertex_cache(&mesh.index_buffer(), mesh.vertex_count());
    let triangles: Vec<[u32; 3]> = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let n = mesh.vertex_count();

    let mut group = c.benchmark_group(format!("vertex cache, {} triangles", triangles.len()));
    group.bench_function("triorder fifo:16", |b| b.iter(|| simulate(CacheModel::Fifo(16), black_box(&triangles), n)));
    group.bench_function("meshopt analyzeVertexCache(16,0,0)", |b| {
        b.iter(|| meshopt::analyze_vertex_cache(black_box(&indices), n, 16, 0, 0))
    });
    let batch = CacheModel::Batch { cache: 32, warp: 32, primgroup: 32 };
    group.bench_function("triorder batch:32,32,32", |b| b.iter(|| simulate(batch, black_box(&triangles), n)));
    group.bench_function("meshopt analyzeVertexCache(32,32,32)", |b| {
        b.iter(|| meshopt::analyze_vertex_cache(black_box(&indices), n, 32, 32, 32))
    });
    group.bench_function("triorder lru:16", |b| b.iter(|| simulate(CacheModel::Lru(16), black_box(&triangles), n)));
    group.finish();

    let mut group = c.benchmark_group(format!("overdraw, {} triangles", triangles.len()));
    group.sample_size(10);
    let cameras = ViewSet::Axis6.cameras(Framing::of(&mesh.positions), 0);
    group.bench_function("triorder axis6@256", |b| {
        b.iter(|| CpuRaster.count(&mesh.positions, black_box(&triangles), &cameras, 256).unwrap())
    });
    // meshoptimizer rasterises on one thread: the like-for-like comparison.
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a thread pool");
    group.bench_function("triorder axis6@256, 1 thread", |b| {
        b.iter(|| {
            one_thread.install(|| CpuRaster.count(&mesh.positions, black_box(&triangles), &cameras, 256).unwrap())
        })
    });
    let adapter = mesh.meshopt_positions();
    group.bench_function("meshopt analyzeOverdraw (6 views@256)", |b| {
        b.iter(|| meshopt::analyze_overdraw(black_box(&indices), &adapter))
    });
    let ico = ViewSet::Ico(162).cameras(Framing::of(&mesh.positions), 0);
    group.bench_function("triorder ico:162@512", |b| {
        b.iter(|| CpuRaster.count(&mesh.positions, black_box(&triangles), &ico, 512).unwrap())
    });
    group.finish();
}

criterion_group!(metrics, benches);
criterion_main!(metrics);
