//! Our cache simulators against meshoptimizer's `analyzeVertexCache` (through the `meshopt`
//! crate) on real meshes, in every configuration where the two models coincide: FIFO-k is
//! meshopt's (k, warp 0, primgroup 0), and our batch model is defined as meshopt's.

mod common;

use triorder::measure::cache::{CacheModel, simulate};
use triorder::order;

#[test]
#[cfg_attr(not(triorder_data), ignore = "needs the shared models: ../shared/data or TRIORDER_DATA (README, Data)")]
fn fifo_and_batch_equal_meshopt_on_real_meshes() {
    let mut checked = 0;
    for name in ["bunny_2k.ply", "dragon_vrip_res3.ply", "happy_buddha_100k.obj", "pirate.obj"] {
        let mesh = common::real_mesh(name);
        for method in ["input", "random:seed=3", "meshopt-vcache"] {
            let resolved = order::resolve(method, 0).unwrap();
            let ordered = common::static_order(&resolved, &mesh).unwrap();
            let triangles = mesh.triangles_in_order(&ordered);
            let indices: Vec<u32> = triangles.iter().flatten().copied().collect();
            let n = mesh.vertex_count();
            let fifo = (3..=64).map(|k| (CacheModel::Fifo(k), (k, 0, 0)));
            let batch = [(32, 32, 32), (64, 32, 16), (14, 64, 128), (16, 32, 32), (128, 0, 0), (16, 0, 0), (8, 3, 1)]
                .map(|(c, w, p)| (CacheModel::Batch { cache: c, warp: w, primgroup: p }, (c, w, p)));
            for (model, (c, w, p)) in fifo.chain(batch) {
                let ours = simulate(model, &triangles, n);
                let theirs = meshopt::analyze_vertex_cache(&indices, n, c, w, p);
                assert_eq!(ours.misses, u64::from(theirs.vertices_transformed), "{name} {method} {model}");
                if w != 0 {
                    assert_eq!(ours.batches, u64::from(theirs.warps_executed), "{name} {method} {model}");
                }
                assert!((ours.atvr() - f64::from(theirs.atvr)).abs() < 1e-5, "{name} {method} {model}");
                checked += 1;
            }
        }
    }
    assert!(checked > 0);
}
