//! Vertex-shader invocations counted on the GPU (`--cache gpu`): what any device's counts must
//! satisfy, and the plumbing into `eval` and experiment rows. Lavapipe's reuse is not a GPU's
//! (../shared/GPU.md), so nothing here asserts a particular hardware figure.
//!
//! Skipped without a Vulkan adapter, unless TRIORDER_REQUIRE_GPU is set (as in CI).

mod common;

use glam::Vec3;
use triorder::gpu::vertex_reuse::{self, VertexCounter};
use triorder::mesh::load;
use triorder::metrics::{CacheModel, cache};
use triorder::order::{self, OrderInput};
use triorder::topology::Topology;

fn counter() -> Option<&'static VertexCounter> {
    common::gpu()?;
    common::available(vertex_reuse::shared())
}

#[test]
fn invocations_are_bounded_repeatable_and_reward_locality() {
    let Some(counter) = counter() else { return };
    let mesh = load::load_file(std::path::Path::new("assets/spot.obj")).unwrap();
    let topology = Topology::new(&mesh);
    let mut acmr = Vec::new();
    for method in ["random", "input", "tipsify", "meshopt-vcache"] {
        let order = order::resolve(method, 3)
            .unwrap()
            .ordering
            .order(&OrderInput { mesh: &mesh, topology: &topology })
            .unwrap();
        let triangles = mesh.triangles_in_order(&order);
        let stats = counter.count(&mesh.positions, &triangles).unwrap();
        assert_eq!(counter.count(&mesh.positions, &triangles).unwrap(), stats, "{method}: not repeatable");
        // Every referenced vertex is shaded at least once; no corner more than once.
        let simulated = cache::simulate(CacheModel::Fifo(16), &triangles, mesh.vertex_count());
        assert_eq!((stats.triangles, stats.vertices), (simulated.triangles, simulated.vertices));
        assert!(
            stats.misses >= stats.vertices as u64 && stats.misses <= 3 * stats.triangles as u64,
            "{method}: {stats:?}"
        );
        eprintln!("{method}: GPU ACMR {:.4}, FIFO-16 {:.4} on {}", stats.acmr(), simulated.acmr(), counter.device());
        acmr.push(stats.acmr());
    }
    // A cache-optimised order never costs the GPU more vertex work than a random one.
    assert!(acmr[2] < acmr[0] && acmr[3] < acmr[0], "{acmr:?}");
}

#[test]
fn unshared_corners_cost_three_invocations_per_triangle() {
    let Some(counter) = counter() else { return };
    let n = 1000u32;
    let positions: Vec<Vec3> = (0..3 * n).map(|i| Vec3::new(i as f32, (i % 3) as f32, 0.0)).collect();
    let triangles: Vec<[u32; 3]> = (0..n).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    assert_eq!(counter.count(&positions, &triangles).unwrap().misses, 3 * u64::from(n));
    let err = counter.count(&positions, &[[0, 1, 3 * n]]).unwrap_err().to_string();
    assert!(err.contains("out of range"), "{err}");
}

#[test]
fn eval_and_specs_write_counted_rows() {
    let Some(counter) = counter() else { return };
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_triorder"))
        .args(["eval", "assets/spot.obj", "-m", "tipsify", "--cache", "fifo:16", "--cache", "gpu", "--json"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["cache"], "fifo:16");
    assert_eq!(json["gpu_vertices"]["device"], counter.device());
    assert!(json["gpu_vertices"]["invocations"].as_u64().unwrap() >= 3225);

    let root = tempfile::tempdir().unwrap();
    let text = r#"id = "tiny-hw"
title = "Hardware reuse smoke"
question = "Do counted rows land beside simulated ones?"
models = ["sphere:500", "grid:8x8"]
methods = ["input", "random"]
caches = ["fifo:16", "gpu"]
[figure]
kind = "bar"
metric = "acmr"
x = "method"
series = "cache"
"#;
    let spec = common::write_spec(root.path(), "tiny-hw", text);
    let options = triorder::experiment::RunOptions { out_dir: root.path().into(), ..Default::default() };
    let csv = triorder::experiment::run(&spec, &options).unwrap();
    let rows = common::csv_rows(&csv);
    let counted: Vec<_> = rows.iter().filter(|r| r["cache"] == "gpu").collect();
    // Two models × two methods × (acmr, atvr), each naming the device that counted it.
    assert_eq!(counted.len(), 8);
    assert!(counted.iter().all(|r| r["backend"] == format!("gpu: {}", counter.device())));
    assert_eq!(counted.iter().filter(|r| r["metric"] == "acmr").count(), 4);
    // A spec cannot ask the GPU to count a per-(keyframe, view) method.
    std::fs::write(&spec, text.replace(r#"["input", "random"]"#, r#"["hs17"]"#)).unwrap();
    let err = triorder::experiment::run(&spec, &options).unwrap_err().to_string();
    assert!(err.contains("gpu") && err.contains("hs17"), "{err}");
}
