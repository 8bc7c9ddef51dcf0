//! The vertex-cache orderings `tipsify`, `forsyth` and `strips` against hand-worked examples,
//! their meshoptimizer peers and the random order, on the shared real meshes (skipped when the
//! data directory is absent). Permutation, winding and determinism are the conformance tests'
//! job; speed is `triorder bench`'s.

mod common;

use triorder::measure::cache::{CacheModel, simulate};
use triorder::mesh::{Mesh, procedural};
use triorder::order;

fn order_of(spec: &str, mesh: &Mesh) -> Vec<u32> {
    let resolved = order::resolve(spec, 0).unwrap();
    common::static_order(&resolved, mesh).unwrap()
}

fn acmr(model: CacheModel, mesh: &Mesh, order: &[u32]) -> f64 {
    simulate(model, &mesh.triangles_in_order(order), mesh.vertex_count()).acmr()
}

/// ACMR of `spec`'s order under `model`.
fn acmr_of(spec: &str, model: CacheModel, mesh: &Mesh) -> f64 {
    acmr(model, mesh, &order_of(spec, mesh))
}

/// grid:2x2 is vertices 0..9 row by row from the bottom left (6 7 8 / 3 4 5 / 0 1 2) and
/// triangles t0=[0,1,4] t1=[0,4,3] t2=[1,2,5] t3=[1,5,4] t4=[3,4,7] t5=[3,7,6] t6=[4,5,8]
/// t7=[4,8,7]. Worked by hand from Sander et al. 2007 §3 (ALGORITHMS.md §2), s starting at k+1:
///
/// k = 16. Dead end, cursor → vertex 0: fan t0, t1 (misses 0 1 4 3; s = 21). Candidates 0 1 4
/// 0 4 3: vertex 1 (L=2, age 3, 3+4 ≤ 16) has priority 3, vertex 4 (L=4, age 2) 2, vertex 3
/// (L=2, age 1) 1 → fan 1: t2, t3 (misses 2 5; s = 23). Candidates: 5 (L=1, age 1) → 1,
/// 4 (L=3, age 4) → 4 → fan 4: t4, t6, t7 (misses 7 8; s = 25). Candidates: 3 (L=1, age 5) → 5,
/// 7 (L=1, age 2) → 2 → fan 3: t5. Everything is emitted.
///
/// k = 3 (s from 4). Fan 0: t0, t1 (s = 8). Candidates 1 (L=2, age 3: 3+4 > 3), 4, 3 all have
/// priority 0; the first, 1, wins → fan 1: t2, then t3, where 1 and 4 have fallen out (s = 12).
/// Candidates 5 (L=1, age 3: 3+2 > 3) and 4 (L=3) score 0 → 5 → fan 5: t6 (s = 13). Candidates
/// 4 (L=2, age 2: 6 > 3) 0, 8 (L=1, age 1: 1+2 ≤ 3) 1 → fan 8: t7 (s = 14). Candidates 4 (L=1,
/// age 3: 5 > 3) 0, 7 (L=2) 0 → 4 → fan 4: t4 (s = 16). Candidates 3 (L=1, age 2: 4 > 3) 0 →
/// fan 3: t5.
#[test]
fn tipsify_on_a_small_grid_follows_the_hand_worked_order() {
    let mesh = procedural::generate("grid:2x2", 0).unwrap().unwrap();
    assert_eq!(
        mesh.triangles,
        [[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4], [3, 4, 7], [3, 7, 6], [4, 5, 8], [4, 8, 7]],
        "the grid's numbering the hand-worked orders assume"
    );
    assert_eq!(order_of("tipsify:cache=16", &mesh), [0, 1, 2, 3, 4, 6, 7, 5]);
    assert_eq!(order_of("tipsify:cache=3", &mesh), [0, 1, 2, 3, 6, 7, 4, 5]);
}

/// Awkward input: a fin (three triangles on one edge), triangles with repeated corners (one with
/// all three the same), a duplicated triangle, isolated vertices, a mesh of degenerate triangles
/// only, and a fan of 3000 triangles around one vertex. Every ordering, at its smallest and
/// largest cache, must return a permutation that keeps each triangle as given.
#[test]
fn cache_orderings_cope_with_awkward_input() {
    let mesh = |triangles: Vec<[u32; 3]>, vertices: u32| {
        let positions = (0..vertices).map(|i| glam::Vec3::new(i as f32, (i % 7) as f32, (i % 3) as f32)).collect();
        Mesh::new("awkward", positions, triangles, Default::default()).unwrap()
    };
    let fan: Vec<[u32; 3]> = (1..=3000).map(|i| [0, i, i + 1]).collect();
    let meshes = [
        mesh(vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [2, 2, 5], [0, 1, 2], [4, 5, 5], [3, 4, 5], [6, 6, 6]], 9),
        mesh(vec![[3, 3, 3], [1, 1, 2], [2, 2, 1]], 5),
        mesh(vec![[7, 8, 9]], 20),
        mesh(fan, 3002),
    ];
    let specs = [
        "tipsify:cache=3",
        "tipsify:cache=65536",
        "forsyth:cache=4",
        "forsyth:cache=1024",
        "forsyth:scores=forsyth",
        "strips",
    ];
    for mesh in &meshes {
        for spec in specs {
            let order = order_of(spec, mesh);
            order::check_permutation(&order, mesh.triangle_count()).unwrap_or_else(|e| panic!("{spec}: {e}"));
        }
    }
}

/// Tipsify is the algorithm of meshoptimizer's `optimizeVertexCacheFifo`: the issue asks for
/// ACMR within 2% on bun_zipper at FIFO-16, and we hold it to 1% at 10, 16 and 32 on every shared
/// mesh (it is in fact equal: same rule, same tie-breaks, same start).
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn tipsify_matches_meshopt_fifo() {
    let bunny = common::real_mesh("bun_zipper.ply");
    let ours = acmr_of("tipsify:cache=16", CacheModel::Fifo(16), &bunny);
    let theirs = acmr_of("meshopt-fifo:cache=16", CacheModel::Fifo(16), &bunny);
    assert!(ours <= 1.02 * theirs, "bun_zipper fifo:16: tipsify {ours:.4}, meshopt-fifo {theirs:.4}");

    for name in common::STATIC_MODELS {
        let mesh = common::real_mesh(name);
        for k in [10, 16, 32] {
            let ours = acmr_of(&format!("tipsify:cache={k}"), CacheModel::Fifo(k), &mesh);
            let theirs = acmr_of(&format!("meshopt-fifo:cache={k}"), CacheModel::Fifo(k), &mesh);
            assert!(ours <= 1.01 * theirs, "{name} fifo:{k}: tipsify {ours:.4}, meshopt-fifo {theirs:.4}");
        }
    }
}

/// Tipsify tuned for k never loses to a random order at k, for every FIFO size 3..=64, on every
/// shared mesh; nor does the default (k = 16) order measured at any of those sizes.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn tipsify_never_loses_to_random() {
    for name in common::STATIC_MODELS {
        let mesh = common::real_mesh(name);
        let random = order_of("random:seed=1", &mesh);
        let default = order_of("tipsify", &mesh);
        for k in 3..=64 {
            let model = CacheModel::Fifo(k);
            let random = acmr(model, &mesh, &random);
            let tuned = acmr_of(&format!("tipsify:cache={k}"), model, &mesh);
            let default = acmr(model, &mesh, &default);
            assert!(tuned <= random, "{name} fifo:{k}: tipsify:cache={k} {tuned:.4} vs random {random:.4}");
            assert!(default <= random, "{name} fifo:{k}: tipsify {default:.4} vs random {random:.4}");
        }
    }
}

/// Issue 4 asks for ACMR within 2% of meshoptimizer's `optimizeVertexCache` at FIFO-16 and
/// LRU-32. The default (tuned) score table meets it on every shared mesh, the eight larger ones
/// held out of its tuning (src/order/forsyth.rs says how it was tuned). Forsyth's own table is
/// held to the 3.5% it is measured within (3.3% worse on armadillo at FIFO-16): it must stay
/// available and sane, and it is the reason the tuned table is the default.
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn forsyth_is_close_to_meshopt_vcache() {
    for name in common::STATIC_MODELS {
        let mesh = common::real_mesh(name);
        let theirs = order_of("meshopt-vcache", &mesh);
        for (spec, bound) in [("forsyth", 1.02), ("forsyth:scores=forsyth", 1.035)] {
            let ours = order_of(spec, &mesh);
            for model in [CacheModel::Fifo(16), CacheModel::Lru(32)] {
                let (ours, theirs) = (acmr(model, &mesh, &ours), acmr(model, &mesh, &theirs));
                assert!(ours <= bound * theirs, "{name} {model}: {spec} {ours:.4}, meshopt-vcache {theirs:.4}");
            }
        }
    }
}

/// B&G 2002 Table 2: strips sit between the optimised orders and an arbitrary one at k = 10
/// (1.06–1.10 against 0.81–0.83 for recursive cut and up to 2.83 for the original order).
#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn strips_lie_between_optimised_orders_and_random() {
    let mesh = common::real_mesh("bunny_2k.ply");
    let k10 = CacheModel::Fifo(10);
    let strips = acmr_of("strips", k10, &mesh);
    let random = acmr_of("random:seed=1", k10, &mesh);
    for optimised in ["tipsify:cache=10", "forsyth", "meshopt-vcache", "meshopt-fifo:cache=10"] {
        let optimised_acmr = acmr_of(optimised, k10, &mesh);
        assert!(optimised_acmr < strips, "{optimised} {optimised_acmr:.4} vs strips {strips:.4}");
    }
    assert!(strips < random, "strips {strips:.4} vs random {random:.4}");
    // One new vertex per strip triangle, give or take the joins: B&G's range, loosely.
    assert!((0.95..=1.15).contains(&strips), "strips ACMR at k=10: {strips:.4}");
}
