//! Criterion benchmark of the runtime choice of index buffer (Han & Sander 2017, §3.3): one
//! `Lookup::buffer` per draw, from the keyframe and the direction to the eye (`cargo bench
//! --bench lookup`). The table is what hs17 builds for 162 viewpoints over 30 keyframes; the
//! queries are 1,024 random (keyframe, eye) pairs, so the time per lookup is the reported time
//! divided by 1,024 (criterion also prints it as a throughput).

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use rand::{Rng, SeedableRng};
use triorder::order::Lookup;
use triorder::raster::views::icosphere_directions;

const FRAMES: usize = 30;
const QUERIES: usize = 1024;

fn benches(c: &mut Criterion) {
    let viewpoints = icosphere_directions(162);
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
    let assignment: Vec<u16> = (0..FRAMES * viewpoints.len()).map(|_| rng.random_range(0..5)).collect();
    let lookup = Lookup::nearest(&viewpoints, &assignment);
    let queries: Vec<(usize, Vec3)> = (0..QUERIES)
        .map(|_| {
            let eye = Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
            (rng.random_range(0..FRAMES), eye * 3.0)
        })
        .collect();

    let mut group = c.benchmark_group("runtime buffer choice");
    group.throughput(Throughput::Elements(QUERIES as u64));
    group.bench_function(format!("Lookup::buffer ×{QUERIES} (162 viewpoints, {FRAMES} keyframes)"), |b| {
        b.iter(|| black_box(&queries).iter().map(|&(f, eye)| lookup.buffer(f, eye)).sum::<usize>())
    });
    group.finish();
}

criterion_group!(lookup, benches);
criterion_main!(lookup);
