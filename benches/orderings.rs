//! Criterion benchmarks: our cache orderings beside their meshoptimizer peers on the same mesh in
//! the same run (`cargo bench --bench orderings`): `forsyth` (LRU 32, tuned scores) against
//! `optimizeVertexCache`, `tipsify:cache=16` against `optimizeVertexCacheFifo(16)`, and our
//! `cheap-cuts` (issue 19: within 3× of its peer's time) against `optimizeVertexCache` followed by
//! `optimizeOverdraw(1.05)`. Ours run as triorder runs them, from the mesh's vertex→triangle
//! adjacency built once per mesh; `triorder bench --only orderings` also times them with that
//! adjacency built inside, and prints ratios.
//!
//! Uses the shared bunny (69,451 triangles) and the smallest shared mesh, RiggedSimple (188
//! triangles, where forsyth is slowest against its peer: docs/performance.md), when
//! ../shared/data exists, else procedural spheres of about those sizes.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use triorder::mesh::{Scene, Source, source};
use triorder::order;

/// The shared mesh `name`, or the procedural `fallback` without the shared data.
fn scene(name: &str, fallback: &str) -> Scene {
    let data = source::data_dir(None).or_else(|| Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data")));
    let open = |name: &str| Source::parse(name)?.open(data.as_deref(), 0);
    open(name).or_else(|_| open(fallback)).expect("a benchmark mesh")
}

fn benches(c: &mut Criterion) {
    bench_mesh(c, &scene("models/bun_zipper.ply", "sphere:70000"));
    bench_mesh(c, &scene("animated/RiggedSimple.glb", "sphere:200"));
}

fn bench_mesh(c: &mut Criterion, scene: &Scene) {
    let (indices, n) = (scene.mesh.index_buffer(), scene.mesh.vertex_count());
    let mut group = c.benchmark_group(format!("orderings, {} triangles", scene.mesh.triangle_count()));
    group.sample_size(20);
    let positions = scene.mesh.meshopt_positions();
    for (ours, theirs) in [
        ("forsyth", "meshopt optimizeVertexCache"),
        ("tipsify:cache=16", "meshopt optimizeVertexCacheFifo(16)"),
        ("cheap-cuts", "meshopt optimizeVertexCache + optimizeOverdraw(1.05)"),
    ] {
        let method = order::resolve(ours, 0).expect("a registered method");
        group.bench_function(format!("triorder {ours}"), |b| b.iter(|| method.ordering.order(black_box(scene))));
        group.bench_function(theirs, |b| {
            b.iter(|| match ours {
                "forsyth" => meshopt::optimize_vertex_cache(black_box(&indices), n),
                "cheap-cuts" => {
                    let mut indices = meshopt::optimize_vertex_cache(black_box(&indices), n);
                    meshopt::optimize_overdraw_in_place(&mut indices, &positions, 1.05);
                    indices
                }
                _ => meshopt::optimize_vertex_cache_fifo(black_box(&indices), n, 16),
            })
        });
    }
    group.finish();
}

criterion_group!(orderings, benches);
criterion_main!(orderings);
